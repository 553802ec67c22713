//! Online estimation of the measurement noise covariances (the adaptive part of the filter).
//!
//! Pure math, no I/O: each estimator is fed one scalar per epoch and returns its estimate.
//!
//! ERMAKF family (redundant-measurement based, the ERMAKF paper, section 3):
//! `redundant` (RMAE window, random weighting, KDE Gaussianity switch, Burg/AIC variance),
//! built on `burg`, `ar_variance`, `kde` and `random_weighting`.
//! EIAKF baseline (innovation based, after Ghaleb et al.): `innovation`.

pub mod ar_variance;
pub mod burg;
mod error;
pub mod innovation;
pub mod kde;
pub mod random_weighting;
pub mod redundant;

pub use error::AdaptiveError;
