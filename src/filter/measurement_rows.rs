//! Rows of the measurement matrix H for the tightly-coupled (pseudo-range, rate; eqs. 7–9)
//! and loosely-coupled (position, velocity) measurements, in the closed-loop error state.
//!
//! Math note: every measurement is y = predicted(nominal) − measured ≈ H δx + noise, with
//! δx = computed − true. For the antenna at lever arm l^b from the IMU:
//! - position: r_ant^n = r_imu^n + C_b^n l^b, so δr_ant^n = D δp + (C_b^n l^b) × φ, with
//!   D = ∂(E, N, U)/∂(L, λ, h) = [[0, (R_N+h)cos L, 0], [R_M+h, 0, 0], [0, 0, 1]];
//! - velocity: v_ant^n = v^n + C_b^n (ω_ib^b × l^b) (earth-rate terms of the lever arm are
//!   below 1e-4 m/s and neglected), so δv_ant^n = δV + (C_b^n (ω × l)) × φ;
//! - a pseudo-range ρ = |r_sat − r_ant| + c δt_u gives ∂ρ/∂r_ant = −u (u the unit
//!   line of sight receiver → satellite); the rate ρ̇ = u·(v_sat − v_ant) + c δt_ru gives
//!   ∂ρ̇/∂v_ant = −u (the dependence of u on position is second order and neglected).

use nalgebra::{Matrix3, RowSVector, Vector3};

use crate::earth::{self, Llh};
use crate::ins::error_state::{StateMatrix, CLOCK_BIAS, CLOCK_DRIFT, DP, DV, N, PHI};
use crate::ins::NavState;

/// One row of H.
pub type Row = RowSVector<f64, N>;

/// h P hᵀ: the variance of the row h's prediction under the error covariance P.
pub fn row_variance(row: &Row, p: &StateMatrix) -> f64 {
    (row * p * row.transpose())[(0, 0)]
}

/// Geometry shared by the rows of one epoch.
#[derive(Debug, Clone, Copy)]
pub struct AntennaGeometry {
    /// ∂(E, N, U)/∂(L, λ, h) at the nominal position.
    d_enu_d_llh: Matrix3<f64>,
    /// C_b^n l^b (m).
    lever_n: Vector3<f64>,
    /// C_b^n (ω_ib^b × l^b) (m/s).
    lever_velocity_n: Vector3<f64>,
    /// ECEF → ENU rotation at the nominal position.
    c_en: Matrix3<f64>,
}

impl AntennaGeometry {
    pub fn new(nav: &NavState, lever_arm_b_m: &Vector3<f64>, w_ib_b_rad_s: &Vector3<f64>) -> Self {
        let (north, east) = earth::metres_per_radian(&nav.p);
        let d_enu_d_llh = Matrix3::new(0.0, east, 0.0, north, 0.0, 0.0, 0.0, 0.0, 1.0);
        let c_bn = nav.q_nb.to_rotation_matrix().into_inner();
        Self {
            d_enu_d_llh,
            lever_n: c_bn * lever_arm_b_m,
            lever_velocity_n: c_bn * w_ib_b_rad_s.cross(lever_arm_b_m),
            c_en: earth::rot_ecef_to_enu(&nav.p),
        }
    }

    /// Antenna position (ECEF, m) for the nominal IMU position `p`.
    pub fn antenna_ecef_m(&self, p: &Llh) -> Vector3<f64> {
        earth::llh_to_ecef(p) + self.c_en.transpose() * self.lever_n
    }

    /// Antenna velocity (ECEF, m/s) for the nominal ENU velocity `v_n`.
    pub fn antenna_velocity_ecef_mps(&self, v_n: &Vector3<f64>) -> Vector3<f64> {
        self.c_en.transpose() * (v_n + self.lever_velocity_n)
    }

    /// Antenna position in ENU relative to the IMU position (m).
    pub fn lever_enu_m(&self) -> Vector3<f64> {
        self.lever_n
    }

    /// Antenna velocity offset from the lever arm, ENU (m/s).
    pub fn lever_velocity_enu_mps(&self) -> Vector3<f64> {
        self.lever_velocity_n
    }

