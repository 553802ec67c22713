//! Simulation: deterministic truth trajectories with their error-free IMU output, and a
//! seeded IMU error model that turns the truth into realistic measurements.

pub mod imu_errors;
pub mod smooth_window;
pub mod trajectory;

pub use imu_errors::{ImuErrorModel, ImuErrorModelError, ImuErrorSpec};
pub use trajectory::{Segment, Trajectory, TrajectoryError, TrajectorySpec, TruthSample};
