//! The satellite at signal transmission time, as a receiver's observation needs it.

use thiserror::Error;

use super::kepler::{KeplerianEphemeris, SatState};
use super::ranging::RangingCode;
use super::signal::Signal;
use super::store::EphemerisStore;
use super::time::GpsTime;
use crate::earth::SPEED_OF_LIGHT_M_S;
use crate::gnss::{SatId, SatObservation};

/// Iterations of t_tx = t_rx − ρ/c − Δt_sv(t_tx). The clock changes by less than 10⁻⁹ s
/// per second of time, so the second pass changes t_tx by < 10⁻¹⁰ s; three are ample.
const TRANSMISSION_TIME_ITERATIONS: usize = 3;

/// Why the satellite state of an observation could not be computed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EphemerisError {
    /// No healthy ephemeris valid at the time.
    #[error("{sat}: no healthy ephemeris valid at GPS week {week} TOW {tow_s:.3} s")]
    NoEphemeris { sat: SatId, week: i32, tow_s: f64 },
    /// The ephemeris has no group-delay correction for the signal (one of the two of a
    /// combination).
    #[error("{sat}: ephemeris has no group delay for signal {signal:?}")]
    NoGroupDelay { sat: SatId, signal: Signal },
    /// A non-finite input or result.
    #[error("{sat}: non-finite {what}")]
    NonFinite { sat: SatId, what: &'static str },
}

/// Satellite state at the transmission time of a signal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransmitState {
    /// Transmission time (GPST).
    pub t_tx: GpsTime,
    /// Position, velocity and clock at t_tx; position in the ECEF frame of t_tx.
    pub state: SatState,
    /// Group delay applied for the measurement (signal or combination) (s).
    pub group_delay_s: f64,
    /// Clock offset for this measurement: `state.clock_bias_s − group_delay_s` (s).
    pub clock_bias_s: f64,
}

/// Evaluates `eph` at the transmission time of a signal (or a combination of signals, see
/// [`RangingCode`]) received at GPST `t_rx` (receiver clock) with pseudo-range
/// `pseudorange_m`:
///   t_tx = t_rx − ρ/c − Δt_sv(t_tx),  Δt_sv = clock polynomial + relativistic − T_GD.
///
/// Choice: the receiver clock offset is not known here and is not removed from t_rx, as
/// in common practice; a 1 ms receiver offset shifts the satellite by ~4 m along its
/// track, mostly absorbed by the receiver clock estimate.
pub fn state_at_transmission(
    eph: &KeplerianEphemeris,
    code: impl Into<RangingCode>,
    t_rx: &GpsTime,
    pseudorange_m: f64,
) -> Result<TransmitState, EphemerisError> {
    let sat = eph.sat;
    let code = code.into();
    if !pseudorange_m.is_finite() || !t_rx.is_finite() {
        return Err(EphemerisError::NonFinite {
            sat,
            what: "pseudo-range or receive time",
        });
    }
    let group_delay_s = code
        .group_delay_s(eph)
        .map_err(|signal| EphemerisError::NoGroupDelay { sat, signal })?;
    let t_nominal = t_rx.add_seconds(-pseudorange_m / SPEED_OF_LIGHT_M_S);
    let mut clock_bias_s = 0.0;
    let mut result = None;
    for _ in 0..TRANSMISSION_TIME_ITERATIONS {
        let t_tx = t_nominal.add_seconds(-clock_bias_s);
        let state = eph.state_at(&t_tx).ok_or(EphemerisError::NonFinite {
            sat,
            what: "ephemeris elements",
        })?;
        clock_bias_s = state.clock_bias_s - group_delay_s;
        result = Some((t_tx, state));
    }
    let (t_tx, state) = result.ok_or(EphemerisError::NonFinite {
        sat,
        what: "transmission time",
    })?;
    let finite = state.pos_ecef_m.iter().all(|v| v.is_finite())
        && state.vel_ecef_mps.iter().all(|v| v.is_finite())
        && clock_bias_s.is_finite()
        && state.clock_drift_s_s.is_finite();
    if !finite {
        return Err(EphemerisError::NonFinite {
            sat,
            what: "satellite state",
        });
    }
    Ok(TransmitState {
        t_tx,
        state,
        group_delay_s,
        clock_bias_s,
    })
}

/// Fills the satellite fields of `obs` (position at transmission in the ECEF frame of
/// that time, velocity, clock bias with relativistic term and the measurement's group
/// delay (one signal's, or a combination's, see [`RangingCode`]),
/// clock drift) from the ephemeris `store` selects for `obs.sat` at the receive time
/// `t_rx`, using `obs.pseudorange_m` for the travel time (an observation without one is
/// refused as non-finite).
pub fn fill_satellite_fields(
    obs: &mut SatObservation,
    store: &EphemerisStore,
    code: impl Into<RangingCode>,
    t_rx: &GpsTime,
) -> Result<TransmitState, EphemerisError> {
    let sat = obs.sat;
    let eph = store.select(sat, t_rx).ok_or(EphemerisError::NoEphemeris {
        sat,
        week: t_rx.week,
        tow_s: t_rx.tow_s,
    })?;
    let pseudorange_m = obs.pseudorange_m.unwrap_or(f64::NAN);
    let tx = state_at_transmission(eph, code, t_rx, pseudorange_m)?;
    obs.sat_pos_ecef_m = tx.state.pos_ecef_m;
    obs.sat_vel_ecef_mps = tx.state.vel_ecef_mps;
    obs.sat_clock_bias_s = tx.clock_bias_s;
    obs.sat_clock_drift_s_s = tx.state.clock_drift_s_s;
    Ok(tx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::ephemeris::GroupDelay;

    fn g32() -> KeplerianEphemeris {
        super::super::kepler::tests::g32()
    }

    #[test]
    fn transmission_time_satisfies_the_light_time_equation() {
        let eph = g32();
        let t_rx = GpsTime::new(2381, 408_660.0);
        let pseudorange_m = 22_000_000.0;
        let tx = state_at_transmission(&eph, Signal::GpsL1Ca, &t_rx, pseudorange_m).unwrap();
        // t_tx = t_rx − ρ/c − (clock − TGD), to the resolution of a seconds-of-week f64
        // (≈ 1.2·10⁻¹⁰ s near 4·10⁵ s, i.e. < 1 µm of satellite motion).
        let expected = t_rx.seconds_since(&tx.t_tx) - pseudorange_m / SPEED_OF_LIGHT_M_S;
        assert!((expected - tx.clock_bias_s).abs() < 3e-10);
        let GroupDelay::Gps { tgd_s } = eph.group_delay else {
            unreachable!()
        };
        assert_eq!(tx.group_delay_s, tgd_s);
        assert!((tx.clock_bias_s - (tx.state.clock_bias_s - tgd_s)).abs() < 1e-18);
        assert!(matches!(
            state_at_transmission(&eph, Signal::GalileoE1, &t_rx, pseudorange_m),
            Err(EphemerisError::NoGroupDelay { .. })
        ));
        assert!(matches!(
            state_at_transmission(&eph, Signal::GpsL1Ca, &t_rx, f64::NAN),
            Err(EphemerisError::NonFinite { .. })
        ));
    }
}
