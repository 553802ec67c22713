//! Kalman filter steps and the models they linearize: the error-state process model,
//! the measurement rows, the EKF update, the cubature rule and the measurement update with
//! the IARF paper's adaptive and robust schemes on either base.

pub mod cubature;
pub mod ekf;
pub mod measurement_rows;
pub mod process_model;
pub mod robust_update;
