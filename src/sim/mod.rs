//! Simulation: the scenario ingredients that stand in for the real world in tests,
//! benchmarks and the `simulate` tool — deterministic truth trajectories with their
//! error-free IMU output, a seeded IMU error model, and a GPS constellation on Keplerian
//! orbits with its pseudo-ranges, and the scenario generator that combines them with the
//! signal environments (foliage, urban canyon, outage) into one event stream. No I/O.

pub mod ar_process;
pub mod carrier;
pub mod constellation;
pub mod environment;
pub mod imu_errors;
pub mod receiver_clock;
pub mod sat_errors;
pub mod scenario;
pub mod scenario_clock;
pub mod scenario_error;
pub mod scenario_spec;
pub mod smooth_window;
pub mod trajectory;

pub use imu_errors::{ImuErrorModel, ImuErrorModelError, ImuErrorSpec};
pub use scenario::{GnssTruth, Scenario, ScenarioEvents, SimEvent};
pub use scenario_clock::ScenarioClock;
pub use scenario_error::ScenarioError;
pub use scenario_spec::{DualAntennaSpec, ScenarioSpec};
pub use trajectory::{Segment, Trajectory, TrajectoryError, TrajectorySpec, TruthSample};
