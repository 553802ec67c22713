//! A [`GnssEpoch`](crate::gnss::GnssEpoch) from one UBX-RXM-RAWX message and the
//! broadcast ephemerides.
//!
//! Choices (beyond the shared ones of [`crate::gnss::epoch_build`]):
//! - [`IonosphereMode::IonoFree`]: the ionosphere-free combination of the first pair of
//!   [`iono_free_pairs`] with both pseudo-ranges valid, σ propagated from both prStdev.
//!   A satellite without one (counted as `single_frequency`) brings no range, which
//!   would carry the ionosphere back as a bias, but when its preferred single signal has
//!   a valid carrier phase it is kept for that phase and its Doppler (counted as
//!   `phase_only`; no pseudo-range): the time difference of a phase and a Doppler change
//!   with the ionosphere by millimetres (per second), as the rates of the pairs do. The
//!   rate is the first signal's Doppler: the ionosphere's rate of change (millimetres per
//!   second) is left in it. The other modes use one signal per satellite
//!   ([`crate::gnss::epoch_build::preferred_signals`]).
//! - Receive time: the RAWX receiver time (week, rcvTow) as GPST, uncorrected for the
//!   receiver clock (see [`crate::gnss::ephemeris::state_at_transmission`]).
//! - Rate: ρ̇ = −λ · D (u-blox Doppler is positive for an approaching satellite), σ_ρ̇ =
//!   λ · σ_D; the pseudo-range σ is the receiver's prStdev.
//! - A satellite with two measurement blocks of one signal (gnssId, svId, sigId), which
//!   a receiver never outputs, is left out whole (counted as `duplicate_signals`).
//! - Carrier phase: the first signal's cpMes when trkStat says it is valid, in cycles of
//!   that signal's wavelength (also for an ionosphere-free pair, like the rate: a time
//!   difference of it changes with the ionosphere by millimetres per second); σ from
//!   cpStdev (0.004 cycles per step, none for step 0), the lock time from locktime. A
//!   receiver clock reset (recStat) marks every phase of the epoch as a loss of lock; the
//!   half cycle is unresolved while trkStat does not say "half cycle valid". RAWX has no
//!   slip flag of its own: a slip shows as a lock time that restarted.

use super::ids::{sat_id, signal};
use super::rawx::{RawMeasurement, RawX};
use crate::gnss::ephemeris::{EphemerisStore, GpsTime, RangingCode, Signal};
use crate::gnss::epoch_build::{
    complete_epoch, preferred_signals, unfilled_observation, BuiltEpoch, EpochStats,
};
use crate::gnss::ionosphere::{iono_free_pairs, IonosphereMode};
use crate::gnss::{CarrierPhase, Klobuchar, SatId, SatObservation};

/// Builds the single-frequency epoch of `raw` ([`IonosphereMode::Broadcast`]).
pub fn build_epoch(raw: &RawX, store: &EphemerisStore, klobuchar: Option<Klobuchar>) -> BuiltEpoch {
    build_epoch_with(raw, store, klobuchar, IonosphereMode::Broadcast)
}

/// Builds the epoch of `raw`: one [`SatObservation`] per satellite with a usable signal
/// (or pair, see `mode`) and an ephemeris in `store`; `klobuchar` is passed through.
pub fn build_epoch_with(
    raw: &RawX,
    store: &EphemerisStore,
    klobuchar: Option<Klobuchar>,
    mode: IonosphereMode,
) -> BuiltEpoch {
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
    let duplicated = satellites_with_duplicate_signals(raw);
    let mut candidates = Vec::new();
    for sat in sats {
        if duplicated.binary_search(&sat).is_ok() {
            stats.duplicate_signals += 1;
            continue;
        }
        let single = || choose(raw, sat).map(|(sig, m)| (RangingCode::Single(sig), m, None));
        let chosen = match mode {
            IonosphereMode::IonoFree => match choose_pair(raw, sat) {
                Some(pair) => Some(pair),
                // A satellite that single-frequency mode would use: its phase alone.
                None => match single() {
                    Some(_) if store.select(sat, &receive_time).is_none() => {
                        stats.no_ephemeris += 1;
                        continue;
                    }
                    Some(one) => {
                        stats.single_frequency += 1;
                        if !one.1.tracking.cp_valid {
                            continue;
                        }
                        Some(one)
                    }
                    None => None,
                },
            },
            IonosphereMode::Broadcast | IonosphereMode::None => single(),
        };
        let Some((code, m, second)) = chosen else {
            stats.unsupported += 1;
            continue;
        };
        match observation(sat, code, m, second, mode, raw.clock_reset) {
            Some(obs) => candidates.push((code, obs)),
            None => stats.unsupported += 1,
        }
    }
    let mut built = complete_epoch(receive_time, candidates, store, klobuchar, stats);
    if mode == IonosphereMode::IonoFree {
        // The single signals' ranges timed their satellites' transmission; now drop them.
        for (obs, code) in built.epoch.satellites.iter_mut().zip(&built.signals) {
            if matches!(code, RangingCode::Single(_)) {
                obs.pseudorange_m = None;
                obs.pseudorange_sigma_m = None;
                built.stats.phase_only += 1;
            }
        }
    }
    built
}

