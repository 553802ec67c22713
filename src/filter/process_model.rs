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
    StateMatrix, StateVector, ACC_BIAS, ACC_SCALE, CLOCK_BIAS, CLOCK_DRIFT, DP, DV, GYRO_BIAS,
    GYRO_GM, GYRO_SCALE, N, N_INS, PHI, WHEEL_SCALE,
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
    /// The receiver clock states, eq. (6); None: inert (loosely coupled, where nothing
    /// measures the clock).
    pub clock: Option<ClockNoise>,
    /// White noise driving the wheel odometry scale factor (a random walk, 1/√s); zero
    /// when the state is off.
    pub wheel_scale_noise_per_sqrt_s: f64,
    /// The IMU scale-factor states (`imu.scale_factor_states`); None: inert.
    pub imu_scale: Option<ImuScaleNoise>,
}

/// The receiver clock model of eq. (6): a random-walk offset driven by a first-order
/// Gauss-Markov drift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockNoise {
    /// White noise driving the clock offset c·δt_u (m/√s).
    pub bias_noise_m_per_sqrt_s: f64,
    /// White noise driving the clock drift c·δt_ru (m/s/√s).
    pub drift_noise_m_s_per_sqrt_s: f64,
    /// Correlation time T_ru of the clock drift (s).
    pub drift_time_s: f64,
}

/// First-order Gauss-Markov models of the IMU scale-factor errors (as KF-GINS carries them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuScaleNoise {
    /// Steady-state 1σ of the gyro scale-factor error (dimensionless).
    pub gyro_sigma: f64,
    /// Steady-state 1σ of the accelerometer scale-factor error (dimensionless).
    pub accel_sigma: f64,
    /// Correlation time of both (s).
    pub time_s: f64,
}

impl ProcessNoise {
    /// The process noise with every spectral density multiplied by `factor` (> 0): the
    /// white-noise amplitudes and the Gauss-Markov σ scale by √factor, the correlation times
    /// stay. Math note: the continuous Q of [`noise_density`] is then `factor` times the
    /// original (q = σ_w² for white noise, 2σ²/T for a Gauss-Markov process), and the system
    /// matrix, which holds only the correlation times, is unchanged.
    pub fn scaled(&self, factor: f64) -> Self {
        let k = factor.sqrt();
        Self {
            gyro_arw_rad_per_sqrt_s: self.gyro_arw_rad_per_sqrt_s * k,
            gyro_markov_sigma_rad_s: self.gyro_markov_sigma_rad_s * k,
            accel_vrw_m_s_per_sqrt_s: self.accel_vrw_m_s_per_sqrt_s * k,
            accel_bias_sigma_m_s2: self.accel_bias_sigma_m_s2 * k,
            clock: self.clock.map(|c| ClockNoise {
                bias_noise_m_per_sqrt_s: c.bias_noise_m_per_sqrt_s * k,
                drift_noise_m_s_per_sqrt_s: c.drift_noise_m_s_per_sqrt_s * k,
                ..c
            }),
            wheel_scale_noise_per_sqrt_s: self.wheel_scale_noise_per_sqrt_s * k,
            imu_scale: self.imu_scale.map(|s| ImuScaleNoise {
                gyro_sigma: s.gyro_sigma * k,
                accel_sigma: s.accel_sigma * k,
                ..s
            }),
            ..*self
        }
    }
}

/// The inputs the linearization needs: the nominal state and the compensated specific
/// force and angular rate in the body frame over the interval.
#[derive(Debug, Clone, Copy)]
pub struct LinearizationPoint {
    pub nav: NavState,
    /// Compensated specific force f_ib^b (m/s²).
    pub f_ib_b_m_s2: Vector3<f64>,
    /// Compensated angular rate ω_ib^b (rad/s); used by the gyro scale-factor states only.
    pub w_ib_b_rad_s: Vector3<f64>,
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
    // The scale factors: ω̂ − ω ≈ diag(ω̂) δs_g and f̂ − f ≈ diag(f̂) δs_a enter as the
    // biases do; the wheel's factor is a random walk (no dynamics). Inert when off.
    if let Some(scale) = noise.imu_scale {
        let decay = -Matrix3::identity() / scale.time_s;
        set(
            PHI,
            GYRO_SCALE,
            &(-c_bn * Matrix3::from_diagonal(&lin.w_ib_b_rad_s)),
        );
        set(
            DV,
            ACC_SCALE,
            &(c_bn * Matrix3::from_diagonal(&lin.f_ib_b_m_s2)),
        );
        set(GYRO_SCALE, GYRO_SCALE, &decay);
        set(ACC_SCALE, ACC_SCALE, &decay);
    }
    // Eq. (6): receiver clock.
    if let Some(clock) = noise.clock {
        f[(CLOCK_BIAS, CLOCK_DRIFT)] = 1.0;
        f[(CLOCK_DRIFT, CLOCK_DRIFT)] = -1.0 / clock.drift_time_s;
    }
    f
}

