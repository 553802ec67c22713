//! A [`GnssEpoch`] from one UBX-RXM-RAWX message and the broadcast ephemerides.
//!
//! Choices:
//! - One signal per satellite, the first of a preference list that the receiver tracked
//!   with a valid pseudo-range: GPS and QZSS L1 C/A; Galileo E1, then E5b, then E5a;
//!   BeiDou B1I, then B3I, then B2I. These are the signals whose group delay the
//!   broadcast clock defines (see [`crate::gnss::ephemeris::group_delay_s`]); L2C/L5,
//!   B1C/B2a and E6 need CNAV-type corrections that are not decoded. GLONASS and SBAS
//!   are not used (no ephemeris model).
//! - Receive time: the RAWX receiver time (week, rcvTow) as GPST, uncorrected for the
//!   receiver clock (see [`crate::gnss::ephemeris::state_at_transmission`]).
//! - Engine time axis: `t_s` = GPS seconds since 1980-01-06 (week · 604 800 + rcvTow).
//! - Rate: ρ̇ = −λ · D (u-blox Doppler is positive for an approaching satellite), σ_ρ̇ =
//!   λ · σ_D; the pseudo-range σ is the receiver's prStdev.

use super::ids::{sat_id, signal};
use super::rawx::{RawMeasurement, RawX};
use crate::gnss::ephemeris::{
    fill_satellite_fields, EphemerisError, EphemerisStore, GpsTime, Signal,
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

/// What happened to the measurements of a RAWX message.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EpochStats {
    /// Measurements in the message.
    pub measurements: usize,
    /// Satellites seen (any signal).
    pub satellites: usize,
    /// Satellites of a system or with signals this crate does not use.
    pub unsupported: usize,
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
    /// Signal used for each satellite of `epoch.satellites`, in the same order.
    pub signals: Vec<Signal>,
    /// Counts.
    pub stats: EpochStats,
}

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
    let mut satellites = Vec::new();
    let mut signals = Vec::new();
    for sat in sats {
        let Some((sig, m)) = choose(raw, sat) else {
            stats.unsupported += 1;
            continue;
        };
        let mut obs = observation(sat, sig, m);
        match fill_satellite_fields(&mut obs, store, sig, &receive_time) {
            Ok(_) => {
                satellites.push(obs);
                signals.push(sig);
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
        sat,
        pseudorange_m: m.pseudorange_m,
        pseudorange_rate_mps: finite(-lambda_m * m.doppler_hz),
        pseudorange_sigma_m: finite(m.pseudorange_sigma_m),
        pseudorange_rate_sigma_mps: finite(lambda_m * m.doppler_sigma_hz),
        cn0_dbhz: Some(m.cn0_dbhz),
        sat_pos_ecef_m: nalgebra::Vector3::zeros(),
        sat_vel_ecef_mps: nalgebra::Vector3::zeros(),
        sat_clock_bias_s: 0.0,
        sat_clock_drift_s_s: 0.0,
        iono_delay_m: None,
        tropo_delay_m: None,
    }
}
