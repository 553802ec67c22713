//! Gyrocompassing at rest (issue 14, item 6, "initial alignment"): a car with a
//! navigation-grade IMU (params/imu_navigation_grade.yaml, its simulated errors at the
//! class's 1-sigmas) parked for a minute, loosely coupled with RTK fixes and no receiver
//! velocity, starts the filter while still parked with the heading the earth's rotation
//! gives: before moving off, with a heading σ below half a degree, and with the heading
//! error within 3σ of that σ at the start and on every epoch to the end of the run.
//!
//! The start's vertical gyro bias (the levelling's mean rate less the earth's, weighed
//! against the class's prior) is within 3σ of the truth: taken whole with the class's σ,
//! the 10 s mean's rate noise (0.057 °/h) was five times the σ claimed (0.011 °/h).
//!
//! And the same start with a tactical IMU (params/imu_tactical.yaml) takes no heading at
//! rest: its gyrocompass σ is degrees, so it waits for the course as before.

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::engine::{Engine, Output, StatusEvent};
use adaptive_gnss_ins::eval;
use adaptive_gnss_ins::ins::error_state::{GYRO_BIAS, GYRO_GM, PHI};
use adaptive_gnss_ins::ros::node::params::config_from_files;
use adaptive_gnss_ins::sim::{ImuErrorModel, ImuErrorSpec, Segment, Trajectory, TrajectorySpec};
use nalgebra::Vector3;

mod support;
use support::fixes::{FixNoise, Fixes};

/// Parked for this long before moving off (s).
const PARKED_S: f64 = 60.0;
/// Largest heading 1-sigma of a navigation-grade start at rest (deg). The gyrocompass's
/// σ after the 10 s levelling of the class is 0.2–0.4° at these latitudes (the rate
/// noise's mean over 10 s dominates).
const MAX_START_SIGMA_DEG: f64 = 0.5;
const IMU_RATE_HZ: f64 = 100.0;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The class preset loosely coupled, the fixes taken at the IMU (no lever arm).
fn config(imu_preset: &str) -> Config {
    let mut config = config_from_files(&[
        repo("params/defaults.yaml"),
        repo("params/ekf_loose.yaml"),
        repo(imu_preset),
    ])
    .unwrap();
    config.mounting.lever_arm_b_m = Vector3::zeros();
    config
}

/// Parked, then pulls away, turns and cruises.
fn drive(lat_deg: f64, yaw_deg: f64) -> Trajectory {
    use Segment::*;
    Trajectory::new(&TrajectorySpec {
        start_t_s: 0.0,
        start_lat_deg: lat_deg,
        start_lon_deg: 114.47,
        start_height_m: 20.0,
        start_yaw_deg: yaw_deg,
        start_speed_m_s: 0.0,
        transition_s: 2.0,
        segments: vec![
            Stationary {
                duration_s: PARKED_S,
            },
            SpeedTo {
                duration_s: 15.0,
                speed_m_s: 10.0,
            },
            Turn {
                duration_s: 10.0,
                yaw_change_deg: 60.0,
            },
            Cruise { duration_s: 20.0 },
        ],
    })
    .unwrap()
}

/// The start of a run: its time, heading error and heading σ (deg), and the worst heading
/// error in units of its σ from the start to the end.
struct Run {
    started_s: f64,
    heading_from_motion: bool,
    start_error_deg: f64,
    start_sigma_deg: f64,
    worst_in_sigma: f64,
    /// The start's vertical (body z) gyro bias error, in its σ (bias and drift).
    start_vertical_bias_in_sigma: f64,
}

fn run(trajectory: &Trajectory, spec: &ImuErrorSpec, config: Config, seed: u64) -> Run {
    let true_vertical_bias_rad_s = spec.gyro_bias_deg_per_h[2].to_radians() / 3600.0;
    let mut imu = ImuErrorModel::new(spec, IMU_RATE_HZ, seed).unwrap();
    let mut fixes = Fixes::new(FixNoise::RTK, seed);
    let mut engine = Engine::new(config);
    let mut start: Option<Run> = None;
    for truth in trajectory.samples(IMU_RATE_HZ).unwrap() {
        let t = truth.nav.t_s;
        let mut out = engine.push_imu(&imu.corrupt(&truth.imu)).unwrap();
        let epoch_due = (t - t.round()).abs() < 1e-9;
        if epoch_due {
            out.extend(engine.push_fix(fixes.fix(&truth.nav)).unwrap());
        }
        let initialized = out.iter().find_map(|o| match o {
            Output::Status(StatusEvent::Initialized {
                t_s,
                heading_from_motion,
            }) => Some((*t_s, *heading_from_motion)),
            _ => None,
        });
        assert!(
            !out.iter()
                .any(|o| matches!(o, Output::Status(StatusEvent::Reset { .. }))),
            "a reset at {t} s"
        );
        let Some(state) = engine.state() else {
            continue;
        };
        if !(epoch_due || initialized.is_some()) {
            continue;
        }
        let reference = eval::TruthSample::from(&truth.nav);
        let error = eval::solution_error(&state.solution(), &reference);
        let error_deg = error.attitude_rpy_rad.unwrap()[2].to_degrees();
        let sigma_deg = state.p[(PHI + 2, PHI + 2)].sqrt().to_degrees();
        if let Some((t_s, heading_from_motion)) = initialized {
            let estimate_rad_s = state.gyro_bias_rad_s[2] + state.gyro_markov_rad_s[2];
            let variance_rad2_s2 = state.p[(GYRO_BIAS + 2, GYRO_BIAS + 2)]
                + state.p[(GYRO_GM + 2, GYRO_GM + 2)]
                + 2.0 * state.p[(GYRO_BIAS + 2, GYRO_GM + 2)];
            start = Some(Run {
                start_vertical_bias_in_sigma: (estimate_rad_s - true_vertical_bias_rad_s)
                    / variance_rad2_s2.sqrt(),
                started_s: t_s,
                heading_from_motion,
                start_error_deg: error_deg,
                start_sigma_deg: sigma_deg,
                worst_in_sigma: 0.0,
            });
        }
        if let Some(start) = &mut start {
            start.worst_in_sigma = start.worst_in_sigma.max(error_deg.abs() / sigma_deg);
        }
    }
    start.expect("the filter started")
}

