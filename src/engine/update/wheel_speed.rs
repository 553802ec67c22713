//! The wheel speed (wheel odometry): the forward speed in the vehicle's (body) frame of
//! the point between its wheels (`mounting.constraint_point_lever_arm_m`), as the base
//! controller reports it, through the state's wheel scale factor.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::WHEEL_SCALE;

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};
use super::point_velocity::{point_velocity_b, point_velocity_rows};

/// The reported forward speed `speed_mps` of the point at `lever_arm_b_m` at the state's
/// last IMU sample, with σ `sigma_mps` (both as reported): the point's forward (body x)
/// velocity v (math in [`super::point_velocity`]) divided by the state's scale factor s
/// (true speed per reported one).
///
/// Math note: the prediction is v̂/ŝ; with the scale-factor error δs = s − ŝ (the estimate
/// takes + δŝ as the biases do) and v̂ − v = H_v δx, v̂/ŝ − v/s ≈ H_v δx / ŝ + v̂ δs / ŝ²:
/// the velocity rows divided by ŝ and v̂/ŝ² in the scale factor's column. With the state
/// off (`wheel_odometry.scale_factor_state`) the column meets a zero row of P and ŝ stays
/// `wheel_odometry.scale_factor`: the fixed factor of the reported speed.
pub struct WheelSpeed<'a> {
    pub t_s: f64,
    pub lever_arm_b_m: &'a Vector3<f64>,
    pub speed_mps: f64,
    pub sigma_mps: f64,
}

/// The body axis measured: x (forward).
const AXES: [usize; 1] = [0];

/// The forward speed the wheels should report for `state`: v / s.
fn reported_mps(state: &FilterState, lever_arm_b_m: &Vector3<f64>) -> f64 {
    point_velocity_b(state, lever_arm_b_m)[AXES[0]] / state.wheel_scale_factor
}

impl MeasurementModel for WheelSpeed<'_> {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::WheelSpeed
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let scale = state.wheel_scale_factor;
        let predicted = reported_mps(state, self.lever_arm_b_m);
        let mut rows = point_velocity_rows(state, self.lever_arm_b_m, &AXES);
        for row in &mut rows {
            *row /= scale;
            row[WHEEL_SCALE] = predicted / scale;
        }
        Linearization {
            rows,
            measured: vec![self.speed_mps],
            predicted: vec![predicted],
            noise: NominalNoise::Joint(DMatrix::from_element(1, 1, self.sigma_mps.powi(2))),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let v = reported_mps(state, self.lever_arm_b_m);
        DVector::from_element(rows.len(), v)
    }

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