    /// Row of a pseudo-range with unit line of sight `los_ecef` (receiver → satellite).
    pub fn pseudorange_row(&self, los_ecef: &Vector3<f64>) -> Row {
        let u_n = self.c_en * los_ecef;
        let mut row = Row::zeros();
        let d_dp = -(u_n.transpose() * self.d_enu_d_llh);
        let d_dphi = -(u_n.transpose() * self.lever_n.cross_matrix());
        row.fixed_view_mut::<1, 3>(0, DP).copy_from(&d_dp);
        row.fixed_view_mut::<1, 3>(0, PHI).copy_from(&d_dphi);
        row[CLOCK_BIAS] = 1.0;
        row
    }

    /// Row of a pseudo-range rate with unit line of sight `los_ecef`.
    pub fn pseudorange_rate_row(&self, los_ecef: &Vector3<f64>) -> Row {
        let u_n = self.c_en * los_ecef;
        let mut row = Row::zeros();
        row.fixed_view_mut::<1, 3>(0, DV)
            .copy_from(&(-u_n.transpose()));
        let d_dphi = -(u_n.transpose() * self.lever_velocity_n.cross_matrix());
        row.fixed_view_mut::<1, 3>(0, PHI).copy_from(&d_dphi);
        row[CLOCK_DRIFT] = 1.0;
        row
    }

    /// Rows of an antenna position measured in ENU (loosely coupled): E, N, U.
    pub fn position_rows(&self) -> [Row; 3] {
        let mut rows = [Row::zeros(); 3];
        let lever_skew = self.lever_n.cross_matrix();
        for (i, row) in rows.iter_mut().enumerate() {
            // (C l) × φ = [(C l)×] φ.
            row.fixed_view_mut::<1, 3>(0, DP)
                .copy_from(&self.d_enu_d_llh.row(i));
            row.fixed_view_mut::<1, 3>(0, PHI)
                .copy_from(&lever_skew.row(i));
        }
        rows
    }

