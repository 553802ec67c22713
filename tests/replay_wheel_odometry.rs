//! `gnss_ins replay` with a base controller's `/wheel/odometry` (nav_msgs/Odometry through
//! the bag's CDR, the node's adapter and the engine; issue 14, item 3): the simulated
//! consumer-MEMS car of tests/wheel_odometry.rs through its 30 s GNSS outage, its bag
//! given a wheel odometry made from the truth (the body-frame forward speed plus white
//! noise of [`WHEEL_SIGMA_MPS`], that σ² as `twist.covariance[0]`, at the truth's 10 Hz).
//! With `wheel_odometry.enabled` every message reaches the engine and the horizontal error
//! at the outage's end is within 1 % of the distance travelled in it; without, the
//! messages are counted as unfed and the run is the one of the bag without them.

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::engine::RejectionReason;
use adaptive_gnss_ins::eval::SolutionError;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriter};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry,
    TwistWithCovarianceStamped,
};
use adaptive_gnss_ins::ros::node::params::config_from_files;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::bag_inputs::WHEEL_ODOMETRY_TOPIC;
use adaptive_gnss_ins::tools::bag_run::BagRun;
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::{self, simulate_with, SimulateOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

const SEED: u64 = 1;
const OUTAGE_START_S: f64 = 145.0;
const OUTAGE_END_S: f64 = 175.0;
const OUTAGE_SPEED_MPS: f64 = 12.0;
const WHEEL_SIGMA_MPS: f64 = 0.05;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn consumer_mems_loose(wheels: bool) -> Config {
    let mut config = config_from_files(&[
        repo("params/ekf.yaml"),
        repo("params/ekf_loose.yaml"),
        repo("params/imu_consumer_mems.yaml"),
    ])
    .unwrap();
    config.wheel_odometry.enabled = wheels;
    config
}

/// Copies the simulated bag `from` to `to`, adding a wheel odometry after each truth
/// message: the base controller's frames, the truth's body-frame forward speed plus
/// noise. Returns the number added.
fn with_wheel_odometry(from: &Path, to: &Path) -> u64 {
    let reader = BagReader::open(from).unwrap();
    let mut writer = BagWriter::create(to).unwrap();
    writer.add_topic::<Imu>(simulate::IMU_TOPIC).unwrap();
    writer
        .add_topic::<GnssMeasurements>(simulate::GNSS_TOPIC)
        .unwrap();
    writer.add_topic::<NavSatFix>(simulate::FIX_TOPIC).unwrap();
    writer
        .add_topic::<TwistWithCovarianceStamped>(simulate::VELOCITY_TOPIC)
        .unwrap();
    writer.add_topic::<Odometry>(simulate::TRUTH_TOPIC).unwrap();
    writer
        .add_topic::<NavSatFix>(simulate::TRUTH_DATUM_TOPIC)
        .unwrap();
    writer
        .add_topic::<NoiseEstimates>(simulate::TRUTH_NOISE_TOPIC)
        .unwrap();
    writer
        .add_topic::<DiagnosticArray>(simulate::TRUTH_ENVIRONMENT_TOPIC)
        .unwrap();
    writer.add_topic::<Odometry>(WHEEL_ODOMETRY_TOPIC).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let noise = Normal::new(0.0, WHEEL_SIGMA_MPS).unwrap();
    let mut added = 0;
    for m in reader.messages().unwrap() {
        let m = m.unwrap();
        writer.write_cdr(&m.topic, &m.data, m.log_time_ns).unwrap();
        if m.topic != simulate::TRUTH_TOPIC {
            continue;
        }
        // The truth's twist is in its child frame, the body (REP-105), as a base
        // controller's.
        let truth: Odometry = cdr::decode(&m.data).unwrap();
        let mut wheels = Odometry {
            header: truth.header.clone(),
            child_frame_id: "base_link".to_owned(),
            ..Odometry::default()
        };
        wheels.header.frame_id = "odom".to_owned();
        wheels.twist.twist.linear.x = truth.twist.twist.linear.x + noise.sample(&mut rng);
        wheels.twist.covariance[0] = WHEEL_SIGMA_MPS.powi(2);
        writer
            .write(WHEEL_ODOMETRY_TOPIC, &wheels, m.log_time_ns)
            .unwrap();
        added += 1;
    }
    writer.finish().unwrap();
    added
}

fn replay_scored(bag: &Path, config: &Config) -> BagRun {
    let truth = TruthSource::Topic(simulate::TRUTH_TOPIC.to_owned());
    replay(bag, config, truth, &ReplayOptions::default(), |_| {}).unwrap()
}

/// The horizontal error scored nearest to the outage's end.
fn at_outage_end_m(run: &BagRun) -> f64 {
    let errors: Vec<&SolutionError> = run.report.errors.iter().map(|(_, e)| e).collect();
    let e = errors
        .iter()
        .min_by(|a, b| {
            (a.t_s - OUTAGE_END_S)
                .abs()
                .total_cmp(&(b.t_s - OUTAGE_END_S).abs())
        })
        .unwrap();
    e.position_enu_m.xy().norm()
}

#[test]
fn replay_feeds_the_wheel_odometry_of_a_bag_when_enabled() {
    let dir = tempfile::tempdir().unwrap();
    let spec = ScenarioSpec::from_yaml(
        &std::fs::read_to_string(repo("tests/data/consumer_mems_car_outage.yaml")).unwrap(),
    )
    .unwrap();
    let plain = dir.path().join("plain.mcap");
    let scenario = Scenario::new(spec, SEED).unwrap();
    simulate_with(&scenario, &plain, SimulateOptions { velocity: true }).unwrap();
    let wheels = dir.path().join("wheels.mcap");
    let added = with_wheel_odometry(&plain, &wheels);

    let on = replay_scored(&wheels, &consumer_mems_loose(true));
    let off = replay_scored(&wheels, &consumer_mems_loose(false));
    let without = replay_scored(&plain, &consumer_mems_loose(false));

    assert!(added > 2000, "{added}");
    assert_eq!(on.counts.wheel_odometry_received, added);
    assert_eq!(on.problems.used(WHEEL_ODOMETRY_TOPIC), added);
    assert_eq!(on.counts.unconvertible_wheel_odometry, 0);
    let before_start = on.rejections.count(RejectionReason::WheelSpeedBeforeStart);
    assert_eq!(on.rejections.total(), before_start, "{:?}", on.rejections);
    assert_eq!(off.counts.wheel_odometry_received, 0);
    assert_eq!(
        off.problems.unfed_inputs.get(WHEEL_ODOMETRY_TOPIC),
        Some(&added)
    );
    assert_eq!(off.report.errors, without.report.errors);

    let distance_m = OUTAGE_SPEED_MPS * (OUTAGE_END_S - OUTAGE_START_S);
    let (on_m, off_m) = (at_outage_end_m(&on), at_outage_end_m(&off));
    println!(
        "replay: {added} wheel odometries ({before_start} before the start); horizontal \
         error at the outage's end ({distance_m} m travelled): {on_m:.2} m with them, \
         {off_m:.2} m without"
    );
    assert!(on_m <= 0.01 * distance_m, "{on_m:.2} m");
    assert!(off_m > 0.01 * distance_m, "{off_m:.2} m");
}
