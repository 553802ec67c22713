//! [`BroadcastNav`]: the broadcast navigation data of one receiver as it arrives
//! (UBX-RXM-SFRBX subframes in; ephemerides, GPS Klobuchar out) and the epoch of each
//! UBX-RXM-RAWX built with what was known when it came, as a receiver in real time. The
//! file reader ([`super::read_ubx_log`]) and the live adapter
//! (`crate::ros::ubx_adapter`) both go through it.

use super::epoch::build_epoch_with;
use super::nav_decoder::{NavDecoder, NavDecoderStats, NavUpdate};
use super::rawx::RawX;
use super::sfrbx::Sfrbx;
use crate::gnss::ephemeris::{EphemerisStore, GpsTime};
use crate::gnss::epoch_build::BuiltEpoch;
use crate::gnss::ionosphere::IonosphereMode;
use crate::gnss::Klobuchar;

/// SFRBX messages held while no RAWX has yet given the GPS week.
/// Choice: a few minutes of subframes of ~40 signals; beyond that the oldest are dropped.
const MAX_PENDING_SFRBX: usize = 4_096;

/// Counts of the navigation data.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BroadcastNavStats {
    /// SFRBX messages dropped because no RAWX gave the week in time.
    pub sfrbx_without_time: usize,
    /// Navigation-message decoder counts.
    pub decoder: NavDecoderStats,
}

/// See the module doc.
#[derive(Debug, Clone, Default)]
pub struct BroadcastNav {
    decoder: NavDecoder,
    store: EphemerisStore,
    klobuchar: Option<Klobuchar>,
    /// Receiver time of the latest RAWX, the reference that resolves broadcast weeks.
    reference: Option<GpsTime>,
    pending: Vec<Sfrbx>,
    sfrbx_without_time: usize,
}

impl BroadcastNav {
    /// No navigation data yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one subframe/page: decoded at once when a RAWX has given the time, else held
    /// until one does.
    pub fn on_sfrbx(&mut self, msg: Sfrbx) {
        match self.reference {
            Some(t) => self.apply(&msg, &t),
            None => {
                if self.pending.len() >= MAX_PENDING_SFRBX {
                    self.pending.remove(0);
                    self.sfrbx_without_time += 1;
                }
                self.pending.push(msg);
            }
        }
    }

    /// The epoch of `raw`, built (as `ionosphere` says) with the ephemerides and
    /// Klobuchar coefficients received so far. A finite receiver time becomes the
    /// reference of the subframes that follow (and of those held until now).
    pub fn on_rawx(&mut self, raw: &RawX, ionosphere: IonosphereMode) -> BuiltEpoch {
        let t = GpsTime::new(i32::from(raw.week), raw.rcv_tow_s);
        if t.is_finite() {
            self.reference = Some(t);
            for msg in std::mem::take(&mut self.pending) {
                self.apply(&msg, &t);
            }
        }
        build_epoch_with(raw, &self.store, self.klobuchar, ionosphere)
    }

    /// The ephemerides received so far.
    pub fn store(&self) -> &EphemerisStore {
        &self.store
    }

    /// The latest GPS Klobuchar coefficients.
    pub fn klobuchar(&self) -> Option<Klobuchar> {
        self.klobuchar
    }

    /// Counts so far; subframes still held for want of a time count as without time.
    pub fn stats(&self) -> BroadcastNavStats {
        BroadcastNavStats {
            sfrbx_without_time: self.sfrbx_without_time + self.pending.len(),
            decoder: self.decoder.stats(),
        }
    }

    fn apply(&mut self, msg: &Sfrbx, t: &GpsTime) {
        match self.decoder.push(msg, t) {
            Some(NavUpdate::Ephemeris(eph)) => {
                self.store.insert(eph);
            }
            Some(NavUpdate::Klobuchar(k)) => self.klobuchar = Some(k),
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::gps_lnav::tests::lnav_words;
    use super::*;

    /// GPS subframe 4, page 18 (SV ID 56): α0..α3 = 11, 8, −4, −1 and β0..β3 = 88, 0,
    /// −3, −1 (8-bit codes).
    fn page_18() -> Vec<u32> {
        lnav_words([
            0x8B_0000,
            (68_000 << 7) | (4 << 2),
            (1 << 22) | (56 << 16) | (0x0B << 8) | 0x08,
            (0xFC << 16) | (0xFF << 8) | 0x58,
            (0xFD << 8) | 0xFF, // β1 = 0
            0,
            0,
            0,
            0,
            0,
        ])
    }

    #[test]
    fn klobuchar_of_subframe_4_page_18_reaches_the_next_epochs() {
        let mut nav = BroadcastNav::new();
        let raw = |tow_s| RawX::new(tow_s, 2381, 18, 1, 1, Vec::new());
        let mode = IonosphereMode::Broadcast;
        assert_eq!(nav.on_rawx(&raw(408_000.0), mode).epoch.klobuchar, None);
        nav.on_sfrbx(Sfrbx {
            gnss_id: 0,
            sv_id: 5,
            sig_id: 0,
            freq_id: 0,
            channel: 3,
            version: 2,
            words: page_18(),
        });
        let k = nav.on_rawx(&raw(408_000.25), mode).epoch.klobuchar.unwrap();
        let p = |e: i32| 2f64.powi(e);
        assert_eq!(
            k.alpha,
            [11.0 * p(-30), 8.0 * p(-27), -4.0 * p(-24), -p(-24)]
        );
        assert_eq!(k.beta, [88.0 * p(11), 0.0, -3.0 * p(16), -p(16)]);
        assert_eq!(nav.stats().decoder.accepted, 1);
    }
}
