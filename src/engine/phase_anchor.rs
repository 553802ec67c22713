//! The previous GNSS epoch's carrier phases, kept with the filter state for the
//! time-differenced carrier phase (TDCP) of the next epoch: each satellite's phase, its
//! lock indicators, its pseudo-range rate and its pseudo-range predicted from the state
//! after that epoch's update.
//!
//! Choice: the anchor lives in [`super::FilterState`] (behind an `Arc`, so the states
//! stored for roll-backs share it): a roll-back re-applies an epoch against the anchor
//! that was current then.

use nalgebra::Vector3;

use crate::config::Config;
use crate::filter::measurement_rows::AntennaGeometry;
use crate::gnss::{geometry, CarrierPhase, GnssEpoch, SatId};

use super::filter_state::FilterState;

/// One satellite's phase at the anchor epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnchoredPhase {
    pub sat: SatId,
    pub phase: CarrierPhase,
    /// The measured pseudo-range rate (m/s), for the Doppler slip test.
    pub pseudorange_rate_mps: Option<f64>,
    /// The pseudo-range predicted from the updated state at the anchor epoch (m): the
    /// geometric range from the antenna of then, receiver and satellite clocks, delays.
    pub predicted_pseudorange_m: f64,
}

/// The carrier phases of one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseAnchor {
    pub t_s: f64,
    pub satellites: Vec<AnchoredPhase>,
}

impl PhaseAnchor {
    /// The anchor of `epoch` at the updated `state`; `w_ib_b_rad_s` is the compensated body
    /// rate (lever-arm velocity). None when no satellite has a phase.
    pub fn record(
        epoch: &GnssEpoch,
        state: &FilterState,
        w_ib_b_rad_s: &Vector3<f64>,
        config: &Config,
    ) -> Option<Self> {
        let geo = AntennaGeometry::new(&state.nav, &config.mounting.lever_arm_b_m, w_ib_b_rad_s);
        let rx_pos = geo.antenna_ecef_m(&state.nav.p);
        let rx_vel = geo.antenna_velocity_ecef_mps(&state.nav.v_n);
        let satellites: Vec<AnchoredPhase> = epoch
            .satellites
            .iter()
            .filter_map(|obs| {
                let phase = obs.carrier_phase?;
                let prediction = geometry::predict(
                    obs,
                    &rx_pos,
                    &rx_vel,
                    state.clock_bias_m,
                    state.clock_drift_mps,
                    epoch.klobuchar.as_ref(),
                    epoch.gps_time_of_week_s,
                )
                .ok()?;
                Some(AnchoredPhase {
                    sat: obs.sat,
                    phase,
                    pseudorange_rate_mps: obs.pseudorange_rate_mps,
                    predicted_pseudorange_m: prediction.pseudorange_m,
                })
            })
            .collect();
        (!satellites.is_empty()).then_some(Self {
            t_s: epoch.t_s,
            satellites,
        })
    }

    /// The anchored phase of `sat`, if any.
    pub fn get(&self, sat: SatId) -> Option<&AnchoredPhase> {
        self.satellites.iter().find(|a| a.sat == sat)
    }
}
