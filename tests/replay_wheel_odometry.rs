//! `gnss_ins replay` with a base controller's `/wheel/odometry` (nav_msgs/Odometry through
//! the bag's CDR, the node's adapter and the engine; issue 14, item 3): the simulated
//! consumer-MEMS car of tests/wheel_odometry.rs through its 30 s GNSS outage, its bag
//! given a wheel odometry made from the truth (the body-frame forward speed plus white
//! noise of [`WHEEL_SIGMA_MPS`], that σ² as `twist.covariance[0]`, at the truth's 10 Hz).
//! With `wheel_odometry.enabled` every message reaches the engine and the horizontal error
//! at the outage's end is within 1 % of the distance travelled in it; without, the
//! messages are counted as unfed and the run is the one of the bag without them.

mod bag_support;
mod car_outage_support;

use std::path::Path;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::engine::RejectionReason;
use adaptive_gnss_ins::eval::SolutionError;
use adaptive_gnss_ins::ros::adapter::Input;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriter};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::Odometry;
use adaptive_gnss_ins::sim::Scenario;
use adaptive_gnss_ins::tools::bag_inputs::WHEEL_ODOMETRY_TOPIC;
use adaptive_gnss_ins::tools::bag_run::BagRun;
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::{self, simulate_with, SimulateOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use car_outage_support::{
    at_outage_end_m, consumer_mems_loose, in_scenario_time, outage_distance_m, spec, CAR_OUTAGE,
    MAX_ERROR_FRACTION, SEED,
};

const WHEEL_SIGMA_MPS: f64 = 0.05;

fn car_config(wheels: bool) -> Config {
    let mut config = consumer_mems_loose();
    config.wheel_odometry.enabled = wheels;
    config
}

/// Copies the simulated bag `from` to `to`, adding a wheel odometry after each truth
/// message: the base controller's frames, the truth's body-frame forward speed plus
/// noise. Returns the number added.
fn with_wheel_odometry(from: &Path, to: &Path) -> u64 {
    let reader = BagReader::open(from).unwrap();
    let mut writer = BagWriter::create(to).unwrap();
    bag_support::add_simulated_topics(&mut writer);
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

/// The horizontal error of `run` scored nearest to the outage's end.
fn run_at_outage_end_m(run: &BagRun) -> f64 {
    let errors: Vec<SolutionError> = run.report.errors.iter().map(|(_, e)| *e).collect();
    at_outage_end_m(&in_scenario_time(&spec(CAR_OUTAGE), &errors))
}

#[test]
fn replay_feeds_the_wheel_odometry_of_a_bag_when_enabled() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.mcap");
    let scenario = Scenario::new(spec(CAR_OUTAGE), SEED).unwrap();
    simulate_with(&scenario, &plain, SimulateOptions { velocity: true }).unwrap();
    let wheels = dir.path().join("wheels.mcap");
    let added = with_wheel_odometry(&plain, &wheels);

    let on = replay_scored(&wheels, &car_config(true));
    let off = replay_scored(&wheels, &car_config(false));
    let without = replay_scored(&plain, &car_config(false));

    assert!(added > 2000, "{added}");
    assert_eq!(on.counts.stream(Input::WheelOdometry).received, added);
    assert_eq!(on.problems.used(WHEEL_ODOMETRY_TOPIC), added);
    assert_eq!(on.counts.stream(Input::WheelOdometry).unconvertible, 0);
    let before_start = on.rejections.count(RejectionReason::WheelSpeedBeforeStart);
    assert_eq!(on.rejections.total(), before_start, "{:?}", on.rejections);
    assert_eq!(off.counts.stream(Input::WheelOdometry).received, 0);
    assert_eq!(
        off.problems.unfed_inputs.get(WHEEL_ODOMETRY_TOPIC),
        Some(&added)
    );
    assert_eq!(off.report.errors, without.report.errors);

    let distance_m = outage_distance_m();
    let (on_m, off_m) = (run_at_outage_end_m(&on), run_at_outage_end_m(&off));
    println!(
        "replay: {added} wheel odometries ({before_start} before the start); horizontal \
         error at the outage's end ({distance_m} m travelled): {on_m:.2} m with them, \
         {off_m:.2} m without"
    );
    assert!(on_m <= MAX_ERROR_FRACTION * distance_m, "{on_m:.2} m");
    assert!(off_m > MAX_ERROR_FRACTION * distance_m, "{off_m:.2} m");
}
