//! Continuous-time error-state dynamics of the ERMAKF paper, eqs. (1)–(6), in the ENU frame,
//! and their discretization over one IMU interval.
//!
//! Math note (conventions, see [`crate::ins::error_state`]): δx = computed − true for
//! velocity, position, biases and clock; φ is defined by C(computed) = (I − φ×) C(true).
//! With these, eq. (1) reads φ̇ = −ω_in × φ + δω_in − C_b^n (ε_b + ε_r) and eq. (2)
//! δV̇ = f^n × φ − (2ω_ie + ω_en) × δV + V × (2δω_ie + δω_en) + δg + C_b^n ∇ (the printed
//! "−f^n × f^n" of eq. (2) is a typesetting slip for f^n × φ).

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::earth::{self, Llh};
use crate::ins::error_state::{
    StateMatrix, ACC_BIAS, CLOCK_BIAS, CLOCK_DRIFT, DP, DV, GYRO_BIAS, GYRO_GM, N, PHI,
};
use crate::ins::NavState;

/// Spectral densities and correlation times of the process noise, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessNoise {
    /// Gyro angle random walk (rad/√s).
    pub gyro_arw_rad_per_sqrt_s: f64,
    /// Steady-state 1σ of the gyro Gauss-Markov drift ε_r (rad/s).
    pub gyro_markov_sigma_rad_s: f64,
    /// Correlation time T_g of ε_r (s).
    pub gyro_markov_time_s: f64,
    /// Accelerometer velocity random walk (m/s/√s).
    pub accel_vrw_m_s_per_sqrt_s: f64,
    /// Steady-state 1σ of the accelerometer Gauss-Markov bias ∇ (m/s²).
    pub accel_bias_sigma_m_s2: f64,
    /// Correlation time T_a of ∇ (s).
    pub accel_markov_time_s: f64,
    /// White noise driving the clock offset c·δt_u (m/√s).
    pub clock_bias_noise_m_per_sqrt_s: f64,
    /// White noise driving the clock drift c·δt_ru (m/s/√s).
    pub clock_drift_noise_m_s_per_sqrt_s: f64,
    /// Correlation time T_ru of the clock drift (s).
    pub clock_drift_time_s: f64,
}

/// The inputs the linearization needs: the nominal state and the bias-compensated
/// specific force in the body frame over the interval.
#[derive(Debug, Clone, Copy)]
pub struct LinearizationPoint {
    pub nav: NavState,
    /// Bias-compensated specific force f_ib^b (m/s²).
    pub f_ib_b_m_s2: Vector3<f64>,
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    v.cross_matrix()
}

