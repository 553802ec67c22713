//! Assembly of SFRBX subframes/pages per satellite into ephemerides (GPS/QZSS LNAV,
//! Galileo I/NAV, BeiDou D1 and D2) and the GPS Klobuchar parameters, as they arrive.

use std::collections::BTreeMap;

use super::beidou_d1::decode_d1_ephemeris;
use super::beidou_d2::{d2_page, decode_d2_ephemeris, D2_EPHEMERIS_PAGES};
use super::beidou_subframe::{bds_subframe, BdsSubframe};
use super::bits::Bits;
use super::galileo_inav::{decode_inav_ephemeris, inav_word, InavWord};
use super::gps_lnav::{decode_lnav_ephemeris, decode_lnav_klobuchar, lnav_subframe};
use super::ids::{sat_id, GNSS_BEIDOU, GNSS_GALILEO, GNSS_GPS, GNSS_QZSS};
use super::nav_error::NavDataError;
use super::sfrbx::Sfrbx;
use crate::gnss::ephemeris::{GpsTime, KeplerianEphemeris, NavSource};
use crate::gnss::{Klobuchar, SatId};

/// What a subframe completed.
#[derive(Debug, Clone, PartialEq)]
pub enum NavUpdate {
    /// A new (or changed) ephemeris.
    Ephemeris(KeplerianEphemeris),
    /// GPS Klobuchar coefficients (subframe 4 page 18).
    Klobuchar(Klobuchar),
}

/// Counts of the decoder.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NavDecoderStats {
    /// Subframes/pages that passed their checks.
    pub accepted: usize,
    /// Subframes/pages refused, for any reason (the two below, preamble, page layout).
    pub rejected: usize,
    /// ... of which for a word count that does not fit the message type.
    pub rejected_word_count: usize,
    /// ... of which for a parity (GPS), BCH (BeiDou) or CRC (Galileo) error.
    pub rejected_parity: usize,
    /// Subframe sets of one frame whose issues of data contradict each other (see
    /// [`NavDataError::IssueMismatch`]): no ephemeris formed from them.
    pub issue_mismatch: usize,
    /// Messages of systems or signals not decoded (GLONASS, SBAS, CNAV, F/NAV, …).
    pub unsupported: usize,
    /// Ephemerides emitted (new or changed).
    pub ephemerides: usize,
}

/// Per-satellite assembly state.
#[derive(Debug, Clone, Default)]
struct LnavSlots {
    sf: [Option<Bits>; 3],
}

#[derive(Debug, Clone, Default)]
struct InavSlots {
    words: [Option<InavWord>; 5],
}

#[derive(Debug, Clone, Default)]
struct D1Slots {
    sf: [Option<BdsSubframe>; 3],
}

/// The pages of [`D2_EPHEMERIS_PAGES`], in that order.
#[derive(Debug, Clone, Default)]
struct D2Slots {
    pages: [Option<BdsSubframe>; 9],
}

/// Turns SFRBX messages into ephemerides; keeps partial subframe sets per satellite.
#[derive(Debug, Clone, Default)]
pub struct NavDecoder {
    lnav: BTreeMap<SatId, LnavSlots>,
    inav: BTreeMap<SatId, InavSlots>,
    d1: BTreeMap<SatId, D1Slots>,
    d2: BTreeMap<SatId, D2Slots>,
    last: BTreeMap<(SatId, NavSourceKey), KeplerianEphemeris>,
    stats: NavDecoderStats,
}

/// Map key for a message source (NavSource is not Ord).
type NavSourceKey = u8;

fn source_key(s: NavSource) -> NavSourceKey {
    s as u8
}

impl NavDecoder {
    /// A decoder with no state.
    pub fn new() -> Self {
        Self::default()
    }

    /// Counts so far.
    pub fn stats(&self) -> NavDecoderStats {
        self.stats
    }

    /// Feeds one SFRBX message; `reference` is a GPST within days of the data (the
    /// receiver time of the latest RAWX), used to resolve week numbers. Returns what the
    /// message completed, if anything.
    pub fn push(&mut self, msg: &Sfrbx, reference: &GpsTime) -> Option<NavUpdate> {
        let Some(sat) = sat_id(msg.gnss_id, msg.sv_id) else {
            self.stats.unsupported += 1;
            return None;
        };
        let words = &msg.words;
        let result = match (msg.gnss_id, msg.sig_id) {
            (GNSS_GPS, 0) => self.push_lnav(sat, NavSource::GpsLnav, words, reference),
            (GNSS_QZSS, 0) => self.push_lnav(sat, NavSource::QzssLnav, words, reference),
            (GNSS_GALILEO, 1) => self.push_inav(sat, words, reference),
            // B1I/B2I/B3I D1 of MEO/IGSO, B1I/B2I D2 of GEO.
            (GNSS_BEIDOU, 0 | 2 | 4) if !is_beidou_geo(sat) => self.push_d1(sat, words, reference),
            (GNSS_BEIDOU, 1 | 3) if is_beidou_geo(sat) => self.push_d2(sat, words, reference),
            _ => {
                self.stats.unsupported += 1;
                return None;
            }
        };
        match result {
            Ok(update) => {
                self.stats.accepted += 1;
                match update {
                    Some(NavUpdate::Ephemeris(eph)) => self.emit(eph),
                    other => other,
                }
            }
            Err(e) => {
                self.stats.rejected += 1;
                match e {
                    NavDataError::WordCount { .. } => self.stats.rejected_word_count += 1,
                    NavDataError::Parity { .. }
                    | NavDataError::Bch { .. }
                    | NavDataError::Crc { .. } => self.stats.rejected_parity += 1,
                    _ => {}
                }
                None
            }
        }
    }

