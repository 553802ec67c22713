//! Online estimation of the noise covariances (the adaptive part of the filter). Pure
//! math, no I/O: each estimator is fed one epoch at a time and returns its estimate.
//!
//! - ERMAKF family (redundant-measurement based, the ERMAKF paper, section 3): `redundant`
//!   (RMAE window, random weighting, KDE Gaussianity switch, Burg/AIC variance), built on
//!   `burg`, `ar_variance`, `kde` and `random_weighting`.
//! - EIAKF baseline (innovation based, after Ghaleb et al.): `innovation`.
//! - IARF family (the IARF paper): `predicted_residual` statistic, `adaptive_factor`,
//!   robust `equivalent_covariance` (double factor, IGG-III), `mahalanobis` test.
//! - Ding, Wang and Rizos: `residual_r` (residual-based R) and `q_scaling`.

pub mod adaptive_factor;
pub mod ar_variance;
pub mod burg;
pub mod common_mode;
pub mod equivalent_covariance;
mod error;
pub mod innovation;
pub mod kde;
pub mod mahalanobis;
pub mod math_error;
pub mod predicted_residual;
pub mod q_scaling;
pub mod random_weighting;
pub mod redundant;
pub mod residual_r;
pub mod variogram;

pub use error::AdaptiveError;