/// The continuous system matrix F of δẋ = F δx + G w.
pub fn system_matrix(lin: &LinearizationPoint, noise: &ProcessNoise) -> StateMatrix {
    let p: &Llh = &lin.nav.p;
    let v = lin.nav.v_n;
    let (sl, cl) = p.lat_rad.sin_cos();
    let tl = sl / cl;
    let rm_h = earth::meridian_radius_m(p.lat_rad) + p.height_m;
    let rn_h = earth::transverse_radius_m(p.lat_rad) + p.height_m;
    let w = earth::EARTH_RATE_RAD_S;
    let w_ie = earth::earth_rate_enu_rad_s(p.lat_rad);
    let w_en = earth::transport_rate_enu_rad_s(p, &v);
    let w_in = w_ie + w_en;
    let c_bn = lin.nav.q_nb.to_rotation_matrix().into_inner();
    let f_n = c_bn * lin.f_ib_b_m_s2;
    let (ve, vn) = (v[0], v[1]);

    // ∂ω_ie^n/∂(δL, δλ, δh)
    let d_wie_dp = Matrix3::new(0.0, 0.0, 0.0, -w * sl, 0.0, 0.0, w * cl, 0.0, 0.0);
    // ∂ω_en^n/∂δV and ∂ω_en^n/∂(δL, δλ, δh) (radii treated as constant in L: their
    // variation is O(e²) of an already small term).
    let d_wen_dv = Matrix3::new(
        0.0,
        -1.0 / rm_h,
        0.0,
        1.0 / rn_h,
        0.0,
        0.0,
        tl / rn_h,
        0.0,
        0.0,
    );
    let d_wen_dp = Matrix3::new(
        0.0,
        0.0,
        vn / (rm_h * rm_h),
        0.0,
        0.0,
        -ve / (rn_h * rn_h),
        ve / (cl * cl * rn_h),
        0.0,
        -ve * tl / (rn_h * rn_h),
    );
    // ∂g^n/∂(δL, δh): normal gravity derivatives by central differences of the same model
    // the mechanization uses, so the linearization matches the nominal dynamics.
    let dlat = 1e-6;
    let dh = 1.0;
    let dg_dlat = -(earth::normal_gravity_m_s2(p.lat_rad + dlat, p.height_m)
        - earth::normal_gravity_m_s2(p.lat_rad - dlat, p.height_m))
        / (2.0 * dlat);
    let dg_dh = -(earth::normal_gravity_m_s2(p.lat_rad, p.height_m + dh)
        - earth::normal_gravity_m_s2(p.lat_rad, p.height_m - dh))
        / (2.0 * dh);

    let mut f = StateMatrix::zeros();
    let mut set = |r: usize, c: usize, m: &Matrix3<f64>| {
        f.fixed_view_mut::<3, 3>(r, c).copy_from(m);
    };
    // Eq. (1): attitude.
    set(PHI, PHI, &(-skew(&w_in)));
    set(PHI, DV, &d_wen_dv);
    set(PHI, DP, &(d_wie_dp + d_wen_dp));
    set(PHI, GYRO_BIAS, &(-c_bn));
    set(PHI, GYRO_GM, &(-c_bn));
    // Eq. (2): velocity.
    let mut d_g_dp = Matrix3::zeros();
    d_g_dp[(2, 0)] = dg_dlat;
    d_g_dp[(2, 2)] = dg_dh;
    set(DV, PHI, &skew(&f_n));
    set(DV, DV, &(skew(&v) * d_wen_dv - skew(&(2.0 * w_ie + w_en))));
    set(DV, DP, &(skew(&v) * (2.0 * d_wie_dp + d_wen_dp) + d_g_dp));
    set(DV, ACC_BIAS, &c_bn);
    // Eq. (3): position (δL, δλ, δh).
    set(
        DP,
        DV,
        &Matrix3::new(
            0.0,
            1.0 / rm_h,
            0.0,
            1.0 / (rn_h * cl),
            0.0,
            0.0,
            0.0,
            0.0,
            1.0,
        ),
    );
    set(
        DP,
        DP,
        &Matrix3::new(
            0.0,
            0.0,
            -vn / (rm_h * rm_h),
            ve * tl / (rn_h * cl),
            0.0,
            -ve / (rn_h * rn_h * cl),
            0.0,
            0.0,
            0.0,
        ),
    );
    // Eqs. (4)–(5): Gauss-Markov sensor errors; ε_b is a random constant.
    set(
        GYRO_GM,
        GYRO_GM,
        &(-Matrix3::identity() / noise.gyro_markov_time_s),
    );
    set(
        ACC_BIAS,
        ACC_BIAS,
        &(-Matrix3::identity() / noise.accel_markov_time_s),
    );
    // Eq. (6): receiver clock.
    f[(CLOCK_BIAS, CLOCK_DRIFT)] = 1.0;
    f[(CLOCK_DRIFT, CLOCK_DRIFT)] = -1.0 / noise.clock_drift_time_s;
    f
}

