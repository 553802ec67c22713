//! Ephemerides per satellite, and the choice of the one to use at a given time.

use std::collections::BTreeMap;

use super::kepler::KeplerianEphemeris;
use super::time::GpsTime;
use crate::gnss::SatId;

/// Ephemerides kept per satellite; the oldest (by toe) is dropped beyond this.
/// Choice: 8 covers several hours of GPS/Galileo uploads and 8 h of hourly BeiDou sets,
/// and bounds memory on a long recording.
pub const MAX_EPHEMERIDES_PER_SAT: usize = 8;

/// Two reference times closer than this (s) denote the same ephemeris set.
const SAME_TOE_TOLERANCE_S: f64 = 1e-3;

/// Broadcast ephemerides of many satellites.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EphemerisStore {
    by_sat: BTreeMap<SatId, Vec<KeplerianEphemeris>>,
}

/// What [`EphemerisStore::insert`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InsertOutcome {
    /// A new ephemeris set was added.
    Added,
    /// A set with the same message source and toe was replaced (a re-broadcast or an
    /// update of the same issue).
    Replaced,
    /// The ephemeris failed [`KeplerianEphemeris::is_valid`] and was not stored.
    Rejected,
}

impl EphemerisStore {
    /// An empty store.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `eph`, replacing a set of the same satellite, source and toe.
    pub fn insert(&mut self, eph: KeplerianEphemeris) -> InsertOutcome {
        if !eph.is_valid() {
            return InsertOutcome::Rejected;
        }
        let list = self.by_sat.entry(eph.sat).or_default();
        if let Some(existing) = list.iter_mut().find(|e| {
            e.source == eph.source && e.toe.seconds_since(&eph.toe).abs() < SAME_TOE_TOLERANCE_S
        }) {
            *existing = eph;
            return InsertOutcome::Replaced;
        }
        list.push(eph);
        if list.len() > MAX_EPHEMERIDES_PER_SAT {
            list.sort_by(|a, b| a.toe.seconds_since(&b.toe).total_cmp(&0.0));
            list.remove(0);
        }
        InsertOutcome::Added
    }

    /// The ephemeris to use for `sat` at GPST `t`: among the healthy sets whose validity
    /// window holds t (|t − toe| ≤ validity), the one with the closest toe; ties go to the
    /// later toe (the fresher upload). None if there is none.
    pub fn select(&self, sat: SatId, t: &GpsTime) -> Option<&KeplerianEphemeris> {
        self.by_sat
            .get(&sat)?
            .iter()
            .filter(|e| e.health == 0)
            .filter_map(|e| {
                let age = t.seconds_since(&e.toe);
                (age.abs() <= e.validity_s).then_some((age, e))
            })
            .min_by(|(a, _), (b, _)| a.abs().total_cmp(&b.abs()).then_with(|| a.total_cmp(b)))
            .map(|(_, e)| e)
    }

    /// All ephemerides stored for `sat` (any order).
    pub fn ephemerides(&self, sat: SatId) -> &[KeplerianEphemeris] {
        self.by_sat.get(&sat).map_or(&[], Vec::as_slice)
    }

    /// The satellites with at least one ephemeris.
    pub fn satellites(&self) -> impl Iterator<Item = SatId> + '_ {
        self.by_sat.keys().copied()
    }

    /// Total number of ephemerides stored.
    pub fn len(&self) -> usize {
        self.by_sat.values().map(Vec::len).sum()
    }

    /// Whether the store is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
