//! The golden replay: a small bag written by the simulator (tests/data/fixture_small.mcap,
//! from tests/data/fixture_small.yaml with seed 1) is
//! 1. opened by the independent `rosbags` package (tools/check_bag_with_rosbags.py, the
//!    venv of scripts/setup_test_peers.sh), which proves it a valid ROS 2 bag, and
//! 2. replayed through the engine with the default parameters; the solution CSV must match
//!    tests/data/fixture_small_solution.csv in every number to a relative 1e-9
//!    (|a − b| ≤ 1e-9 · max(|a|, |b|, 1): relative for values above 1 in their unit, an
//!    absolute 1e-9 below, where a relative test would ask more digits of a near-zero
//!    velocity or roll than the arithmetic carries).
//!
//! The golden CSV records what the engine does, not what it should do: a deliberate
//! change of the engine's math changes it legitimately. Regenerate it then with
//!   cargo test --release --test replay_golden -- --ignored regenerate_golden_solution
//! (or `gnss_ins replay tests/data/fixture_small.mcap --csv
//! tests/data/fixture_small_solution.csv`), and look at the diff before committing. The
//! bag itself only changes when the simulator or the bag writer does:
//!   cargo test --release --test replay_golden -- --ignored regenerate_fixture_bag
//! (or `gnss_ins simulate --scenario tests/data/fixture_small.yaml --seed 1 --out
//! tests/data/fixture_small.mcap`), then regenerate the CSV.

use std::path::{Path, PathBuf};
use std::process::Command;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::simulate;
use serde_json::Value;

mod venv_support;

/// Relative tolerance of the comparison (see the module doc).
const RELATIVE_TOLERANCE: f64 = 1e-9;
/// Seed of the fixture's simulation.
const FIXTURE_SEED: u64 = 1;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn fixture_bag() -> PathBuf {
    data("fixture_small.mcap")
}

/// The fixture's scenario with its seed.
fn fixture_scenario() -> Scenario {
    let yaml = std::fs::read_to_string(data("fixture_small.yaml")).unwrap();
    Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), FIXTURE_SEED).unwrap()
}

fn golden_csv() -> PathBuf {
    data("fixture_small_solution.csv")
}

/// Replays the fixture with the default parameters into the CSV `out`; returns the
/// number of solutions.
fn replay_fixture(out: &Path) -> usize {
    let options = ReplayOptions {
        csv: Some(out),
        ..ReplayOptions::default()
    };
    let result = replay(
        &fixture_bag(),
        &Config::default(),
        TruthSource::None,
        &options,
        |_| {},
    )
    .unwrap();
    assert!(result.problems.bag_errors.is_empty());
    assert!(result.problems.undecodable.is_empty());
    result.report.solutions
}

#[test]
fn rosbags_reads_the_fixture_as_a_ros2_bag() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/check_bag_with_rosbags.py");
    let output = Command::new(venv_support::python())
        .arg(&script)
        .arg(fixture_bag())
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "rosbags could not read the fixture: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let summary: Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(summary["log_time_order"], true);
    // 36 s: IMU at 100 Hz, GNSS at 1 Hz, the reference at 5 Hz, all including t = 0 and
    // t = 36 s; the datum once; the environment at every GNSS epoch.
    let expected = [
        ("/imu", "sensor_msgs/msg/Imu", 3601),
        (
            "/gnss/measurements",
            "adaptive_gnss_ins/msg/GnssMeasurements",
            37,
        ),
        ("/gnss/fix", "sensor_msgs/msg/NavSatFix", 37),
        ("/ground_truth", "nav_msgs/msg/Odometry", 181),
        ("/ground_truth/datum", "sensor_msgs/msg/NavSatFix", 1),
        (
            "/ground_truth/noise",
            "adaptive_gnss_ins/msg/NoiseEstimates",
            37,
        ),
        (
            "/ground_truth/environment",
            "diagnostic_msgs/msg/DiagnosticArray",
            37,
        ),
    ];
    let topics = summary["topics"].as_object().unwrap();
    assert_eq!(topics.len(), expected.len());
    let mut total = 0;
    for (topic, type_name, count) in expected {
        let got = &topics[topic];
        assert_eq!(got["type"], type_name, "{topic}");
        assert_eq!(got["count"], count, "{topic}");
        assert_eq!(got["count_in_index"], count, "{topic}");
        total += count;
    }
    assert_eq!(summary["message_count"], total);
    // Log times are UTC, from the scenario's start (the default week: 2025-10-01
    // 23:59:51 UTC, plus the scenario's start_gps_s of 3 h).
    let start_ns = fixture_scenario().clock().start_utc_ns();
    assert_eq!(start_ns, 1_759_363_191_000_000_000 + 10_800_000_000_000);
    assert_eq!(summary["start_time_ns"], start_ns);
    // rosbags reports the end as one past the last log time (36 s).
    assert_eq!(summary["end_time_ns"], start_ns + 36_000_000_001);
    for (type_name, verdict) in summary["definitions"].as_object().unwrap() {
        assert!(
            verdict == "matches jazzy" || verdict == "matches msg/",
            "{type_name}: {verdict}"
        );
    }
    // The first IMU sample as rosbags decoded it: stamped at the start, at rest (the
    // specific force is gravity, up, with the simulated accelerometer errors).
    let first_imu = &topics["/imu"]["first"];
    assert_eq!(
        first_imu["header"]["stamp"]["sec"],
        start_ns / 1_000_000_000
    );
    assert_eq!(first_imu["header"]["stamp"]["nanosec"], 0);
    let f_up = first_imu["linear_acceleration"]["z"].as_f64().unwrap();
    assert!((f_up - 9.80).abs() < 0.05, "{f_up}");
}

