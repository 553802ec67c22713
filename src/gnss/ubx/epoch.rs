//! A [`GnssEpoch`] from one UBX-RXM-RAWX message and the broadcast ephemerides.
//!
//! Choices:
//! - Single frequency ([`IonosphereMode::Broadcast`], [`IonosphereMode::None`]): one
//!   signal per satellite, the first of a preference list that the receiver tracked
//!   with a valid pseudo-range: GPS and QZSS L1 C/A; Galileo E1, then E5b, then E5a;
//!   BeiDou B1I, then B3I, then B2I. These are the signals whose group delay the
//!   broadcast clock defines (see [`crate::gnss::ephemeris::group_delay_s`]); L2C/L5,
//!   B1C/B2a and E6 need CNAV-type corrections that are not decoded. GLONASS and SBAS
//!   are not used (no ephemeris model).
//! - [`IonosphereMode::IonoFree`]: the ionosphere-free combination of the first pair of
//!   [`iono_free_pairs`] with both pseudo-ranges valid, σ propagated from both prStdev;
//!   satellites without one are left out (counted as `single_frequency`). The rate is the
//!   first signal's Doppler: the ionosphere's rate of change (millimetres per second) is
//!   left in it.
//! - Receive time: the RAWX receiver time (week, rcvTow) as GPST, uncorrected for the
//!   receiver clock (see [`crate::gnss::ephemeris::state_at_transmission`]).
//! - Engine time axis: `t_s` = GPS seconds since 1980-01-06 (week · 604 800 + rcvTow).
//! - Rate: ρ̇ = −λ · D (u-blox Doppler is positive for an approaching satellite), σ_ρ̇ =
//!   λ · σ_D; the pseudo-range σ is the receiver's prStdev.

use super::ids::{sat_id, signal};
use super::rawx::{RawMeasurement, RawX};
use crate::gnss::ephemeris::{
    fill_satellite_fields, EphemerisError, EphemerisStore, GpsTime, RangingCode, Signal,
};
use crate::gnss::ionosphere::{iono_free_pairs, IonosphereMode};
use crate::gnss::{Constellation, GnssEpoch, Klobuchar, SatId, SatObservation};

/// Signals tried per constellation, best first.
pub fn preferred_signals(constellation: Constellation) -> &'static [Signal] {
    match constellation {
        Constellation::Gps => &[Signal::GpsL1Ca],
        Constellation::Qzss => &[Signal::QzssL1Ca],
        Constellation::Galileo => &[Signal::GalileoE1, Signal::GalileoE5b, Signal::GalileoE5a],
        Constellation::Beidou => &[Signal::BeidouB1I, Signal::BeidouB3I, Signal::BeidouB2I],
        Constellation::Glonass | Constellation::Sbas => &[],
    }
}

/// What happened to the measurements of a RAWX message.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EpochStats {
    /// Measurements in the message.
    pub measurements: usize,
    /// Satellites seen (any signal).
    pub satellites: usize,
    /// Satellites of a system or with signals this crate does not use.
    pub unsupported: usize,
    /// Satellites left out for lack of a dual-frequency pair (ionosphere-free mode).
    pub single_frequency: usize,
    /// Satellites skipped for lack of a healthy, valid ephemeris.
    pub no_ephemeris: usize,
    /// Satellites skipped for another ephemeris problem (group delay, non-finite).
    pub ephemeris_errors: usize,
    /// Satellites in the epoch.
    pub used: usize,
}

/// The epoch and how it was built.
#[derive(Debug, Clone, PartialEq)]
pub struct BuiltEpoch {
    /// The epoch for the engine.
    pub epoch: GnssEpoch,
    /// Receive time (GPST, receiver clock).
    pub receive_time: GpsTime,
    /// Signal or combination used for each satellite of `epoch.satellites`, in order.
    pub signals: Vec<RangingCode>,
    /// Counts.
    pub stats: EpochStats,
}

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
    let mut satellites = Vec::new();
    let mut signals = Vec::new();
    for sat in sats {
        let chosen = match mode {
            IonosphereMode::IonoFree => choose_pair(raw, sat),
            IonosphereMode::Broadcast | IonosphereMode::None => {
                choose(raw, sat).map(|(sig, m)| (RangingCode::Single(sig), m, None))
            }
        };
        let Some((code, m, second)) = chosen else {
            // Ionosphere-free mode: a satellite that single-frequency mode would use.
            let single = mode == IonosphereMode::IonoFree && choose(raw, sat).is_some();
            match (single, store.select(sat, &receive_time).is_some()) {
                (true, true) => stats.single_frequency += 1,
                (true, false) => stats.no_ephemeris += 1,
                (false, _) => stats.unsupported += 1,
            }
            continue;
        };
        let Some(mut obs) = observation(sat, code, m, second, mode) else {
            stats.unsupported += 1;
            continue;
        };
        match fill_satellite_fields(&mut obs, store, code, &receive_time) {
            Ok(_) => {
                satellites.push(obs);
                signals.push(code);
            }
            Err(EphemerisError::NoEphemeris { .. }) => stats.no_ephemeris += 1,
            Err(_) => stats.ephemeris_errors += 1,
        }
    }
    stats.used = satellites.len();
    BuiltEpoch {
        epoch: GnssEpoch {
            t_s: f64::from(receive_time.week) * crate::gnss::ephemeris::SECONDS_PER_WEEK
                + receive_time.tow_s,
            gps_time_of_week_s: receive_time.tow_s,
            satellites,
            klobuchar,
        },
        receive_time,
        signals,
        stats,
    }
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
        sat,
        pseudorange_m,
        pseudorange_rate_mps: finite(-lambda_m * m.doppler_hz),
        pseudorange_sigma_m: finite(pseudorange_sigma_m),
        pseudorange_rate_sigma_mps: finite(lambda_m * m.doppler_sigma_hz),
        cn0_dbhz: Some(m.cn0_dbhz),
        sat_pos_ecef_m: nalgebra::Vector3::zeros(),
        sat_vel_ecef_mps: nalgebra::Vector3::zeros(),
        sat_clock_bias_s: 0.0,
        sat_clock_drift_s_s: 0.0,
        iono_delay_m,
        tropo_delay_m: None,
    })
}
