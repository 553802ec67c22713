//! Simulation: the scenario ingredients that stand in for the real world in tests,
//! benchmarks and the `simulate` tool — deterministic truth trajectories with their
//! error-free IMU output, a seeded IMU error model, and a GPS constellation on Keplerian
//! orbits with its pseudo-ranges. No I/O.

pub mod constellation;
pub mod imu_errors;
pub mod smooth_window;
pub mod trajectory;

pub use imu_errors::{ImuErrorModel, ImuErrorModelError, ImuErrorSpec};
pub use trajectory::{Segment, Trajectory, TrajectoryError, TrajectorySpec, TruthSample};
