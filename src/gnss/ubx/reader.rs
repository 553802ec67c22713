//! A whole UBX log (bytes) turned into GNSS epochs, in stream order: each RAWX epoch is
//! built with the ephemerides decoded from the SFRBX messages received before it, as a
//! real-time receiver would.

use super::epoch::build_epoch_with;
use super::frame::{FrameReader, FrameStats};
use super::message::{decode_message, UbxMessage};
use super::nav_decoder::{NavDecoder, NavDecoderStats, NavUpdate};
use super::nav_pvt::NavPvt;
use super::rawx::RawX;
use super::sfrbx::Sfrbx;
use crate::gnss::ephemeris::{EphemerisStore, GpsTime};
use crate::gnss::epoch_build::BuiltEpoch;
use crate::gnss::ionosphere::IonosphereMode;
use crate::gnss::Klobuchar;

/// SFRBX messages held while no RAWX has yet given the GPS week.
/// Choice: a few minutes of subframes of ~40 signals; beyond that the oldest are dropped.
const MAX_PENDING_SFRBX: usize = 4_096;

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
    /// SFRBX messages dropped because no RAWX ever gave the week.
    pub sfrbx_without_time: usize,
    /// Navigation-message decoder counts.
    pub nav: NavDecoderStats,
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
    let mut decoder = NavDecoder::new();
    let mut reference: Option<GpsTime> = None;
    let mut pending: Vec<Sfrbx> = Vec::new();
    let mut reader = FrameReader::new(bytes);
    for frame in reader.by_ref() {
        match decode_message(&frame) {
            Ok(UbxMessage::RawX(raw)) => {
                log.stats.rawx += 1;
                let t = GpsTime::new(i32::from(raw.week), raw.rcv_tow_s);
                if t.is_finite() {
                    reference = Some(t);
                    for msg in pending.drain(..) {
                        apply(&mut log, &mut decoder, &msg, &t);
                    }
                }
                let built = build_epoch_with(&raw, &log.store, log.klobuchar, ionosphere);
                log.epochs.push(built);
                log.rawx.push(raw);
            }
            Ok(UbxMessage::Sfrbx(msg)) => {
                log.stats.sfrbx += 1;
                match reference {
                    Some(t) => apply(&mut log, &mut decoder, &msg, &t),
                    None => {
                        if pending.len() >= MAX_PENDING_SFRBX {
                            pending.remove(0);
                            log.stats.sfrbx_without_time += 1;
                        }
                        pending.push(msg);
                    }
                }
            }
            Ok(UbxMessage::NavPvt(pvt)) => {
                log.stats.nav_pvt += 1;
                log.nav_pvt.push(pvt);
            }
            Ok(UbxMessage::Unknown { .. }) => log.stats.unknown += 1,
            Err(_) => log.stats.decode_errors += 1,
        }
    }
    log.stats.sfrbx_without_time += pending.len();
    log.stats.frames = reader.stats();
    log.stats.nav = decoder.stats();
    log
}

fn apply(log: &mut UbxLog, decoder: &mut NavDecoder, msg: &Sfrbx, t: &GpsTime) {
    match decoder.push(msg, t) {
        Some(NavUpdate::Ephemeris(eph)) => {
            log.store.insert(eph);
        }
        Some(NavUpdate::Klobuchar(k)) => log.klobuchar = Some(k),
        None => {}
    }
}