    /// Returns the ephemeris if it differs from the last one emitted for the satellite.
    fn emit(&mut self, eph: KeplerianEphemeris) -> Option<NavUpdate> {
        let key = (eph.sat, source_key(eph.source));
        if self.last.get(&key) == Some(&eph) {
            return None;
        }
        self.last.insert(key, eph);
        self.stats.ephemerides += 1;
        Some(NavUpdate::Ephemeris(eph))
    }

    /// The update of a complete set of slots: an ephemeris; nothing while its parts are
    /// of different uploads or frames; nothing, counted, when they contradict each other.
    fn completed(
        &mut self,
        decoded: Result<Option<KeplerianEphemeris>, NavDataError>,
    ) -> Result<Option<NavUpdate>, NavDataError> {
        match decoded {
            Ok(eph) => Ok(eph.map(NavUpdate::Ephemeris)),
            Err(NavDataError::IssueMismatch { .. }) => {
                self.stats.issue_mismatch += 1;
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    fn push_lnav(
        &mut self,
        sat: SatId,
        source: NavSource,
        words: &[u32],
        reference: &GpsTime,
    ) -> Result<Option<NavUpdate>, NavDataError> {
        let sf = lnav_subframe(sat, words)?;
        let slots = self.lnav.entry(sat).or_default();
        match sf.id {
            1..=3 => {
                if let Some(slot) = slots.sf.get_mut(usize::from(sf.id - 1)) {
                    *slot = Some(sf.data);
                }
                let [Some(s1), Some(s2), Some(s3)] = &slots.sf else {
                    return Ok(None);
                };
                let decoded = decode_lnav_ephemeris(sat, source, s1, s2, s3, reference);
                self.completed(decoded)
            }
            4 if source == NavSource::GpsLnav => {
                Ok(decode_lnav_klobuchar(&sf.data).map(NavUpdate::Klobuchar))
            }
            _ => Ok(None),
        }
    }

    fn push_inav(
        &mut self,
        sat: SatId,
        words: &[u32],
        reference: &GpsTime,
    ) -> Result<Option<NavUpdate>, NavDataError> {
        let word = inav_word(sat, words)?;
        let slots = self.inav.entry(sat).or_default();
        let index = match word.word_type {
            1..=5 => usize::from(word.word_type - 1),
            _ => return Ok(None),
        };
        if let Some(slot) = slots.words.get_mut(index) {
            *slot = Some(word);
        }
        let [Some(w1), Some(w2), Some(w3), Some(w4), Some(w5)] = &slots.words else {
            return Ok(None);
        };
        let decoded = decode_inav_ephemeris(sat, [w1, w2, w3, w4, w5], reference);
        self.completed(decoded)
    }

    fn push_d1(
        &mut self,
        sat: SatId,
        words: &[u32],
        reference: &GpsTime,
    ) -> Result<Option<NavUpdate>, NavDataError> {
        let sf = bds_subframe(sat, words)?;
        let slots = self.d1.entry(sat).or_default();
        if !(1..=3).contains(&sf.id) {
            return Ok(None);
        }
        if let Some(slot) = slots.sf.get_mut(usize::from(sf.id - 1)) {
            *slot = Some(sf);
        }
        let [Some(s1), Some(s2), Some(s3)] = &slots.sf else {
            return Ok(None);
        };
        let decoded = decode_d1_ephemeris(sat, s1, s2, s3, reference);
        self.completed(decoded)
    }

    fn push_d2(
        &mut self,
        sat: SatId,
        words: &[u32],
        reference: &GpsTime,
    ) -> Result<Option<NavUpdate>, NavDataError> {
        let sf = bds_subframe(sat, words)?;
        // Page 2 (ionosphere) and subframes 2–5 do not enter the ephemeris.
        let Some(index) =
            d2_page(&sf).and_then(|p| D2_EPHEMERIS_PAGES.iter().position(|e| *e == p))
        else {
            return Ok(None);
        };
        let slots = self.d2.entry(sat).or_default();
        if let Some(slot) = slots.pages.get_mut(index) {
            *slot = Some(sf);
        }
        let [Some(p1), Some(p3), Some(p4), Some(p5), Some(p6), Some(p7), Some(p8), Some(p9), Some(p10)] =
            &slots.pages
        else {
            return Ok(None);
        };
        let pages = [p1, p3, p4, p5, p6, p7, p8, p9, p10];
        let decoded = decode_d2_ephemeris(sat, pages, reference);
        self.completed(decoded)
    }
}

/// BeiDou GEO satellites (PRN 1–5 and 59–63), which broadcast D2.
fn is_beidou_geo(sat: SatId) -> bool {
    matches!(sat.prn, 1..=5 | 59..=63)
}