/// The continuous noise covariance G Q_c Gᵀ (a spectral density matrix).
///
/// Math note: the white sensor noises enter as −C_b^n w_g and C_b^n w_a; their spectral
/// densities are isotropic, so C (q I) Cᵀ = q I and G Q_c Gᵀ is diagonal. A first-order
/// Gauss-Markov process of steady-state variance σ² and time T is driven by white noise of
/// density 2σ²/T.
pub fn noise_density(noise: &ProcessNoise) -> SMatrix<f64, N, N> {
    let mut q = StateMatrix::zeros();
    let mut diag3 = |start: usize, value: f64| {
        for i in start..start + 3 {
            q[(i, i)] = value;
        }
    };
    diag3(PHI, noise.gyro_arw_rad_per_sqrt_s.powi(2));
    diag3(DV, noise.accel_vrw_m_s_per_sqrt_s.powi(2));
    diag3(
        GYRO_GM,
        2.0 * noise.gyro_markov_sigma_rad_s.powi(2) / noise.gyro_markov_time_s,
    );
    diag3(
        ACC_BIAS,
        2.0 * noise.accel_bias_sigma_m_s2.powi(2) / noise.accel_markov_time_s,
    );
    q[(CLOCK_BIAS, CLOCK_BIAS)] = noise.clock_bias_noise_m_per_sqrt_s.powi(2);
    q[(CLOCK_DRIFT, CLOCK_DRIFT)] = noise.clock_drift_noise_m_s_per_sqrt_s.powi(2);
    q
}

