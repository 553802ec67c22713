//! Online noise-covariance adaptation. The IARF family (Jiang & Zhang 2018): predicted-
//! residual statistic, adaptive factors, robust equivalent covariance (double factor,
//! IGG-III), Mahalanobis test. The Ding family (Ding, Wang & Rizos 2007): residual-based R
//! estimate and process-noise scaling.

pub mod adaptive_factor;
pub mod equivalent_covariance;
pub mod mahalanobis;
pub mod math_error;
pub mod predicted_residual;
pub mod q_scaling;
pub mod residual_r;