#[test]
fn a_navigation_grade_imu_finds_its_heading_at_rest() {
    // Biases at the class's σ (params/imu_navigation_grade.yaml), one per axis's sign.
    let spec = ImuErrorSpec {
        gyro_bias_deg_per_h: [0.01, -0.01, 0.01],
        accel_bias_ug: [25.0, -25.0, 25.0],
        gyro_gm_sigma_deg_per_h: 0.005,
        gyro_gm_correlation_time_s: 3600.0,
        accel_gm_sigma_ug: 5.0,
        accel_gm_correlation_time_s: 3600.0,
        gyro_arw_deg_per_sqrt_h: 0.003,
        accel_vrw_ug_per_sqrt_hz: 20.0,
        gyro_scale_factor_ppm: [0.0; 3],
        accel_scale_factor_ppm: [0.0; 3],
    };
    // KF-GINS's demo start (Wuhan, heading 185.7°), and others in both hemispheres.
    for (seed, lat_deg, yaw_deg) in [
        (1, 30.44, -95.7),
        (2, 47.4, 30.0),
        (3, -35.0, 160.0),
        (4, 60.0, -20.0),
    ] {
        let name = format!("seed {seed}, latitude {lat_deg}°, yaw {yaw_deg}°");
        let trajectory = drive(lat_deg, yaw_deg);
        let r = run(
            &trajectory,
            &spec,
            config("params/imu_navigation_grade.yaml"),
            seed,
        );
        println!(
            "{name}: started at {:.1} s, heading error {:+.3}° (σ {:.3}°), worst later {:.2}σ; \
             vertical gyro bias {:+.2}σ",
            r.started_s,
            r.start_error_deg,
            r.start_sigma_deg,
            r.worst_in_sigma,
            r.start_vertical_bias_in_sigma
        );
        assert!(
            r.started_s < PARKED_S && !r.heading_from_motion,
            "{name}: started at {} s, heading from motion {}",
            r.started_s,
            r.heading_from_motion
        );
        assert!(
            r.start_sigma_deg < MAX_START_SIGMA_DEG,
            "{name}: heading σ {:.3}° at the start",
            r.start_sigma_deg
        );
        assert!(
            r.start_error_deg.abs() <= 3.0 * r.start_sigma_deg,
            "{name}: heading error {:.3}° at the start beyond 3σ ({:.3}°)",
            r.start_error_deg,
            r.start_sigma_deg
        );
        assert!(
            r.worst_in_sigma <= 3.0,
            "{name}: heading error reached {:.2}σ",
            r.worst_in_sigma
        );
        assert!(
            r.start_vertical_bias_in_sigma.abs() <= 3.0,
            "{name}: vertical gyro bias {:.2}σ off at the start",
            r.start_vertical_bias_in_sigma
        );
    }
}

#[test]
fn a_tactical_imu_takes_no_heading_at_rest() {
    let trajectory = drive(30.44, -95.7);
    let spec = ImuErrorSpec {
        gyro_bias_deg_per_h: [1.0, -1.0, 1.0],
        gyro_arw_deg_per_sqrt_h: 0.1,
        accel_bias_ug: [1000.0, -1000.0, 1000.0],
        accel_vrw_ug_per_sqrt_hz: 60.0,
        ..ImuErrorSpec::default()
    };
    let r = run(&trajectory, &spec, config("params/imu_tactical.yaml"), 1);
    println!(
        "tactical: started at {:.1} s, heading error {:+.3}° (σ {:.3}°)",
        r.started_s, r.start_error_deg, r.start_sigma_deg
    );
    assert!(
        r.started_s > PARKED_S && r.heading_from_motion,
        "tactical: started at {} s, heading from motion {}",
        r.started_s,
        r.heading_from_motion
    );
}