/// Transition matrix Φ and discrete process noise Q_d over `dt_s`.
///
/// Math note: Van Loan's method gives Φ = e^{F dt} and Q_d = ∫₀^dt e^{Fs} Q_c e^{Fᵀs} ds.
/// Over one IMU interval ‖F dt‖ is of order 0.1 or less, so both are evaluated by their
/// Taylor series to third order in dt (Φ to (F dt)³/6; Q_d = Q dt + (FQ + QFᵀ) dt²/2 +
/// (F(FQ + QFᵀ) + (FQ + QFᵀ)Fᵀ) dt³/6). The first neglected term of an entry is of
/// relative size dt² times ratios of the noise densities that feed it indirectly (the
/// accelerometer Gauss-Markov noise reaching δV–δλ is the largest here): about 2e-6 at
/// dt = 0.01 s, far below the uncertainty of any noise density. The unit test checks the
/// series against the matrix exponential of Van Loan's block matrix.
pub fn discretize(f: &StateMatrix, q_c: &StateMatrix, dt_s: f64) -> (StateMatrix, StateMatrix) {
    let f_dt = f * dt_s;
    let f_dt2 = f_dt * f_dt;
    let phi = StateMatrix::identity() + f_dt + f_dt2 * 0.5 + f_dt2 * f_dt * (1.0 / 6.0);
    let fq = f * q_c;
    let m1 = fq + fq.transpose();
    let fm1 = f * m1;
    let m2 = fm1 + fm1.transpose();
    let mut q_d = q_c * dt_s + m1 * (dt_s * dt_s * 0.5) + m2 * (dt_s.powi(3) / 6.0);
    q_d = (q_d + q_d.transpose()) * 0.5;
    (phi, q_d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, UnitQuaternion};

    fn noise() -> ProcessNoise {
        ProcessNoise {
            gyro_arw_rad_per_sqrt_s: 0.012f64.to_radians() / 60.0,
            gyro_markov_sigma_rad_s: 0.5f64.to_radians() / 3600.0,
            gyro_markov_time_s: 3600.0,
            accel_vrw_m_s_per_sqrt_s: 100e-6 * 9.80665,
            accel_bias_sigma_m_s2: 1250e-6 * 9.80665,
            accel_markov_time_s: 3600.0,
            clock_bias_noise_m_per_sqrt_s: 0.5,
            clock_drift_noise_m_s_per_sqrt_s: 0.1,
            clock_drift_time_s: 1800.0,
        }
    }

    fn moving_point() -> LinearizationPoint {
        LinearizationPoint {
            nav: NavState {
                t_s: 0.0,
                p: Llh::from_degrees(39.1, 117.2, 30.0),
                v_n: Vector3::new(12.0, -7.0, 0.3),
                q_nb: UnitQuaternion::from_euler_angles(0.02, -0.03, 1.1),
            },
            f_ib_b_m_s2: Vector3::new(0.8, -0.4, 9.81),
        }
    }

    #[test]
    fn series_discretization_matches_van_loan_exponential() {
        let n = noise();
        let f = system_matrix(&moving_point(), &n);
        let q = noise_density(&n);
        // IMU intervals of 100 Hz and 50 Hz. The bound 1e-5 (relative to the standard
        // deviations involved) is the truncation estimate of the doc comment with margin.
        for dt in [0.01, 0.02] {
            let (phi, q_d) = discretize(&f, &q, dt);
            // Van Loan: exp([[-F, Q], [0, Fᵀ]] dt) = [[., Φ⁻¹ Q_d], [0, Φᵀ]], evaluated on
            // a rescaled state whose discrete noise variances are all about one, so that the
            // exponential's absolute accuracy is uniform over the entries; scaled back after.
            let mut t = StateMatrix::identity();
            for i in 0..N {
                if q_d[(i, i)] > 0.0 {
                    t[(i, i)] = 1.0 / q_d[(i, i)].sqrt();
                }
            }
            let t_inv = t.try_inverse().unwrap();
            let f_s = t * f * t_inv;
            let q_s = t * q * t;
            let mut a = DMatrix::<f64>::zeros(2 * N, 2 * N);
            a.view_mut((0, 0), (N, N)).copy_from(&(-f_s * dt));
            a.view_mut((0, N), (N, N)).copy_from(&(q_s * dt));
            a.view_mut((N, N), (N, N))
                .copy_from(&(f_s.transpose() * dt));
            let e = a.exp();
            let phi_s = e.view((N, N), (N, N)).transpose();
            let q_d_s = &phi_s * e.view((0, N), (N, N));
            // Φ: the Taylor remainder after (F dt)³/6 is bounded by ‖F dt‖⁴/24 · e^‖F dt‖.
            let phi_ref = t_inv * StateMatrix::from_column_slice(phi_s.as_slice()) * t;
            let a_norm = (f * dt).norm();
            let bound = a_norm.powi(4) / 24.0 * a_norm.exp() + 1e-14;
            let phi_err = (phi - phi_ref).norm();
            assert!(phi_err < bound, "dt {dt}: ‖ΔΦ‖ {phi_err} > {bound}");
            // Q_d: compare in the scaled coordinates, where an absolute error is an error
            // relative to the standard deviations of the two states involved.
            let q_ours = t * q_d * t;
            for i in 0..N {
                for j in 0..N {
                    let q_err = (q_ours[(i, j)] - q_d_s[(i, j)]).abs();
                    assert!(q_err < 1e-5, "dt {dt}: Q_d[{i},{j}] relative error {q_err}");
                }
            }
        }
    }

    #[test]
    fn system_matrix_matches_finite_difference_of_position_kinematics() {
        // δL̇ = δV_N/(R_M+h) − V_N δh/(R_M+h)²: perturb the nominal and compare.
        let lin = moving_point();
        let f = system_matrix(&lin, &noise());
        let rate = |vn: f64, h: f64| vn / (earth::meridian_radius_m(lin.nav.p.lat_rad) + h);
        let (vn, h) = (lin.nav.v_n[1], lin.nav.p.height_m);
        let d = 1e-3;
        let d_dv = (rate(vn + d, h) - rate(vn - d, h)) / (2.0 * d);
        let d_dh = (rate(vn, h + d) - rate(vn, h - d)) / (2.0 * d);
        assert!((f[(DP, DV + 1)] - d_dv).abs() < 1e-15);
        assert!((f[(DP, DP + 2)] - d_dh).abs() < 1e-18);
    }
}
