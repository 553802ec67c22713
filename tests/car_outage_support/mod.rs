//! The simulated consumer-MEMS car through a 30 s GNSS outage at 12 m/s ending in a turn
//! (tests/data/consumer_mems_car_outage.yaml), loosely coupled with the receiver's
//! velocities (params/imu_consumer_mems.yaml): what the motion-constraint and wheel
//! odometry tests share.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::eval::SolutionError;
use adaptive_gnss_ins::ros::node::params::config_from_files;
use adaptive_gnss_ins::sim::{ScenarioClock, ScenarioSpec};

pub const SEED: u64 = 1;
/// The car's outage and its speed.
pub const OUTAGE_START_S: f64 = 145.0;
pub const OUTAGE_END_S: f64 = 175.0;
pub const OUTAGE_SPEED_MPS: f64 = 12.0;
/// Issue 14's figure: the horizontal error at the outage's end as a fraction of the
/// distance travelled in it.
pub const MAX_ERROR_FRACTION: f64 = 0.01;
pub const CAR_OUTAGE: &str = "tests/data/consumer_mems_car_outage.yaml";

pub fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The distance travelled in the outage (m).
pub fn outage_distance_m() -> f64 {
    OUTAGE_SPEED_MPS * (OUTAGE_END_S - OUTAGE_START_S)
}

pub fn consumer_mems_loose() -> Config {
    config_from_files(&[
        repo("params/defaults.yaml"),
        repo("params/ekf_loose.yaml"),
        repo("params/imu_consumer_mems.yaml"),
    ])
    .unwrap()
}

/// The scenario of the repository file `file`.
pub fn spec(file: &str) -> ScenarioSpec {
    ScenarioSpec::from_yaml(&std::fs::read_to_string(repo(file)).unwrap()).unwrap()
}

/// The errors of a replay of the simulated bag of `spec` (stamped in real time) on the
/// scenario's own time line, which [`at`] and the outage constants use.
pub fn in_scenario_time(spec: &ScenarioSpec, errors: &[SolutionError]) -> Vec<SolutionError> {
    let clock = ScenarioClock::new(&spec.gnss);
    errors
        .iter()
        .map(|e| SolutionError {
            t_s: clock.scenario_time_of_unix_s(e.t_s),
            ..*e
        })
        .collect()
}

/// The error scored nearest to `t_s`.
pub fn at(errors: &[SolutionError], t_s: f64) -> &SolutionError {
    errors
        .iter()
        .min_by(|a, b| (a.t_s - t_s).abs().total_cmp(&(b.t_s - t_s).abs()))
        .unwrap()
}

pub fn horizontal_m(e: &SolutionError) -> f64 {
    e.position_enu_m.xy().norm()
}

/// The horizontal error scored nearest to the outage's end.
pub fn at_outage_end_m(errors: &[SolutionError]) -> f64 {
    horizontal_m(at(errors, OUTAGE_END_S))
}
