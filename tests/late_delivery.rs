//! GNSS inputs delivered late, as DDS may (it gives no order across topics): each
//! measurement that arrives after the IMU passed its stamp rolls the engine back (during
//! the start-up too), so the adapter publishes the solutions of an in-time delivery but
//! for those it published before the measurement arrived, and publishes them all (a start
//! found late included), with every epoch's report once. Driven through the adapter, as
//! the node and `gnss_ins replay` drive it, on the fixture's scenario: tightly coupled,
//! and loosely coupled with receiver velocities (a fix waits for its velocity).

mod odometry_support;

use std::path::Path;

use adaptive_gnss_ins::config::{Config, Coupling};
use adaptive_gnss_ins::ros::adapter::{Input, InputMessage, OutputFrames, Published, RosAdapter};
use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::ros::convert::time_to_seconds;
use adaptive_gnss_ins::ros::msg::Odometry;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::bag_inputs::{BagInput, BagInputs, BagTopics};
use adaptive_gnss_ins::tools::simulate::{simulate_with, SimulateOptions};
use odometry_support::assert_live_matches_replay;

/// The input messages of the fixture's scenario, in the bag's order (GNSS epochs and, with
/// `velocity`, fixes and velocities).
fn fixture_messages(velocity: bool) -> Vec<InputMessage> {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("fixture.mcap");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let yaml = std::fs::read_to_string(root.join("tests/data/fixture_small.yaml")).unwrap();
    let scenario = Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), 1).unwrap();
    simulate_with(&scenario, &bag, SimulateOptions { velocity }).unwrap();
    let reader = BagReader::open(&bag).unwrap();
    let fed = [Input::Imu, Input::Gnss, Input::Fix, Input::Velocity];
    BagInputs::new(reader.messages().unwrap(), BagTopics::default(), &fed)
        .filter_map(|item| match item {
            BagInput::Message(m) => Some(m),
            _ => None,
        })
        .collect()
}

/// What the adapter published for some messages, and its count of late ones.
struct Run {
    odometry: Vec<Odometry>,
    /// Epoch reports (`~/noise_estimates`).
    epochs: usize,
    late_measurements: u64,
}

/// What the adapter publishes for `messages`.
fn run(messages: &[InputMessage], config: &Config) -> Run {
    let mut adapter = RosAdapter::new(config.clone(), OutputFrames::default());
    let (mut odometry, mut epochs) = (Vec::new(), 0);
    for m in messages {
        for published in adapter.on_message(m) {
            match published {
                Published::Solution(s) => {
                    odometry.push(s.messages.expect("framed").odometry.clone());
                }
                Published::Epoch(_) => epochs += 1,
                Published::NoFix(_) => {}
            }
        }
    }
    let late_measurements = adapter.engine().late_measurements();
    Run {
        odometry,
        epochs,
        late_measurements,
    }
}

/// `messages` with every GNSS message (all but the IMU) delivered after `delay` more IMU
/// samples.
fn delayed(messages: &[InputMessage], delay: usize) -> Vec<InputMessage> {
    let mut out = Vec::new();
    let mut held: Vec<(usize, InputMessage)> = Vec::new();
    let mut imu_seen = 0;
    for m in messages {
        if let InputMessage::Imu(_) = m {
            out.push(m.clone());
            imu_seen += 1;
            while held.first().is_some_and(|(due, _)| *due <= imu_seen) {
                out.push(held.remove(0).1);
            }
        } else {
            held.push((imu_seen + delay, m.clone()));
        }
    }
    out.extend(held.into_iter().map(|(_, m)| m));
    out
}

/// The stamps (s) of the GNSS messages the coupling of `config` uses, sorted.
fn measurement_stamps_s(messages: &[InputMessage], config: &Config) -> Vec<f64> {
    let tight = config.filter.coupling == Coupling::Tight;
    let mut stamps: Vec<f64> = messages
        .iter()
        .filter_map(|m| match m {
            InputMessage::Gnss(g) if tight => Some(&g.header.stamp),
            InputMessage::Fix(f) if !tight => Some(&f.header.stamp),
            _ => None,
        })
        .map(|t| time_to_seconds(t).unwrap())
        .collect();
    stamps.sort_by(f64::total_cmp);
    stamps
}

fn check(config: &Config, velocity: bool) {
    let messages = fixture_messages(velocity);
    let in_time = run(&messages, config);
    assert_eq!(in_time.late_measurements, 0, "the bag's order is the IMU's");
    let solutions = &in_time.odometry;
    assert!(solutions.len() > 2000, "{} solutions", solutions.len());
    let stamps = measurement_stamps_s(&messages, config);
    let epochs = stamps.len() as u64;
    // The epochs a solution follows (the last one, at the last IMU sample, none).
    let solution_s = |o: &Odometry| time_to_seconds(&o.header.stamp).unwrap();
    let (first_s, last_s) = (
        solution_s(&solutions[0]),
        solution_s(&solutions[solutions.len() - 1]),
    );
    let epochs_running = stamps
        .iter()
        .filter(|&&t| first_s < t && t < last_s)
        .count();
    // One sample, a few, and 0.2 s of a 100 Hz IMU.
    for delay in [1, 7, 20] {
        let late = run(&delayed(&messages, delay), config);
        let count = late.late_measurements;
        let what = format!("GNSS {delay} IMU samples late vs in time");
        let compared = assert_live_matches_replay(&late.odometry, solutions, &stamps, count, &what);
        println!("{what}: {count} late measurements, {compared:?}");
        // Every epoch after the first IMU sample came late, the starting one among them,
        // and each lacked in the solutions published before it came; each is reported
        // once, as in time.
        assert!(
            count + 1 >= epochs && count <= epochs,
            "{count} of {epochs}"
        );
        assert_eq!(compared.late_runs, epochs_running, "{compared:?}");
        assert!(
            compared.worst_late > 0.01,
            "the test sees a late epoch: {compared:?}"
        );
        assert_eq!(late.epochs, in_time.epochs, "{what}: epoch reports");
    }
}

#[test]
fn late_gnss_epochs_give_the_in_time_solutions_after_they_arrive() {
    check(&Config::default(), false);
}

#[test]
fn late_fixes_and_velocities_give_the_in_time_solutions_after_they_arrive() {
    let mut config = Config::default();
    config.set_parameter("filter.coupling", "loose").unwrap();
    check(&config, true);
}
