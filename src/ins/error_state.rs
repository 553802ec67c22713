//! The 20-state error vector of the ERMAKF paper, eqs. (1)–(6), with every block's offset
//! named once. Blocks are used by name (`PHI`, `DV`, ...), never by literal offsets.
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
/// Dimension of the error state.
pub const N: usize = 20;

/// Dimension of the inertial part (everything before the clock).
pub const N_INS: usize = CLOCK_BIAS;

pub type StateVector = nalgebra::SVector<f64, N>;
pub type StateMatrix = nalgebra::SMatrix<f64, N, N>;
