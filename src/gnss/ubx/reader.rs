//! A whole UBX log (bytes) turned into GNSS epochs, in stream order: each RAWX epoch is
//! built with the ephemerides decoded from the SFRBX messages received before it, as a
//! real-time receiver would ([`BroadcastNav`]).

use super::broadcast_nav::{BroadcastNav, BroadcastNavStats};
use super::frame::FrameReader;
use super::message::{decode_message, UbxMessage};
use super::nav_pvt::NavPvt;
use super::rawx::RawX;
use super::scanner::FrameStats;
use crate::gnss::ephemeris::EphemerisStore;
use crate::gnss::epoch_build::BuiltEpoch;
use crate::gnss::ionosphere::IonosphereMode;
use crate::gnss::Klobuchar;

/// Counts of a log.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UbxLogStats {
    /// Framing counts (valid, bad checksum, truncated, skipped bytes).
    pub frames: FrameStats,
    /// Valid frames of message types not decoded here.
    pub unknown: usize,
    /// Valid frames whose payload did not fit the message layout.
    pub decode_errors: usize,
    /// RAWX messages.
    pub rawx: usize,
    /// SFRBX messages.
    pub sfrbx: usize,
    /// NAV-PVT messages.
    pub nav_pvt: usize,
    /// Navigation-data counts (SFRBX without time, decoder).
    pub nav: BroadcastNavStats,
}

/// Everything decoded from a log.
#[derive(Debug, Clone, Default)]
pub struct UbxLog {
    /// One epoch per RAWX message, in order, built with the ephemerides known then.
    pub epochs: Vec<BuiltEpoch>,
    /// The RAWX messages, in order (to rebuild epochs with a later store).
    pub rawx: Vec<RawX>,
    /// The NAV-PVT solutions, in order.
    pub nav_pvt: Vec<NavPvt>,
    /// All ephemerides decoded.
    pub store: EphemerisStore,
    /// The latest GPS Klobuchar parameters.
    pub klobuchar: Option<Klobuchar>,
    /// Counts.
    pub stats: UbxLogStats,
}

/// Decodes a UBX byte stream, its epochs built single-frequency
/// ([`IonosphereMode::Broadcast`]). Never fails: what cannot be used is skipped and
/// counted.
pub fn read_ubx_log(bytes: &[u8]) -> UbxLog {
    read_ubx_log_with(bytes, IonosphereMode::Broadcast)
}

/// Decodes a UBX byte stream, its epochs built as `ionosphere` says.
pub fn read_ubx_log_with(bytes: &[u8], ionosphere: IonosphereMode) -> UbxLog {
    let mut log = UbxLog::default();
    let mut nav = BroadcastNav::new();
    let mut reader = FrameReader::new(bytes);
    for frame in reader.by_ref() {
        match decode_message(&frame) {
            Ok(UbxMessage::RawX(raw)) => {
                log.stats.rawx += 1;
                log.epochs.push(nav.on_rawx(&raw, ionosphere));
                log.rawx.push(raw);
            }
            Ok(UbxMessage::Sfrbx(msg)) => {
                log.stats.sfrbx += 1;
                nav.on_sfrbx(msg);
            }
            Ok(UbxMessage::NavPvt(pvt)) => {
                log.stats.nav_pvt += 1;
                log.nav_pvt.push(pvt);
            }
            Ok(UbxMessage::Unknown { .. }) => log.stats.unknown += 1,
            Err(_) => log.stats.decode_errors += 1,
        }
    }
    log.stats.frames = reader.stats();
    log.stats.nav = nav.stats();
    log.store = nav.store().clone();
    log.klobuchar = nav.klobuchar();
    log
}