    /// Rows of an antenna velocity measured in ENU (loosely coupled): E, N, U.
    pub fn velocity_rows(&self) -> [Row; 3] {
        let mut rows = [Row::zeros(); 3];
        let lever_skew = self.lever_velocity_n.cross_matrix();
        for (i, row) in rows.iter_mut().enumerate() {
            row[DV + i] = 1.0;
            row.fixed_view_mut::<1, 3>(0, PHI)
                .copy_from(&lever_skew.row(i));
        }
        rows
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ins::error_state::StateVector;
    use nalgebra::UnitQuaternion;

    fn nav() -> NavState {
        NavState {
            t_s: 0.0,
            p: Llh::from_degrees(40.0, -105.0, 1600.0),
            v_n: Vector3::new(3.0, 4.0, 0.1),
            q_nb: UnitQuaternion::from_euler_angles(0.1, -0.05, 0.7),
        }
    }

    /// The "true" state for which `nominal` has the error δx (what feedback would remove).
    fn true_state(nominal: &NavState, dx: &StateVector) -> NavState {
        let phi = Vector3::new(dx[PHI], dx[PHI + 1], dx[PHI + 2]);
        NavState {
            t_s: nominal.t_s,
            p: Llh::new(
                nominal.p.lat_rad - dx[DP],
                nominal.p.lon_rad - dx[DP + 1],
                nominal.p.height_m - dx[DP + 2],
            ),
            v_n: nominal.v_n - Vector3::new(dx[DV], dx[DV + 1], dx[DV + 2]),
            q_nb: UnitQuaternion::from_scaled_axis(phi) * nominal.q_nb,
        }
    }

    /// Perturbations of millimetres to centimetres (or milliradians) per column.
    fn fd_steps() -> [(usize, f64); 9] {
        [
            (PHI, 1e-3),
            (PHI + 1, 1e-3),
            (PHI + 2, 1e-3),
            (DV, 1e-2),
            (DV + 1, 1e-2),
            (DV + 2, 1e-2),
            (DP, 1e-7),
            (DP + 1, 1e-7),
            (DP + 2, 1e-2),
        ]
    }

    /// Central difference of `g` (predicted at the nominal minus measured at the truth)
    /// along error-state column `i`.
    fn central_difference<F: Fn(&NavState) -> f64>(g: F, i: usize, step: f64) -> f64 {
        let nominal = nav();
        let mut dx = StateVector::zeros();
        dx[i] = step;
        let plus = true_state(&nominal, &dx);
        let minus = true_state(&nominal, &(-dx));
        (g(&minus) - g(&plus)) / (2.0 * step)
    }

    /// Truncation (relative 1e-5) plus ECEF rounding (about 1e-8 m over two evaluations).
    fn fd_tolerance(step: f64, h: f64) -> f64 {
        1e-5 * h.abs().max(1.0) + 1e-8 / step
    }

    /// The rows neglect the rotation of the local ENU frame with position (it turns the
    /// lever arm and the velocity in ECEF, and the line of sight): below 1e-6 m (or m/s)
    /// per metre of position error for a lever arm under a metre, checked here.
    fn neglected_frame_rotation_tolerance(i: usize, step: f64, h: f64) -> f64 {
        if i == DP || i == DP + 1 {
            fd_tolerance(step, h) + 1e-6 * earth::SEMI_MAJOR_AXIS_M
        } else {
            fd_tolerance(step, h)
        }
    }

    #[test]
    fn tight_rows_match_finite_differences() {
        let nominal = nav();
        let lever = Vector3::new(0.3, -0.2, 0.8);
        let w = Vector3::new(0.1, -0.2, 0.5);
        let sat = Vector3::new(15_000e3, -10_000e3, 20_000e3);
        let sat_v = Vector3::new(1000.0, 2000.0, -500.0);
        let geo = AntennaGeometry::new(&nominal, &lever, &w);
        let los = (sat - geo.antenna_ecef_m(&nominal.p)).normalize();
        let range = |s: &NavState| {
            let g = AntennaGeometry::new(s, &lever, &w);
            (sat - g.antenna_ecef_m(&s.p)).norm()
        };
        let rate = |s: &NavState| {
            let g = AntennaGeometry::new(s, &lever, &w);
            los.dot(&(sat_v - g.antenna_velocity_ecef_mps(&s.v_n)))
        };
        let h_rho = geo.pseudorange_row(&los);
        let h_rate = geo.pseudorange_rate_row(&los);
        for (i, step) in fd_steps() {
            let fd = central_difference(range, i, step);
            assert!(
                (fd - h_rho[i]).abs() < fd_tolerance(step, h_rho[i]),
                "ρ col {i}: fd {fd} H {}",
                h_rho[i]
            );
            let fd = central_difference(rate, i, step);
            assert!(
                (fd - h_rate[i]).abs() < neglected_frame_rotation_tolerance(i, step, h_rate[i]),
                "ρ̇ col {i}: fd {fd} H {}",
                h_rate[i]
            );
        }
    }

    #[test]
    fn loose_rows_match_finite_differences() {
        let nominal = nav();
        let lever = Vector3::new(0.3, -0.2, 0.8);
        let w = Vector3::new(0.1, -0.2, 0.5);
        let geo = AntennaGeometry::new(&nominal, &lever, &w);
        let pos_rows = geo.position_rows();
        let vel_rows = geo.velocity_rows();
        for k in 0..3 {
            // Position in the ENU frame of the nominal point (the filter's linearization).
            let c_en = earth::rot_ecef_to_enu(&nominal.p);
            let enu = |s: &NavState| {
                let g = AntennaGeometry::new(s, &lever, &w);
                (c_en * g.antenna_ecef_m(&s.p))[k]
            };
            let vel = |s: &NavState| {
                let g = AntennaGeometry::new(s, &lever, &w);
                (c_en * g.antenna_velocity_ecef_mps(&s.v_n))[k]
            };
            for (i, step) in fd_steps() {
                let fd = central_difference(enu, i, step);
                let h = pos_rows[k][i];
                assert!(
                    (fd - h).abs() < neglected_frame_rotation_tolerance(i, step, h),
                    "pos row {k} col {i}: fd {fd} H {h}"
                );
                let fd = central_difference(vel, i, step);
                let h = vel_rows[k][i];
                assert!(
                    (fd - h).abs() < neglected_frame_rotation_tolerance(i, step, h),
                    "vel row {k} col {i}: fd {fd} H {h}"
                );
            }
        }
    }
}
