//! The non-holonomic constraint (NHC) of a wheeled vehicle: the point between its wheels
//! (`mounting.constraint_point_lever_arm_m`) moves neither sideways nor up or down in the
//! vehicle's (body) frame.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::filter::robust_update::UpdateOutcome;

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};
use super::point_velocity::{point_velocity_b, point_velocity_rows};

/// The lateral (body y) and vertical (body z) velocity of the constraint point at the
/// state's last IMU sample is zero, with σ `sigma_lateral_mps` and `sigma_vertical_mps`
/// (math in [`super::point_velocity`]).
pub struct NonHolonomic<'a> {
    pub t_s: f64,
    pub lever_arm_b_m: &'a Vector3<f64>,
    pub sigma_lateral_mps: f64,
    pub sigma_vertical_mps: f64,
}

/// The body axes the constraint holds: y (left) and z (up).
const AXES: [usize; 2] = [1, 2];

impl MeasurementModel for NonHolonomic<'_> {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::NonHolonomic
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let v = point_velocity_b(state, self.lever_arm_b_m);
        let variances = DVector::from_vec(vec![
            self.sigma_lateral_mps.powi(2),
            self.sigma_vertical_mps.powi(2),
        ]);
        Linearization {
            rows: point_velocity_rows(state, self.lever_arm_b_m, &AXES),
            measured: vec![0.0; 2],
            predicted: AXES.iter().map(|&axis| v[axis]).collect(),
            noise: NominalNoise::Joint(DMatrix::from_diagonal(&variances)),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let v = point_velocity_b(state, self.lever_arm_b_m);
        DVector::from_iterator(rows.len(), rows.iter().map(|&i| v[AXES[i]]))
    }

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
