//! A [`GnssEpoch`](crate::gnss::GnssEpoch) from one UBX-RXM-RAWX message and the
//! broadcast ephemerides.
//!
//! Choices (beyond the shared ones of [`crate::gnss::epoch_build`]):
//! - Receive time: the RAWX receiver time (week, rcvTow) as GPST, uncorrected for the
//!   receiver clock (see [`crate::gnss::ephemeris::state_at_transmission`]).
//! - Rate: ρ̇ = −λ · D (u-blox Doppler is positive for an approaching satellite), σ_ρ̇ =
//!   λ · σ_D; the pseudo-range σ is the receiver's prStdev.

use super::ids::{sat_id, signal};
use super::rawx::{RawMeasurement, RawX};
use crate::gnss::ephemeris::{EphemerisStore, GpsTime, Signal};
use crate::gnss::epoch_build::{
    complete_epoch, preferred_signals, unfilled_observation, BuiltEpoch, EpochStats,
};
use crate::gnss::{Klobuchar, SatId, SatObservation};

/// Builds the epoch of `raw`: one [`SatObservation`] per satellite with a usable signal
/// and an ephemeris in `store`; `klobuchar` is passed through.
pub fn build_epoch(raw: &RawX, store: &EphemerisStore, klobuchar: Option<Klobuchar>) -> BuiltEpoch {
    let receive_time = GpsTime::new(i32::from(raw.week), raw.rcv_tow_s);
    let mut stats = EpochStats {
        measurements: raw.measurements.len(),
        ..EpochStats::default()
    };
    let mut sats: Vec<SatId> = raw
        .measurements
        .iter()
        .filter_map(|m| sat_id(m.gnss_id, m.sv_id))
        .collect();
    sats.sort();
    sats.dedup();
    stats.satellites = sats.len();
    let mut candidates = Vec::new();
    for sat in sats {
        match choose(raw, sat) {
            Some((sig, m)) => candidates.push((sig, observation(sat, sig, m))),
            None => stats.unsupported += 1,
        }
    }
    complete_epoch(receive_time, candidates, store, klobuchar, stats)
}

/// The preferred usable measurement of `sat`.
fn choose(raw: &RawX, sat: SatId) -> Option<(Signal, &RawMeasurement)> {
    preferred_signals(sat.constellation)
        .iter()
        .find_map(|&wanted| {
            raw.measurements.iter().find_map(|m| {
                let usable = sat_id(m.gnss_id, m.sv_id) == Some(sat)
                    && signal(m.gnss_id, m.sig_id) == Some(wanted)
                    && m.tracking.pr_valid
                    && m.pseudorange_m.is_finite()
                    && m.pseudorange_m > 0.0;
                usable.then_some((wanted, m))
            })
        })
}

fn observation(sat: SatId, sig: Signal, m: &RawMeasurement) -> SatObservation {
    let lambda_m = sig.wavelength_m();
    let finite = |v: f64| v.is_finite().then_some(v);
    SatObservation {
        pseudorange_rate_mps: finite(-lambda_m * m.doppler_hz),
        pseudorange_sigma_m: finite(m.pseudorange_sigma_m),
        pseudorange_rate_sigma_mps: finite(lambda_m * m.doppler_sigma_hz),
        cn0_dbhz: Some(m.cn0_dbhz),
        ..unfilled_observation(sat, m.pseudorange_m)
    }
}
