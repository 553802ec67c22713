//! The velocity of a point of the vehicle in the vehicle's (body) frame, and its rows of H:
//! what the non-holonomic constraint ([`super::NonHolonomic`]) and the wheel speed
//! ([`super::WheelSpeed`]) measure.
//!
//! Math note: the point's body velocity is v_p^b = C_n^b v^n + ω × l, l the point's lever
//! arm from the IMU. With δV = computed − true, C_b^n(true) = exp(φ×) C_b^n(computed) and
//! the compensated rate ω + δb (δb the bias error the feedback adds to the estimate),
//! v_p^b(computed) − v_p^b(true) = C_n^b δV − C_n^b [v^n×] φ − [l×] δb, the gyro part on
//! the constant and the Gauss-Markov block alike, and − [l×] diag(ω) δs_g on the gyro
//! scale-factor block (whose rate error is diag(ω) δs_g).

use nalgebra::Vector3;

use crate::filter::measurement_rows::Row;
use crate::ins::error_state::{DV, GYRO_BIAS, GYRO_GM, GYRO_SCALE, PHI};

use super::super::filter_state::FilterState;

/// The velocity (m/s) in the body frame of the point at `lever_arm_b_m` from the IMU, at
/// the state's last IMU sample.
pub(super) fn point_velocity_b(state: &FilterState, lever_arm_b_m: &Vector3<f64>) -> Vector3<f64> {
    let w = state.compensate(&state.last_imu).w_ib_b_rad_s;
    state.nav.q_nb.inverse_transform_vector(&state.nav.v_n) + w.cross(lever_arm_b_m)
}

/// The rows of H of the body `axes` (0 forward, 1 left, 2 up) of that velocity.
pub(super) fn point_velocity_rows(
    state: &FilterState,
    lever_arm_b_m: &Vector3<f64>,
    axes: &[usize],
) -> Vec<Row> {
    let c_nb = state.nav.q_nb.inverse().to_rotation_matrix().into_inner();
    let d_dphi = -(c_nb * state.nav.v_n.cross_matrix());
    let d_db = -lever_arm_b_m.cross_matrix();
    let w = state.compensate(&state.last_imu).w_ib_b_rad_s;
    let d_dsg = d_db * nalgebra::Matrix3::from_diagonal(&w);
    axes.iter()
        .map(|&axis| {
            let mut row = Row::zeros();
            row.fixed_view_mut::<1, 3>(0, DV).copy_from(&c_nb.row(axis));
            row.fixed_view_mut::<1, 3>(0, PHI)
                .copy_from(&d_dphi.row(axis));
            row.fixed_view_mut::<1, 3>(0, GYRO_BIAS)
                .copy_from(&d_db.row(axis));
            row.fixed_view_mut::<1, 3>(0, GYRO_GM)
                .copy_from(&d_db.row(axis));
            row.fixed_view_mut::<1, 3>(0, GYRO_SCALE)
                .copy_from(&d_dsg.row(axis));
            row
        })
        .collect()
}