/// Parses a solution CSV into its header and rows of numbers.
fn read_csv(path: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_owned();
    let rows = lines
        .map(|line| line.split(',').map(|f| f.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn replaying_the_fixture_reproduces_the_golden_solution() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("solution.csv");
    let solutions = replay_fixture(&out);
    let (header, rows) = read_csv(&out);
    let (golden_header, golden) = read_csv(&golden_csv());
    assert_eq!(header, golden_header);
    assert_eq!(rows.len(), solutions);
    assert_eq!(rows.len(), golden.len(), "number of solutions");
    // The fixture's solutions start once the heading is known from the motion (about
    // 10 s) and run to its end (36 s) at the IMU rate.
    assert!(golden.len() > 2000, "{}", golden.len());
    let columns: Vec<&str> = header.split(',').collect();
    let mut worst = (0.0_f64, String::new());
    for (i, (row, want)) in rows.iter().zip(&golden).enumerate() {
        assert_eq!(row.len(), want.len(), "row {i}");
        // The time (UNIX seconds, where the relative test would allow 1.8 s) exactly.
        assert_eq!(row[0], want[0], "row {i}: t_s");
        for ((got, want), column) in row.iter().zip(want).zip(&columns) {
            let scale = got.abs().max(want.abs()).max(1.0);
            let error = (got - want).abs() / scale;
            assert!(
                error <= RELATIVE_TOLERANCE,
                "row {i} (t = {} s), {column}: {got} against the golden {want}",
                row[0]
            );
            if error > worst.0 {
                worst = (error, format!("row {i}, {column}"));
            }
        }
    }
    eprintln!("largest scaled difference {:e} ({})", worst.0, worst.1);
}

/// Rewrites the golden CSV from the engine as it is now (see the module doc).
#[test]
#[ignore = "regenerates tests/data/fixture_small_solution.csv"]
fn regenerate_golden_solution() {
    let solutions = replay_fixture(&golden_csv());
    eprintln!("wrote {} ({solutions} solutions)", golden_csv().display());
}

/// Rewrites the fixture bag from its scenario (see the module doc).
#[test]
#[ignore = "regenerates tests/data/fixture_small.mcap"]
fn regenerate_fixture_bag() {
    let scenario = fixture_scenario();
    let summary = simulate(&scenario, &fixture_bag()).unwrap();
    eprintln!("wrote {}: {summary:?}", fixture_bag().display());
}

/// `simulate` is deterministic from the seed: the committed fixture is reproduced to the
/// byte, and a different seed gives a different bag.
#[test]
fn simulating_the_fixture_scenario_again_gives_the_same_bytes() {
    let yaml = std::fs::read_to_string(data("fixture_small.yaml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let again = dir.path().join("again.mcap");
    simulate(&fixture_scenario(), &again).unwrap();
    let committed = std::fs::read(fixture_bag()).unwrap();
    assert!(
        std::fs::read(&again).unwrap() == committed,
        "the simulated bag differs from the fixture"
    );
    let other = dir.path().join("other_seed.mcap");
    let scenario =
        Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), FIXTURE_SEED + 1).unwrap();
    simulate(&scenario, &other).unwrap();
    assert!(std::fs::read(&other).unwrap() != committed);
}
