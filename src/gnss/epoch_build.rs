//! The part of building a [`GnssEpoch`] that does not depend on where the measurements
//! come from (UBX-RXM-RAWX or a RINEX observation file): the signal each satellite is
//! measured on, the satellite state at transmission from the broadcast ephemerides, and
//! the counts of what was used.
//!
//! Choices:
//! - One signal per satellite, the first of a preference list that was tracked with a
//!   valid pseudo-range: GPS and QZSS L1 C/A; Galileo E1, then E5b, then E5a; BeiDou
//!   B1I, then B3I, then B2I. These are the signals whose group delay the broadcast
//!   clock defines (see [`crate::gnss::ephemeris::group_delay_s`]); L2C/L5, B1C/B2a and
//!   E6 need CNAV-type corrections that are not decoded. GLONASS and SBAS are not used
//!   (no ephemeris model).
//! - Engine time axis: `t_s` = GPS seconds since 1980-01-06 (week · 604 800 + TOW) of
//!   the receive time.

use crate::gnss::ephemeris::{
    fill_satellite_fields, EphemerisError, EphemerisStore, GpsTime, RangingCode, Signal,
    SECONDS_PER_WEEK,
};
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

/// What happened to the measurements of an input epoch.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EpochStats {
    /// Measurements in the input (UBX: RAWX measurement blocks; RINEX: satellite lines).
    pub measurements: usize,
    /// Satellites seen (any signal).
    pub satellites: usize,
    /// Satellites of a system or with signals this crate does not use.
    pub unsupported: usize,
    /// Satellites left out because the input holds two measurements of one of their
    /// signals (corrupt or forged input: which one is right cannot be known).
    pub duplicate_signals: usize,
    /// Satellites without a dual-frequency pair (ionosphere-free mode): no range of
    /// theirs is used.
    pub single_frequency: usize,
    /// Of those, the satellites kept for their carrier phase and rate alone.
    pub phase_only: usize,
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

/// An observation of `sat` with its measured pseudo-range and everything else absent;
/// the satellite fields are zero until [`complete_epoch`] fills them.
pub fn unfilled_observation(sat: SatId, pseudorange_m: f64) -> SatObservation {
    SatObservation {
        sat,
        pseudorange_m: Some(pseudorange_m),
        pseudorange_rate_mps: None,
        pseudorange_sigma_m: None,
        pseudorange_rate_sigma_mps: None,
        cn0_dbhz: None,
        sat_pos_ecef_m: nalgebra::Vector3::zeros(),
        sat_vel_ecef_mps: nalgebra::Vector3::zeros(),
        sat_clock_bias_s: 0.0,
        sat_clock_drift_s_s: 0.0,
        iono_delay_m: None,
        tropo_delay_m: None,
        carrier_phase: None,
    }
}

/// The epoch received at `receive_time` from the chosen measurement of each satellite
/// (`candidates`: signal or combination, and the observation with its satellite fields
/// unfilled): each gets
/// its satellite state from the ephemeris `store` selects, or is counted and left out.
/// `stats` comes with the input counts (measurements, satellites, unsupported); the
/// ephemeris counts and `used` are added here. `klobuchar` is passed through.
pub fn complete_epoch(
    receive_time: GpsTime,
    candidates: impl IntoIterator<Item = (RangingCode, SatObservation)>,
    store: &EphemerisStore,
    klobuchar: Option<Klobuchar>,
    mut stats: EpochStats,
) -> BuiltEpoch {
    let mut satellites = Vec::new();
    let mut signals = Vec::new();
    for (signal, mut obs) in candidates {
        match fill_satellite_fields(&mut obs, store, signal, &receive_time) {
            Ok(_) => {
                satellites.push(obs);
                signals.push(signal);
            }
            Err(EphemerisError::NoEphemeris { .. }) => stats.no_ephemeris += 1,
            Err(_) => stats.ephemeris_errors += 1,
        }
    }
    stats.used = satellites.len();
    BuiltEpoch {
        epoch: GnssEpoch {
            t_s: f64::from(receive_time.week) * SECONDS_PER_WEEK + receive_time.tow_s,
            gps_time_of_week_s: receive_time.tow_s,
            satellites,
            klobuchar,
        },
        receive_time,
        signals,
        stats,
    }
}
