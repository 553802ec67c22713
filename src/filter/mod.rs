//! Kalman filter steps and the models they linearize: the error-state process model,
//! the measurement rows, the EKF update and the cubature rule.

pub mod cubature;
pub mod ekf;
pub mod measurement_rows;
pub mod process_model;
