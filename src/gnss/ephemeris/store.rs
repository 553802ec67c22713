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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::ephemeris::{GroupDelay, NavSource};
    use crate::gnss::Constellation;

    fn eph(toe_tow_s: f64, health: u16) -> KeplerianEphemeris {
        KeplerianEphemeris {
            sat: SatId {
                constellation: Constellation::Galileo,
                prn: 7,
            },
            source: NavSource::GalileoInav,
            toe: GpsTime::new(2381, toe_tow_s),
            toc: GpsTime::new(2381, toe_tow_s),
            sqrt_a_sqrt_m: 5_440.6,
            eccentricity: 1e-4,
            inclination_rad: 0.97,
            inclination_rate_rad_s: 0.0,
            raan_rad: 1.0,
            raan_rate_rad_s: -5e-9,
            arg_perigee_rad: 0.3,
            mean_anomaly_rad: 2.0,
            mean_motion_diff_rad_s: 3e-9,
            cuc_rad: 0.0,
            cus_rad: 0.0,
            crc_m: 0.0,
            crs_m: 0.0,
            cic_rad: 0.0,
            cis_rad: 0.0,
            af0_s: 1e-4,
            af1_s_s: 1e-12,
            af2_s_s2: 0.0,
            group_delay: GroupDelay::Galileo {
                bgd_e1_e5a_s: 1e-9,
                bgd_e1_e5b_s: Some(2e-9),
            },
            issue_of_data: 1,
            health,
            validity_s: 14_400.0,
        }
    }

    #[test]
    fn selects_the_closest_healthy_toe_within_validity() {
        let mut store = EphemerisStore::new();
        assert_eq!(store.insert(eph(400_000.0, 0)), InsertOutcome::Added);
        assert_eq!(store.insert(eph(406_000.0, 0)), InsertOutcome::Added);
        assert_eq!(store.insert(eph(409_000.0, 1)), InsertOutcome::Added);
        assert_eq!(store.insert(eph(406_000.0, 0)), InsertOutcome::Replaced);
        let mut bad = eph(500_000.0, 0);
        bad.sqrt_a_sqrt_m = -1.0;
        assert_eq!(store.insert(bad), InsertOutcome::Rejected);
        assert_eq!(store.len(), 3);
        let sat = eph(0.0, 0).sat;
        // 408 500: the unhealthy set at 409 000 is closest but skipped.
        let chosen = store.select(sat, &GpsTime::new(2381, 408_500.0)).unwrap();
        assert_eq!(chosen.toe.tow_s, 406_000.0);
        let chosen = store.select(sat, &GpsTime::new(2381, 402_000.0)).unwrap();
        assert_eq!(chosen.toe.tow_s, 400_000.0);
        // Outside every window (406 000 + 14 400 < 421 000).
        assert!(store.select(sat, &GpsTime::new(2381, 421_000.0)).is_none());
        let other = SatId {
            constellation: Constellation::Gps,
            prn: 7,
        };
        assert!(store
            .select(other, &GpsTime::new(2381, 406_000.0))
            .is_none());
    }

    #[test]
    fn keeps_a_bounded_number_of_sets_per_satellite() {
        let mut store = EphemerisStore::new();
        for k in 0..(MAX_EPHEMERIDES_PER_SAT + 3) {
            store.insert(eph(3_600.0 * k as f64, 0));
        }
        assert_eq!(store.len(), MAX_EPHEMERIDES_PER_SAT);
        let sat = eph(0.0, 0).sat;
        let oldest = store
            .ephemerides(sat)
            .iter()
            .map(|e| e.toe.tow_s)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(oldest, 3.0 * 3_600.0);
    }
}