/// The satellites (sorted) of which `raw` holds two blocks of one signal.
fn satellites_with_duplicate_signals(raw: &RawX) -> Vec<SatId> {
    let mut keys: Vec<(u8, u8, u8)> = raw
        .measurements
        .iter()
        .map(|m| (m.gnss_id, m.sv_id, m.sig_id))
        .collect();
    keys.sort_unstable();
    let mut sats: Vec<SatId> = keys
        .windows(2)
        .filter(|w| w[0] == w[1])
        .filter_map(|w| sat_id(w[0].0, w[0].1))
        .collect();
    sats.sort();
    sats.dedup();
    sats
}

/// The usable measurement of `sat` on `wanted`.
fn measurement(raw: &RawX, sat: SatId, wanted: Signal) -> Option<&RawMeasurement> {
    raw.measurements.iter().find(|m| {
        sat_id(m.gnss_id, m.sv_id) == Some(sat)
            && signal(m.gnss_id, m.sig_id) == Some(wanted)
            && m.tracking.pr_valid
            && m.pseudorange_m.is_finite()
            && m.pseudorange_m > 0.0
    })
}

/// The preferred usable measurement of `sat`.
fn choose(raw: &RawX, sat: SatId) -> Option<(Signal, &RawMeasurement)> {
    preferred_signals(sat.constellation)
        .iter()
        .find_map(|&wanted| measurement(raw, sat, wanted).map(|m| (wanted, m)))
}

/// The preferred usable ionosphere-free pair of `sat`.
fn choose_pair(
    raw: &RawX,
    sat: SatId,
) -> Option<(RangingCode, &RawMeasurement, Option<&RawMeasurement>)> {
    iono_free_pairs(sat.constellation)
        .iter()
        .find_map(|&(first, second)| {
            let m1 = measurement(raw, sat, first)?;
            let m2 = measurement(raw, sat, second)?;
            Some((RangingCode::IonoFree { first, second }, m1, Some(m2)))
        })
}

/// The observation of `code` from its first signal's measurement `m` and, for a
/// combination, the second's; None if the combination is undefined.
fn observation(
    sat: SatId,
    code: RangingCode,
    m: &RawMeasurement,
    second: Option<&RawMeasurement>,
    mode: IonosphereMode,
    clock_reset: bool,
) -> Option<SatObservation> {
    let lambda_m = code.primary().wavelength_m();
    let finite = |v: f64| v.is_finite().then_some(v);
    let (pseudorange_m, pseudorange_sigma_m) = code.combine(
        (m.pseudorange_m, m.pseudorange_sigma_m),
        second.map(|s| (s.pseudorange_m, s.pseudorange_sigma_m)),
    )?;
    // Broadcast: unset, so the engine applies the epoch's Klobuchar model if any.
    let iono_delay_m = match mode {
        IonosphereMode::Broadcast => None,
        IonosphereMode::IonoFree | IonosphereMode::None => Some(0.0),
    };
    Some(SatObservation {
        pseudorange_rate_mps: finite(-lambda_m * m.doppler_hz),
        pseudorange_sigma_m: finite(pseudorange_sigma_m),
        pseudorange_rate_sigma_mps: finite(lambda_m * m.doppler_sigma_hz),
        cn0_dbhz: Some(m.cn0_dbhz),
        iono_delay_m,
        carrier_phase: carrier_phase(m, lambda_m, clock_reset),
        ..unfilled_observation(sat, pseudorange_m)
    })
}

/// The carrier phase of `m` (wavelength `lambda_m`) when trkStat marks it valid.
fn carrier_phase(m: &RawMeasurement, lambda_m: f64, clock_reset: bool) -> Option<CarrierPhase> {
    (m.tracking.cp_valid && m.carrier_phase_cycles.is_finite()).then(|| CarrierPhase {
        cycles: m.carrier_phase_cycles,
        wavelength_m: Some(lambda_m),
        sigma_cycles: (m.carrier_phase_sigma_cycles > 0.0).then_some(m.carrier_phase_sigma_cycles),
        lock_time_s: Some(m.lock_time_s),
        loss_of_lock: clock_reset,
        half_cycle_unresolved: !m.tracking.half_cycle_valid,
    })
}