/// The continuous noise covariance G Q_c Gᵀ (a spectral density matrix), as its diagonal.
///
/// Math note: the white sensor noises enter as −C_b^n w_g and C_b^n w_a; their spectral
/// densities are isotropic, so C (q I) Cᵀ = q I and G Q_c Gᵀ is diagonal. A first-order
/// Gauss-Markov process of steady-state variance σ² and time T is driven by white noise of
/// density 2σ²/T.
pub fn noise_density(noise: &ProcessNoise) -> StateVector {
    let mut q = StateVector::zeros();
    let mut diag3 = |start: usize, value: f64| {
        for i in start..start + 3 {
            q[i] = value;
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
    if let Some(scale) = noise.imu_scale {
        diag3(GYRO_SCALE, 2.0 * scale.gyro_sigma.powi(2) / scale.time_s);
        diag3(ACC_SCALE, 2.0 * scale.accel_sigma.powi(2) / scale.time_s);
    }
    if let Some(clock) = noise.clock {
        q[CLOCK_BIAS] = clock.bias_noise_m_per_sqrt_s.powi(2);
        q[CLOCK_DRIFT] = clock.drift_noise_m_s_per_sqrt_s.powi(2);
    }
    q[WHEEL_SCALE] = noise.wheel_scale_noise_per_sqrt_s.powi(2);
    q
}

/// A square matrix of the leading `M` states.
type Square<const M: usize> = SMatrix<f64, M, M>;

/// The non-zero pattern of the leading M × M block of F (about 85 of 400 entries of the
/// paper's 20 states), row by row, for cheap products with dense matrices; nothing is
/// copied or allocated per IMU sample.
struct SparseF<'a, const M: usize> {
    f: &'a StateMatrix,
    /// Bit k of `rows[r]` is set when F[r, k] is not zero (M ≤ N = 27 bits fit a u32).
    rows: [u32; M],
}

/// Rows of an M × M matrix, row r at index r.
type Rows<const M: usize> = [[f64; M]; M];

impl<'a, const M: usize> SparseF<'a, M> {
    fn new(f: &'a StateMatrix) -> Self {
        let rows = std::array::from_fn(|r| {
            (0..M).fold(0u32, |mask, k| mask | (u32::from(f[(r, k)] != 0.0) << k))
        });
        Self { f, rows }
    }

    /// Writes the rows of F X into `fx`, given `x_rows`, the matrix whose column k is row k
    /// of X (Xᵀ; X itself when X is exactly symmetric).
    ///
    /// Math note (rounding): (F X)[r, c] is the sum of F[r, k] X[k, c] over the non-zero
    /// F[r, k] in increasing k, starting from zero, as a plain row-times-column product
    /// that skips F's zeros would add them; a row's M sums run side by side.
    fn times(&self, x_rows: &Square<M>, fx: &mut Rows<M>) {
        let f = self.f.as_slice();
        let x = x_rows.as_slice();
        for (r, (row, &pattern)) in fx.iter_mut().zip(&self.rows).enumerate() {
            let mut acc = [0.0; M];
            // The set bits from the lowest: k in increasing order.
            let mut mask = pattern;
            while mask != 0 {
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let v = f[r + N * k];
                for (a, xc) in acc.iter_mut().zip(&x[k * M..(k + 1) * M]) {
                    *a += v * xc;
                }
            }
            *row = acc;
        }
    }
}

/// The Lyapunov operator L(X) = F X + X Fᵀ = F X + (F X)ᵀ of a symmetric X, from the rows
/// `fx` of F X. The result is exactly symmetric: L[i, j] and L[j, i] add the same two
/// numbers, and floating-point addition is commutative.
fn lyapunov<const M: usize>(fx: &Rows<M>, i: usize, j: usize) -> f64 {
    fx[i][j] + fx[j][i]
}

/// Time update of the covariance over `dt_s`, eq. (10): P⁻ = Φ P Φᵀ + Q_d with Van Loan's
/// Φ = e^{F dt} and Q_d = ∫₀^dt e^{Fs} Q_c e^{Fᵀs} ds, for the diagonal density `q_c`.
///
/// Math note: X(t) = e^{Ft} P e^{Fᵀt} + ∫₀^t e^{Fs} Q_c e^{Fᵀs} ds solves Ẋ = L(X) + Q_c
/// with the Lyapunov operator L(X) = F X + X Fᵀ, so its Taylor series is
/// X(dt) = P + T₁ dt + T₂ dt²/2 + T₃ dt³/6 with T₁ = L(P) + Q_c, T_{k+1} = L(T_k). Each L
/// costs one product of the sparse F with a dense matrix, a tenth of a dense product.
/// Over one IMU interval ‖F dt‖ is 0.1 or less; the first neglected term of an entry is of
/// relative size dt² times ratios of the noise densities that feed it indirectly (about
/// 2e-6 at dt = 0.01 s), far below the uncertainty of any noise density. The series is
/// covariant under a diagonal rescaling of the state, so states of very different units
/// (radians of latitude, metres of clock) lose nothing to each other. The unit test
/// checks it against the matrix exponential of Van Loan's block matrix.
///
/// Choice (inert states): when the trailing states are inert (zero variance, rows of F and
/// density: [`crate::ins::error_state`]'s Choice), the series runs on the leading 18 (the
/// clock inert too, loosely coupled), 20 or 21 (the wheel's factor on) states only and the
/// rest stays zero: the same numbers to the bit as the series on all N (a unit test
/// compares them), at the cost of 18 or 20 states instead of 27 (docs/benchmarks.md).
pub fn propagate_covariance(
    f: &StateMatrix,
    q_c: &StateVector,
    p: &StateMatrix,
    dt_s: f64,
) -> StateMatrix {
    const PAPER: usize = CLOCK_DRIFT + 1;
    const WITH_WHEEL: usize = WHEEL_SCALE + 1;
    if inert_from(N_INS, f, q_c, p) {
        series::<N_INS>(f, q_c, p, dt_s)
    } else if inert_from(PAPER, f, q_c, p) {
        series::<PAPER>(f, q_c, p, dt_s)
    } else if inert_from(WITH_WHEEL, f, q_c, p) {
        series::<WITH_WHEEL>(f, q_c, p, dt_s)
    } else {
        series::<N>(f, q_c, p, dt_s)
    }
}

/// Whether every state from `first` on is inert: zero variance, density and row of F.
///
/// Math note: a zero variance of the positive semi-definite P makes its row and column
/// zero, so F's columns of those states add exact zeros to F P and may be left out; a
/// zero row of F and density keep them zero.
fn inert_from(first: usize, f: &StateMatrix, q_c: &StateVector, p: &StateMatrix) -> bool {
    (first..N).all(|i| q_c[i] == 0.0 && p[(i, i)] == 0.0 && (0..N).all(|j| f[(i, j)] == 0.0))
}

/// The series of [`propagate_covariance`] on the leading `M` states; the others are zero.
fn series<const M: usize>(
    f: &StateMatrix,
    q_c: &StateVector,
    p: &StateMatrix,
    dt_s: f64,
) -> StateMatrix {
    let f_sparse = SparseF::<M>::new(f);
    // P is symmetric only up to rounding when it comes from outside: its rows are the
    // columns of Pᵀ. T₁ and T₂ are exactly symmetric, so they are their own row matrices.
    let mut fx: Rows<M> = [[0.0; M]; M];
    f_sparse.times(&Square::<M>::from_fn(|i, j| p[(j, i)]), &mut fx);
    let t1 = Square::<M>::from_fn(|i, j| {
        let l = lyapunov(&fx, i, j);
        if i == j {
            l + q_c[i]
        } else {
            l
        }
    });
    f_sparse.times(&t1, &mut fx);
    let t2 = Square::<M>::from_fn(|i, j| lyapunov(&fx, i, j));
    f_sparse.times(&t2, &mut fx);
    let (c1, c2, c3) = (dt_s, dt_s * dt_s * 0.5, dt_s.powi(3) / 6.0);
    let p_new = |i, j| p[(i, j)] + t1[(i, j)] * c1 + t2[(i, j)] * c2 + lyapunov(&fx, i, j) * c3;
    // Symmetric: each pair of entries once, from the mean of both triangles.
    let mut out = StateMatrix::zeros();
    for j in 0..M {
        for i in 0..=j {
            let v = (p_new(i, j) + p_new(j, i)) * 0.5;
            out[(i, j)] = v;
            out[(j, i)] = v;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, UnitQuaternion};

    #[test]
    fn scaled_noise_scales_the_density_and_keeps_the_dynamics() {
        let n = noise();
        let s = n.scaled(7.5);
        let (q0, q1) = (noise_density(&n), noise_density(&s));
        for i in 0..q0.len() {
            assert!(
                (q1[i] - 7.5 * q0[i]).abs() <= 1e-12 * q0[i].abs(),
                "state {i}"
            );
        }
        let lin = LinearizationPoint {
            nav: crate::ins::NavState {
                t_s: 0.0,
                p: crate::earth::Llh::from_degrees(40.0, 116.0, 50.0),
                v_n: nalgebra::Vector3::new(3.0, 4.0, 0.1),
                q_nb: UnitQuaternion::identity(),
            },
            f_ib_b_m_s2: nalgebra::Vector3::new(0.1, 0.2, 9.8),
            w_ib_b_rad_s: nalgebra::Vector3::new(0.01, -0.02, 0.3),
        };
        assert_eq!(system_matrix(&lin, &n), system_matrix(&lin, &s));
    }

    fn noise() -> ProcessNoise {
        ProcessNoise {
            gyro_arw_rad_per_sqrt_s: 0.012f64.to_radians() / 60.0,
            gyro_markov_sigma_rad_s: 0.5f64.to_radians() / 3600.0,
            gyro_markov_time_s: 3600.0,
            accel_vrw_m_s_per_sqrt_s: 100e-6 * 9.80665,
            accel_bias_sigma_m_s2: 1250e-6 * 9.80665,
            accel_markov_time_s: 3600.0,
            clock: Some(ClockNoise {
                bias_noise_m_per_sqrt_s: 0.5,
                drift_noise_m_s_per_sqrt_s: 0.1,
                drift_time_s: 1800.0,
            }),
            wheel_scale_noise_per_sqrt_s: 1e-5,
            imu_scale: Some(ImuScaleNoise {
                gyro_sigma: 300e-6,
                accel_sigma: 1000e-6,
                time_s: 3600.0,
            }),
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
            w_ib_b_rad_s: Vector3::new(0.01, -0.02, 0.3),
        }
    }

    /// A prior covariance of the size the filter starts with.
    fn prior() -> StateMatrix {
        let mut sigmas = StateVector::zeros();
        let values = [
            (PHI, 0.02),
            (DV, 0.5),
            (DP, 5.0 / 6.4e6),
            (GYRO_BIAS, 2.4e-6),
            (GYRO_GM, 2.4e-6),
            (ACC_BIAS, 0.012),
            (GYRO_SCALE, 300e-6),
            (ACC_SCALE, 1000e-6),
        ];
        for (start, sigma) in values {
            for i in start..start + 3 {
                sigmas[i] = sigma;
            }
        }
        sigmas[DP + 2] = 5.0;
        sigmas[CLOCK_BIAS] = 30.0;
        sigmas[CLOCK_DRIFT] = 5.0;
        sigmas[WHEEL_SCALE] = 0.05;
        let mut p = StateMatrix::from_diagonal(&sigmas.component_mul(&sigmas));
        // Some correlation, as after updates.
        p[(DV, PHI + 1)] = 0.3 * sigmas[DV] * sigmas[PHI + 1];
        p[(PHI + 1, DV)] = p[(DV, PHI + 1)];
        p[(CLOCK_BIAS, DP + 2)] = 0.5 * sigmas[CLOCK_BIAS] * sigmas[DP + 2];
        p[(DP + 2, CLOCK_BIAS)] = p[(CLOCK_BIAS, DP + 2)];
        p
    }

    /// The series of [`propagate_covariance`] written out plainly: (F X)[r,c] summed over
    /// the non-zero F[r,k] in increasing k, whole-matrix sums and products.
    fn plain_series(f: &StateMatrix, q: &StateVector, p: &StateMatrix, dt: f64) -> StateMatrix {
        let lyapunov = |x: &StateMatrix| {
            let mut fx = StateMatrix::zeros();
            for r in 0..N {
                for c in 0..N {
                    let mut sum = 0.0;
                    for k in (0..N).filter(|&k| f[(r, k)] != 0.0) {
                        sum += f[(r, k)] * x[(k, c)];
                    }
                    fx[(r, c)] = sum;
                }
            }
            fx + fx.transpose()
        };
        let t1 = lyapunov(p) + StateMatrix::from_diagonal(q);
        let t2 = lyapunov(&t1);
        let t3 = lyapunov(&t2);
        let p_new = p + t1 * dt + t2 * (dt * dt * 0.5) + t3 * (dt.powi(3) / 6.0);
        (p_new + p_new.transpose()) * 0.5
    }

    #[test]
    fn propagation_gives_the_plain_series_bit_for_bit() {
        let n = noise();
        let f = system_matrix(&moving_point(), &n);
        let q = noise_density(&n);
        // A symmetric prior and one whose triangles differ in the last bits, as a caller's
        // P may.
        let mut lopsided = prior();
        lopsided[(DV, PHI + 1)] *= 1.0 + 4.0 * f64::EPSILON;
        lopsided[(CLOCK_BIAS, DP + 2)] *= 1.0 - 2.0 * f64::EPSILON;
        assert_ne!(lopsided, lopsided.transpose());
        for p0 in [prior(), lopsided] {
            for dt in [0.005, 0.01, 0.02] {
                let ours = propagate_covariance(&f, &q, &p0, dt);
                let plain = plain_series(&f, &q, &p0, dt);
                for (i, (a, b)) in ours.iter().zip(plain.iter()).enumerate() {
                    assert_eq!(a.to_bits(), b.to_bits(), "dt {dt}: entry {i}: {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn inert_states_leave_the_other_states_as_the_full_series_does() {
        // Scale factors off: the leading-block path gives the full series' numbers to the
        // bit, and the inert rows stay exactly zero; the wheel's factor alone likewise, and
        // the clock off too (loosely coupled).
        let no_clock = ProcessNoise {
            clock: None,
            wheel_scale_noise_per_sqrt_s: 0.0,
            imu_scale: None,
            ..noise()
        };
        let off = ProcessNoise {
            wheel_scale_noise_per_sqrt_s: 0.0,
            imu_scale: None,
            ..noise()
        };
        let wheel_only = ProcessNoise {
            imu_scale: None,
            ..noise()
        };
        for (noise, first_inert) in [
            (no_clock, CLOCK_BIAS),
            (off, WHEEL_SCALE),
            (wheel_only, GYRO_SCALE),
        ] {
            let f = system_matrix(&moving_point(), &noise);
            let q = noise_density(&noise);
            let mut p0 = prior();
            for i in first_inert..N {
                p0.row_mut(i).fill(0.0);
                p0.column_mut(i).fill(0.0);
            }
            let fast = propagate_covariance(&f, &q, &p0, 0.01);
            let full = series::<N>(&f, &q, &p0, 0.01);
            for (a, b) in fast.iter().zip(full.iter()) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
            assert!((first_inert..N).all(|i| fast.row(i).iter().all(|&v| v == 0.0)));
        }
    }

    #[test]
    fn series_propagation_matches_van_loan_exponential() {
        let n = noise();
        let f = system_matrix(&moving_point(), &n);
        let q = noise_density(&n);
        let p = prior();
        // IMU intervals of 100 Hz and 50 Hz, from the filter's start covariance and from
        // a tiny one (where Q_d dominates). The bound 1e-5 (relative to the standard
        // deviations involved) is the truncation estimate of the doc comment with margin.
        for p0 in [p, p * 1e-8] {
            for dt in [0.01, 0.02] {
                let ours = propagate_covariance(&f, &q, &p0, dt);
                // Van Loan: exp([[-F, Q], [0, Fᵀ]] dt) = [[., Φ⁻¹ Q_d], [0, Φᵀ]], evaluated
                // on a state rescaled to unit variances, so that the exponential's absolute
                // accuracy is uniform over the entries.
                let mut t = StateMatrix::identity();
                for i in 0..N {
                    t[(i, i)] = 1.0 / ours[(i, i)].sqrt();
                }
                let t_inv = t.try_inverse().unwrap();
                let f_s = t * f * t_inv;
                let q_s = t * StateMatrix::from_diagonal(&q) * t;
                let mut a = DMatrix::<f64>::zeros(2 * N, 2 * N);
                a.view_mut((0, 0), (N, N)).copy_from(&(-f_s * dt));
                a.view_mut((0, N), (N, N)).copy_from(&(q_s * dt));
                a.view_mut((N, N), (N, N))
                    .copy_from(&(f_s.transpose() * dt));
                let e = a.exp();
                let phi_s =
                    StateMatrix::from_column_slice(e.view((N, N), (N, N)).transpose().as_slice());
                let q_d_s = phi_s
                    * StateMatrix::from_column_slice(
                        e.view((0, N), (N, N)).clone_owned().as_slice(),
                    );
                let reference = phi_s * (t * p0 * t) * phi_s.transpose() + q_d_s;
                let scaled = t * ours * t;
                for i in 0..N {
                    for j in 0..N {
                        let err = (scaled[(i, j)] - reference[(i, j)]).abs();
                        assert!(err < 1e-5, "dt {dt}: P[{i},{j}] relative error {err}");
                    }
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
