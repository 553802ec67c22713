//! The non-holonomic constraint (NHC) of a wheeled vehicle: the point between its wheels
//! (`mounting.constraint_point_lever_arm_m`) moves neither sideways nor up or down in the
//! vehicle's (body) frame.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::filter::measurement_rows::Row;
use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::{DV, GYRO_BIAS, GYRO_GM, PHI};

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};

/// The lateral (body y) and vertical (body z) velocity of the constraint point at the
/// state's last IMU sample is zero, with σ `sigma_lateral_mps` and `sigma_vertical_mps`.
///
/// Math note: the point's body velocity is v_p^b = C_n^b v^n + ω × l. With δV = computed −
/// true, C_b^n(true) = exp(φ×) C_b^n(computed) and the compensated rate ω + δb (δb the
/// bias error the feedback adds to the estimate), v_p^b(computed) − v_p^b(true) =
/// C_n^b δV − C_n^b [v^n×] φ − [l×] δb, the gyro part on the constant and the
/// Gauss-Markov block alike.
pub struct NonHolonomic<'a> {
    pub t_s: f64,
    pub lever_arm_b_m: &'a Vector3<f64>,
    pub sigma_lateral_mps: f64,
    pub sigma_vertical_mps: f64,
}

/// The body axes the constraint holds: y (left) and z (up).
const AXES: [usize; 2] = [1, 2];

impl NonHolonomic<'_> {
    /// The constraint point's velocity in the body frame (m/s).
    fn point_velocity_b(&self, state: &FilterState) -> Vector3<f64> {
        let w = state.compensate(&state.last_imu).w_ib_b_rad_s;
        state.nav.q_nb.inverse_transform_vector(&state.nav.v_n) + w.cross(self.lever_arm_b_m)
    }
}

impl MeasurementModel for NonHolonomic<'_> {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::NonHolonomic
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let c_nb = state.nav.q_nb.inverse().to_rotation_matrix().into_inner();
        let d_dphi = -(c_nb * state.nav.v_n.cross_matrix());
        let d_db = -self.lever_arm_b_m.cross_matrix();
        let rows = AXES
            .iter()
            .map(|&axis| {
                let mut row = Row::zeros();
                row.fixed_view_mut::<1, 3>(0, DV).copy_from(&c_nb.row(axis));
                row.fixed_view_mut::<1, 3>(0, PHI)
                    .copy_from(&d_dphi.row(axis));
                row.fixed_view_mut::<1, 3>(0, GYRO_BIAS)
                    .copy_from(&d_db.row(axis));
                row.fixed_view_mut::<1, 3>(0, GYRO_GM)
                    .copy_from(&d_db.row(axis));
                row
            })
            .collect();
        let v = self.point_velocity_b(state);
        let variances = DVector::from_vec(vec![
            self.sigma_lateral_mps.powi(2),
            self.sigma_vertical_mps.powi(2),
        ]);
        Linearization {
            rows,
            measured: vec![0.0; 2],
            predicted: AXES.iter().map(|&axis| v[axis]).collect(),
            noise: NominalNoise::Joint(DMatrix::from_diagonal(&variances)),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let v = self.point_velocity_b(state);
        DVector::from_iterator(rows.len(), rows.iter().map(|&i| v[AXES[i]]))
    }

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
