//! The 20-state error vector of the ERMAKF paper, eqs. (1)–(6), extended by seven optional
//! scale-factor states (issue 14), with every block's offset named once. Blocks are used by
//! name (`PHI`, `DV`, ...), never by literal offsets.
//!
//! | block | meaning | unit |
//! | --- | --- | --- |
//! | `PHI` | attitude error φ^n (E, N, U): C_b^n(true) = exp(φ×) C_b^n(computed) | rad |
//! | `DV` | velocity error δV^n = V(computed) − V(true), ENU | m/s |
//! | `DP` | position error (δL, δλ, δh) = computed − true | rad, rad, m |
//! | `GYRO_BIAS` | gyro zero-offset bias ε_b (random constant), body FLU | rad/s |
//! | `GYRO_GM` | gyro first-order Gauss-Markov drift ε_r, body FLU | rad/s |
//! | `ACC_BIAS` | accelerometer first-order Gauss-Markov bias ∇_b, body FLU | m/s² |
//! | `CLOCK_BIAS` | receiver clock offset c·δt_u | m |
//! | `CLOCK_DRIFT` | receiver clock drift c·δt_ru | m/s |
//! | `WHEEL_SCALE` | wheel odometry scale factor s_w, true speed = s_w · reported | 1 |
//! | `GYRO_SCALE` | gyro scale-factor error s_g: ω_meas = (1 + s_g) ω + ε, body FLU | 1 |
//! | `ACC_SCALE` | accelerometer scale-factor error s_a: f_meas = (1 + s_a) f + ∇ | 1 |
//!
//! The scale-factor blocks carry the error as the biases do (estimate += δx̂).
//!
//! Choice (optional states): the three scale-factor blocks are always in the vector but
//! inert when switched off (`wheel_odometry.scale_factor_state`, `imu.scale_factor_states`):
//! zero variance, zero rows and columns of F, zero process noise and zero measurement
//! columns. Their rows and columns of P then stay exactly zero, every product adds exact
//! zeros after the 20 states' terms, and the outputs are those of the 20-state filter to
//! the bit (tests/replay_golden.rs); the cubature update, which needs a positive-definite
//! P, runs on the states that are not inert ([`active_states`]). A dimension chosen at
//! build would save the extra columns but split every test and binary in two; the cost
//! of the inert columns is measured in docs/benchmarks.md.
//!
//! Choices where the paper leaves room (numerically motivated):
//! - The clock states are carried in metres and metres per second (c·δt_u, c·δt_ru) rather
//!   than seconds, so their variances are of the same order as the range variances.
//! - Position keeps the paper's (δL, δλ, δh). Floating-point arithmetic is invariant under
//!   a diagonal rescaling of the state (up to rounding), so the radian scale of δL, δλ costs
//!   no precision in the Joseph-form update; outputs convert to metres with
//!   [`crate::earth::metres_per_radian`].

/// Attitude error φ (3).
pub const PHI: usize = 0;
/// Velocity error δV^n (3).
pub const DV: usize = 3;
/// Position error δL, δλ, δh (3).
pub const DP: usize = 6;
/// Gyro constant bias ε_b (3).
pub const GYRO_BIAS: usize = 9;
/// Gyro Gauss-Markov drift ε_r (3).
pub const GYRO_GM: usize = 12;
/// Accelerometer Gauss-Markov bias ∇_b (3).
pub const ACC_BIAS: usize = 15;
/// Receiver clock offset (1), metres.
pub const CLOCK_BIAS: usize = 18;
/// Receiver clock drift (1), metres per second.
pub const CLOCK_DRIFT: usize = 19;
/// Wheel odometry scale factor (1), dimensionless.
pub const WHEEL_SCALE: usize = 20;
/// Gyro scale-factor error (3), dimensionless.
pub const GYRO_SCALE: usize = 21;
/// Accelerometer scale-factor error (3), dimensionless.
pub const ACC_SCALE: usize = 24;
/// Dimension of the error state.
pub const N: usize = 27;

/// Dimension of the inertial part of the paper's state (everything before the clock).
pub const N_INS: usize = CLOCK_BIAS;

pub type StateVector = nalgebra::SVector<f64, N>;
pub type StateMatrix = nalgebra::SMatrix<f64, N, N>;

/// The states that are not inert in `p`: those whose row of P is not all zero (an inert
/// state's variance and correlations are exactly zero, see the module's Choice), in
/// increasing order.
pub fn active_states(p: &StateMatrix) -> Vec<usize> {
    (0..N)
        .filter(|&i| p.row(i).iter().any(|&v| v != 0.0))
        .collect()
}
