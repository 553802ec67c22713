//! The wheel speed (wheel odometry): the forward speed in the vehicle's (body) frame of
//! the point between its wheels (`mounting.constraint_point_lever_arm_m`), as the base
//! controller measures it.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::filter::robust_update::UpdateOutcome;

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};
use super::point_velocity::{point_velocity_b, point_velocity_rows};

/// The forward (body x) velocity of the point at `lever_arm_b_m` at the state's last IMU
/// sample is `speed_mps`, with σ `sigma_mps` (math in [`super::point_velocity`]).
///
/// Choice: the scale factor is a fixed parameter (`wheel_odometry.scale_factor`) the
/// caller has applied to `speed_mps` and `sigma_mps`; a scale-factor state would change
/// the error state and is not carried.
pub struct WheelSpeed<'a> {
    pub t_s: f64,
    pub lever_arm_b_m: &'a Vector3<f64>,
    pub speed_mps: f64,
    pub sigma_mps: f64,
}

/// The body axis measured: x (forward).
const AXES: [usize; 1] = [0];

impl MeasurementModel for WheelSpeed<'_> {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::WheelSpeed
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let v = point_velocity_b(state, self.lever_arm_b_m);
        Linearization {
            rows: point_velocity_rows(state, self.lever_arm_b_m, &AXES),
            measured: vec![self.speed_mps],
            predicted: vec![v[AXES[0]]],
            noise: NominalNoise::Joint(DMatrix::from_element(1, 1, self.sigma_mps.powi(2))),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let v = point_velocity_b(state, self.lever_arm_b_m);
        DVector::from_iterator(rows.len(), rows.iter().map(|&i| v[AXES[i]]))
    }

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
