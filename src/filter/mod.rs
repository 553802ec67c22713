//! Kalman filter steps and the models they linearize: the error-state process model,
//! the measurement rows, and the EKF update.

pub mod ekf;
pub mod measurement_rows;
pub mod process_model;
