//! A [`GnssEpoch`](crate::gnss::GnssEpoch) from one RINEX observation epoch and the
//! broadcast ephemerides, through the same satellite-state computation as the UBX path
//! ([`crate::gnss::epoch_build`]).
//!
//! Choices (beyond the shared ones):
//! - Signal → RINEX 3 pseudo-range codes, best first: GPS and QZSS L1 C/A `C1C`;
//!   Galileo E1 `C1C`, `C1X`, `C1B`; E5a `C5Q`, `C5X`, `C5I`; E5b `C7Q`, `C7X`, `C7I`;
//!   BeiDou B1I `C2I`, `C2X`, `C1I` (the RINEX 3.02 name), B3I `C6I`, `C6X`, B2I `C7I`,
//!   `C7X`. The Doppler and signal strength are read from the same band and attribute
//!   (`D1C`, `S1C`, ...).
//! - Receive time: the epoch time as GPST, receiver clock, uncorrected by any receiver
//!   clock offset written on the epoch line (as for UBX).
//! - Rate: ρ̇ = −λ · D (RINEX Doppler is positive for an approaching satellite). RINEX
//!   carries no measurement σ: both σ fields are None. C/N0 is the `S` value as written
//!   (dB-Hz in files by receivers' converters).
//! - Carrier phase: the `L` value of the same band and attribute (cycles of the signal's
//!   wavelength), its LLI bit 0 the loss of lock, bit 1 the unresolved half cycle; RINEX
//!   has no lock time and no phase σ.

use super::header::ObsCode;
use super::record::{ObsEpoch, SatRecord};
use crate::gnss::ephemeris::{EphemerisStore, RangingCode, Signal};
use crate::gnss::epoch_build::{
    complete_epoch, preferred_signals, unfilled_observation, BuiltEpoch, EpochStats,
};
use crate::gnss::{CarrierPhase, Klobuchar, SatObservation};

/// RINEX 3 pseudo-range codes of `signal`, best first (empty: not read from RINEX).
pub fn pseudorange_codes(signal: Signal) -> &'static [&'static str] {
    match signal {
        Signal::GpsL1Ca | Signal::QzssL1Ca => &["C1C"],
        Signal::GalileoE1 => &["C1C", "C1X", "C1B"],
        Signal::GalileoE5a => &["C5Q", "C5X", "C5I"],
        Signal::GalileoE5b => &["C7Q", "C7X", "C7I"],
        Signal::BeidouB1I => &["C2I", "C2X", "C1I"],
        Signal::BeidouB3I => &["C6I", "C6X"],
        Signal::BeidouB2I => &["C7I", "C7X"],
        Signal::GpsL2C
        | Signal::GpsL5
        | Signal::GalileoE6
        | Signal::BeidouB1C
        | Signal::BeidouB2a
        | Signal::SbasL1 => &[],
    }
}

/// Builds the [`GnssEpoch`](crate::gnss::GnssEpoch) of `epoch`: one observation per
/// satellite with a usable signal and an ephemeris in `store`; `klobuchar` is passed
/// through.
pub fn build_rinex_epoch(
    epoch: &ObsEpoch,
    store: &EphemerisStore,
    klobuchar: Option<Klobuchar>,
) -> BuiltEpoch {
    let mut stats = EpochStats {
        measurements: epoch.satellites.len(),
        ..EpochStats::default()
    };
    let mut records: Vec<&SatRecord> = epoch.satellites.iter().collect();
    records.sort_by_key(|r| r.sat);
    records.dedup_by_key(|r| r.sat);
    stats.satellites = records.len();
    let mut candidates = Vec::new();
    for record in records {
        match choose(record) {
            Some((signal, obs)) => candidates.push((RangingCode::Single(signal), obs)),
            None => stats.unsupported += 1,
        }
    }
    complete_epoch(epoch.time, candidates, store, klobuchar, stats)
}

/// The preferred signal of `record` with a positive pseudo-range, as an observation.
fn choose(record: &SatRecord) -> Option<(Signal, SatObservation)> {
    preferred_signals(record.sat.constellation)
        .iter()
        .find_map(|&signal| {
            pseudorange_codes(signal).iter().find_map(|text| {
                let code = ObsCode::parse(text)?;
                let pseudorange_m = record.get(code)?.value;
                (pseudorange_m > 0.0)
                    .then(|| (signal, observation(record, signal, code, pseudorange_m)))
            })
        })
}

fn observation(
    record: &SatRecord,
    signal: Signal,
    code: ObsCode,
    pseudorange_m: f64,
) -> SatObservation {
    let value = |kind: u8| record.get(code.with_type(kind)).map(|v| v.value);
    let phase = record.get(code.with_type(b'L'));
    SatObservation {
        pseudorange_rate_mps: value(b'D').map(|d| -signal.wavelength_m() * d),
        cn0_dbhz: value(b'S'),
        carrier_phase: phase.map(|p| {
            let lli = p.lli.unwrap_or(0);
            CarrierPhase {
                cycles: p.value,
                wavelength_m: Some(signal.wavelength_m()),
                sigma_cycles: None,
                lock_time_s: None,
                loss_of_lock: lli & 0x01 != 0,
                half_cycle_unresolved: lli & 0x02 != 0,
            }
        }),
        ..unfilled_observation(record.sat, pseudorange_m)
    }
}
