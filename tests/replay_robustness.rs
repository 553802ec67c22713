//! `gnss_ins replay` on damaged or unexpected bags: a truncated bag and a corrupt chunk
//! give partial results and name the damage; unknown topics, topics of an unexpected type
//! and messages that do not decode are counted and skipped; a bag with no IMU fails with
//! a clear message. Replay runs the node's adapter: one IMU stamp far ahead costs a reset
//! (the node's time-jump rule), not the rest of the bag; a solution with a non-finite
//! value is counted and not written. The binary exits non-zero when nothing usable is
//! left or when most IMU samples did not reach the filter.
//!
//! The bags are made from the golden fixture (tests/data/fixture_small.mcap, 36 s).

mod odometry_support;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::engine::RejectionReason;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriteOptions, BagWriter};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NavSatStatus, NoiseEstimates, Odometry,
    RosMessage,
};
use adaptive_gnss_ins::tools::bag_run::BagRun;
use adaptive_gnss_ins::tools::replay::TruthSource;
use adaptive_gnss_ins::tools::replay::{replay, ReplayError, ReplayOptions};

fn fixture_bag() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixture_small.mcap")
}

fn replay_bag(bag: &Path) -> Result<BagRun, ReplayError> {
    replay(
        bag,
        &Config::default(),
        TruthSource::None,
        &ReplayOptions::default(),
        |_| {},
    )
}

/// Runs the `gnss_ins` binary with `args`.
fn gnss_ins(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Runs `gnss_ins replay BAG --csv CSV`; returns its output and its stderr.
fn replay_to_csv(bag: &Path, csv: &Path) -> (Output, String) {
    let output = gnss_ins(&[
        "replay".as_ref(),
        bag.as_os_str(),
        "--csv".as_ref(),
        csv.as_os_str(),
    ]);
    let text = stderr(&output);
    (output, text)
}

/// Adds `topic` to `writer` with the type `type_name` (one of the fixture's types).
fn add_topic(writer: &mut BagWriter, topic: &str, type_name: &str) {
    match type_name {
        t if t == Imu::TYPE_NAME => writer.add_topic::<Imu>(topic),
        t if t == GnssMeasurements::TYPE_NAME => writer.add_topic::<GnssMeasurements>(topic),
        t if t == NavSatFix::TYPE_NAME => writer.add_topic::<NavSatFix>(topic),
        t if t == Odometry::TYPE_NAME => writer.add_topic::<Odometry>(topic),
        t if t == NoiseEstimates::TYPE_NAME => writer.add_topic::<NoiseEstimates>(topic),
        t if t == DiagnosticArray::TYPE_NAME => writer.add_topic::<DiagnosticArray>(topic),
        other => panic!("unexpected type {other}"),
    }
    .unwrap();
}

/// What to do with one message of the fixture while copying it.
enum Copy {
    Keep,
    Drop,
    /// Write these bytes instead of the message's.
    Replace(Vec<u8>),
}

/// Copies the fixture to `out` with `options`, letting `edit` keep, drop or replace each
/// message (by topic and index on its topic); topics all of whose messages are dropped
/// are left out. `extra` adds topics before the copy.
fn copy_fixture(
    out: &Path,
    options: BagWriteOptions,
    extra: impl FnOnce(&mut BagWriter),
    mut edit: impl FnMut(&str, u64) -> Copy,
) {
    let reader = BagReader::open(fixture_bag()).unwrap();
    let mut writer = BagWriter::create_with_options(out, options).unwrap();
    extra(&mut writer);
    let mut index = std::collections::HashMap::<String, u64>::new();
    let mut added = std::collections::HashSet::<String>::new();
    for message in reader.messages().unwrap() {
        let message = message.unwrap();
        let k = index.entry(message.topic.clone()).or_insert(0);
        let action = edit(&message.topic, *k);
        *k += 1;
        let data = match action {
            Copy::Keep => message.data,
            Copy::Drop => continue,
            Copy::Replace(bytes) => bytes,
        };
        if added.insert(message.topic.clone()) {
            add_topic(&mut writer, &message.topic, &message.type_name);
        }
        writer
            .write_cdr(&message.topic, &data, message.log_time_ns)
            .unwrap();
    }
    writer.finish().unwrap();
}

/// Copies the fixture to `out` with each /imu message `k` changed by `edit(k, message)`,
/// the other messages kept.
fn copy_fixture_imu_edited(out: &Path, mut edit: impl FnMut(u64, &mut Imu)) {
    let edited: Vec<Vec<u8>> = BagReader::open(fixture_bag())
        .unwrap()
        .messages()
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.topic == "/imu")
        .zip(0..)
        .map(|(m, k)| {
            let mut imu: Imu = cdr::decode(&m.data).unwrap();
            edit(k, &mut imu);
            cdr::encode(&imu).unwrap()
        })
        .collect();
    copy_fixture(
        out,
        BagWriteOptions::default(),
        |_| {},
        |topic, k| {
            if topic == "/imu" {
                Copy::Replace(edited[k as usize].clone())
            } else {
                Copy::Keep
            }
        },
    );
}

/// The rows of a solution CSV as numbers (without the header).
fn csv_rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// Copies the fixture to `out` with every /imu message handled as `imu` says, the other
/// messages kept.
fn copy_fixture_imu_as(out: &Path, imu: impl Fn() -> Copy) {
    copy_fixture(
        out,
        BagWriteOptions::default(),
        |_| {},
        |topic, _| {
            if topic == "/imu" {
                imu()
            } else {
                Copy::Keep
            }
        },
    );
}

#[test]
fn a_truncated_bag_gives_the_solutions_before_the_cut_and_names_the_damage() {
    let full = replay_bag(&fixture_bag()).unwrap();
    assert!(full.problems.bag_errors.is_empty());

    let dir = tempfile::tempdir().unwrap();
    let cut = dir.path().join("cut.mcap");
    let bytes = std::fs::read(fixture_bag()).unwrap();
    // 70 %: past the first chunk (768 KiB of 1.6 MB), inside the second.
    std::fs::write(&cut, &bytes[..bytes.len() * 7 / 10]).unwrap();

    let partial = replay_bag(&cut).unwrap();
    assert!(
        !partial.problems.bag_errors.is_empty(),
        "the truncation must be reported"
    );
    assert!(partial.report.solutions > 0);
    assert!(
        partial.report.solutions < full.report.solutions,
        "{} of {}",
        partial.report.solutions,
        full.report.solutions
    );

    // The binary keeps what it could compute: exit 0, the damage on stderr, the output
    // bag and CSV written.
    let csv = dir.path().join("cut.csv");
    let out = dir.path().join("cut_out.mcap");
    let output = gnss_ins(&[
        "replay".as_ref(),
        cut.as_os_str(),
        "--csv".as_ref(),
        csv.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(stderr(&output).contains("bag error"), "{}", stderr(&output));
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
    assert_eq!(rows, partial.report.solutions);
    let written = BagReader::open(&out).unwrap();
    let odometry = written
        .topics()
        .iter()
        .find(|t| t.topic == "/odometry")
        .unwrap();
    assert_eq!(odometry.message_count as usize, partial.report.solutions);
}

#[test]
fn a_corrupt_chunk_is_skipped_and_the_rest_is_replayed() {
    let dir = tempfile::tempdir().unwrap();
    // Small chunks so that one corrupt chunk is a small part of the bag.
    let small_chunks = BagWriteOptions {
        chunk_size_bytes: 64 * 1024,
        ..BagWriteOptions::default()
    };
    let bag = dir.path().join("chunks.mcap");
    copy_fixture(&bag, small_chunks, |_| {}, |_, _| Copy::Keep);
    let intact = replay_bag(&bag).unwrap();
    assert!(intact.problems.bag_errors.is_empty());

    // Flip a byte three quarters into the file: inside a chunk's messages (the summary
    // at the end is a few kB).
    let mut bytes = std::fs::read(&bag).unwrap();
    let at = bytes.len() * 3 / 4;
    bytes[at] ^= 0x5a;
    let corrupt = dir.path().join("corrupt.mcap");
    std::fs::write(&corrupt, &bytes).unwrap();

    let result = replay_bag(&corrupt).unwrap();
    assert_eq!(
        result.problems.bag_errors.len(),
        1,
        "{:?}",
        result.problems.bag_errors
    );
    assert!(
        result.problems.bag_errors[0].contains("corrupt"),
        "{}",
        result.problems.bag_errors[0]
    );
    // One 64 KiB chunk holds under 2 s of data: most solutions survive, and solutions
    // resume after the gap (the last one is at the end of the bag).
    let lost = intact.report.solutions - result.report.solutions;
    assert!(
        lost > 0 && lost < 300,
        "{} of {}",
        result.report.solutions,
        intact.report.solutions
    );
    assert!(result.report.solutions > intact.report.solutions * 8 / 10);
}

#[test]
fn unknown_topics_wrong_types_and_undecodable_messages_are_counted_and_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("odd.mcap");
    let garbage = vec![0, 1, 0, 0, 0xde, 0xad];
    copy_fixture(
        &bag,
        BagWriteOptions::default(),
        |w| {
            // A topic no run uses, and a used topic name with another type.
            w.add_topic::<DiagnosticArray>("/camera/status").unwrap();
            w.add_topic::<Odometry>("/gnss/fix").unwrap();
            for k in 0..5_u64 {
                let t_ns = k * 1_000_000_000;
                w.write("/camera/status", &DiagnosticArray::default(), t_ns)
                    .unwrap();
                w.write("/gnss/fix", &Odometry::default(), t_ns).unwrap();
            }
        },
        |topic, k| match topic {
            "/gnss/fix" => Copy::Drop,
            // Every 100th IMU sample is garbage (36 of 3601).
            "/imu" if k % 100 == 50 => Copy::Replace(garbage.clone()),
            _ => Copy::Keep,
        },
    );
    let result = replay_bag(&bag).unwrap();
    let p = &result.problems;
    assert_eq!(
        p.unused_topics
            .get("/camera/status (diagnostic_msgs/msg/DiagnosticArray)"),
        Some(&5),
        "{p:?}"
    );
    assert_eq!(
        p.wrong_types
            .get("/gnss/fix: nav_msgs/msg/Odometry, expected sensor_msgs/msg/NavSatFix"),
        Some(&5),
        "{p:?}"
    );
    let undecodable: u64 = p
        .undecodable
        .iter()
        .filter(|(k, _)| k.starts_with("/imu: "))
        .map(|(_, n)| n)
        .sum();
    assert_eq!(undecodable, 36, "{p:?}");
    assert_eq!(p.used("/imu"), 3601 - 36);
    assert_eq!(p.used("/gnss/measurements"), 37);
    assert!(p.bag_errors.is_empty());
    // The engine bridges a missing IMU sample (a 20 ms interval): solutions go on.
    assert!(
        result.report.solutions > 2000,
        "{}",
        result.report.solutions
    );

    let output = gnss_ins(&["replay".as_ref(), bag.as_os_str()]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(text.contains("ignored 5 messages on a topic this run does not use: /camera/status"));
    assert!(text.contains("skipped 5 messages of an unexpected type: /gnss/fix"));
    assert!(text.contains("undecodable messages (/imu: "), "{text}");
}

#[test]
fn a_bag_without_imu_fails_with_a_clear_message_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("no_imu.mcap");
    copy_fixture_imu_as(&bag, || Copy::Drop);
    let error = replay_bag(&bag).unwrap_err();
    let text = error.to_string();
    assert!(matches!(error, ReplayError::NoImu { .. }), "{text}");
    assert!(
        text.contains("no sensor_msgs/msg/Imu messages on /imu"),
        "{text}"
    );
    assert!(
        text.contains("/gnss/measurements (adaptive_gnss_ins/msg/GnssMeasurements, 37)"),
        "{text}"
    );

    let output = gnss_ins(&["replay".as_ref(), bag.as_os_str()]);
    assert!(!output.status.success());
    assert!(stderr(&output).contains("no sensor_msgs/msg/Imu messages on /imu"));
}

#[test]
fn a_bag_whose_imu_never_decodes_exits_non_zero_and_says_what_was_used() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("bad_imu.mcap");
    copy_fixture_imu_as(&bag, || Copy::Replace(vec![0, 1, 0, 0, 7]));
    let result = replay_bag(&bag).unwrap();
    assert_eq!(result.report.solutions, 0);
    assert_eq!(result.problems.used("/imu"), 0);

    let output = gnss_ins(&["replay".as_ref(), bag.as_os_str()]);
    assert!(!output.status.success());
    let text = stderr(&output);
    assert!(text.contains("3601 undecodable messages (/imu: "), "{text}");
    assert!(text.contains("no solution"), "{text}");
    assert!(text.contains("37 on /gnss/measurements"), "{text}");
}

/// Issue 12, item 9: a configuration under which the fixture never starts names the
/// parameter that prevents the start (the fixture sees at most 10 satellites and drives
/// at 8 m/s), not "nothing usable in the bag".
#[test]
fn a_configuration_that_never_starts_names_the_parameter_that_prevents_it() {
    let dir = tempfile::tempdir().unwrap();
    for (section, key, value, expected) in [
        (
            "init",
            "min_satellites",
            "64",
            "init.min_satellites = 64 satellites",
        ),
        (
            "init",
            "heading_min_speed_mps",
            "50.0",
            "init.heading_min_speed_mps = 50 m/s",
        ),
    ] {
        let params = dir.path().join(format!("{key}.yaml"));
        std::fs::write(
            &params,
            format!("/**:\n  ros__parameters:\n    {section}:\n      {key}: {value}\n"),
        )
        .unwrap();
        let output = gnss_ins(&[
            "replay".as_ref(),
            fixture_bag().as_os_str(),
            "--params".as_ref(),
            params.as_os_str(),
        ]);
        assert!(!output.status.success());
        let text = stderr(&output);
        assert!(text.contains("no solution"), "{text}");
        assert!(text.contains(expected), "{key}: {text}");
    }
}

#[test]
fn a_file_that_is_not_a_bag_fails_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let not_a_bag = dir.path().join("notes.mcap");
    std::fs::write(&not_a_bag, "just text").unwrap();
    let output = gnss_ins(&["replay".as_ref(), not_a_bag.as_os_str()]);
    assert!(!output.status.success());
    assert!(
        stderr(&output).contains("not an MCAP file"),
        "{}",
        stderr(&output)
    );
}

/// Issue 12, items 14 and 11: one IMU sample stamped 10⁶ s ahead made replay reject every
/// later sample as out of order and exit 0 with the solutions of the first 15 s. Replay
/// applies the node's time-line rule: the lone outlier is dropped and counted, no reset.
#[test]
fn one_imu_sample_stamped_far_ahead_is_dropped_not_the_rest_of_the_bag() {
    let full = replay_bag(&fixture_bag()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("ahead.mcap");
    // The sample at 15 s, while driving.
    copy_fixture_imu_edited(&bag, |k, imu| {
        if k == 1500 {
            imu.header.stamp.sec += 1_000_000;
        }
    });
    let result = replay_bag(&bag).unwrap();
    assert_eq!(result.counts.time_jump_resets, 0);
    assert_eq!(result.counts.imu_stamp_outliers, 1);
    assert_eq!(result.rejections.count(RejectionReason::ImuGap), 0);
    assert_eq!(
        result.rejections.count(RejectionReason::ImuOutOfOrder),
        0,
        "the samples after it are used"
    );
    assert!(
        result.report.solutions + 1 >= full.report.solutions,
        "{} of {} solutions",
        result.report.solutions,
        full.report.solutions
    );

    let csv = dir.path().join("ahead.csv");
    let (output, text) = replay_to_csv(&bag, &csv);
    assert!(output.status.success(), "{text}");
    assert!(
        text.contains("dropped 1 messages: imu_stamp_outliers"),
        "{text}"
    );
    let last_t_s = csv_rows(&csv).last().unwrap()[0];
    assert!(last_t_s > 35.9, "the solutions end at {last_t_s} s");
}

/// The other half of item 14: a replay that loses most of its IMU samples (here the IMU
/// clock freezes at 15 s, so every later sample repeats a stamp) says so and exits
/// non-zero, keeping what it wrote.
#[test]
fn a_replay_that_drops_most_imu_samples_fails_and_keeps_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("frozen.mcap");
    let mut frozen = None;
    copy_fixture_imu_edited(&bag, |k, imu| {
        if k >= 1500 {
            imu.header.stamp = *frozen.get_or_insert(imu.header.stamp);
        }
    });
    let result = replay_bag(&bag).unwrap();
    assert_eq!(result.imu_dropped("/imu"), (2100, 3601));

    let csv = dir.path().join("frozen.csv");
    let (output, text) = replay_to_csv(&bag, &csv);
    assert!(!output.status.success(), "{text}");
    assert!(
        text.contains("2100 of the 3601 IMU messages did not reach the filter"),
        "{text}"
    );
    assert_eq!(csv_rows(&csv).len(), result.report.solutions);
}

/// Spikes inside the widest screen, every tenth sample: 0.99e6 deg/s and 0.99e6 g.
const SPIKE_RAD_S: f64 = 0.99e6 * std::f64::consts::PI / 180.0;
const SPIKE_M_S2: f64 = 0.99e6 * 9.80665;

/// The IMU screen as wide as its parameter ranges allow.
const OPEN_SCREEN_YAML: &str = "/**:\n  ros__parameters:\n    imu:\n      \
    gyro_range_deg_per_s: 1.0e6\n      accel_range_g: 1.0e6\n      \
    gyro_max_step_deg_per_s: 0.0\n      accel_max_step_g: 0.0\n";

/// Every number of an Odometry.
/// Issue 12, item 7: a gyro sample of 10¹⁰ rad/s every 100 samples made replay write
/// solutions with non-finite covariances and negative variances (NaN σ in the CSV).
/// Replay now has the node's guard: they are counted and not written, to the bag or the
/// CSV. The IMU screen drops such samples now, so the screen is opened as wide as the
/// parameter ranges allow (what slips through a screen is what the guard is for) and the
/// spikes stay just inside it.
#[test]
fn solutions_with_a_non_finite_value_or_a_negative_variance_are_counted_and_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("spikes.mcap");
    copy_fixture_imu_edited(&bag, |k, imu| {
        if k % 10 == 5 {
            imu.angular_velocity.x = SPIKE_RAD_S;
            imu.linear_acceleration.z = SPIKE_M_S2;
        }
    });
    let params = dir.path().join("open_screen.yaml");
    std::fs::write(&params, OPEN_SCREEN_YAML).unwrap();
    let mut config = Config::default();
    config.imu.gyro_range_rad_s = 1e6_f64.to_radians();
    config.imu.accel_range_m_s2 = 1e6 * 9.80665;
    config.imu.gyro_step_max_rad_s = 0.0;
    config.imu.accel_step_max_m_s2 = 0.0;
    let csv = dir.path().join("spikes.csv");
    let out = dir.path().join("spikes_out.mcap");
    let options = ReplayOptions {
        out_bag: Some(&out),
        csv: Some(&csv),
        ..ReplayOptions::default()
    };
    let result = replay(&bag, &config, TruthSource::None, &options, |_| {}).unwrap();
    let non_finite = result.counts.non_finite_outputs;
    let negative = result.counts.negative_variance_outputs;
    // The precondition of the test, not a figure of merit: 16 with these spikes (the
    // 1e10 rad/s spikes before the screen gave hundreds).
    assert!(
        non_finite + negative >= 10,
        "the bag must provoke bad solutions: {non_finite}, {negative}"
    );

    let output = gnss_ins(&[
        "replay".as_ref(),
        bag.as_os_str(),
        "--params".as_ref(),
        params.as_os_str(),
        "--csv".as_ref(),
        dir.path().join("spikes_cli.csv").as_os_str(),
    ]);
    let text = stderr(&output);
    assert!(output.status.success(), "{text}");
    assert!(
        text.contains("solutions with a negative variance were not written"),
        "{text}"
    );
    let rows = csv_rows(&csv);
    assert!(!rows.is_empty());
    assert_eq!(rows.len(), result.report.solutions);
    assert!(rows.iter().flatten().all(|v| v.is_finite()));
    let (mut odometry, mut fixes, mut no_fixes) = (0, 0, 0);
    for m in BagReader::open(&out).unwrap().messages().unwrap() {
        let m = m.unwrap();
        match m.topic.as_str() {
            "/odometry" => {
                odometry += 1;
                let o: Odometry = cdr::decode(&m.data).unwrap();
                assert!(
                    odometry_support::numbers(&o).iter().all(|v| v.is_finite()),
                    "{o:?}"
                );
                let (pose, twist) = (&o.pose.covariance, &o.twist.covariance);
                assert!((0..6).all(|k| pose[7 * k] >= 0.0 && twist[7 * k] >= 0.0));
            }
            "/fix/filtered" => {
                let f: NavSatFix = cdr::decode(&m.data).unwrap();
                if f.status.status == NavSatStatus::STATUS_NO_FIX {
                    // No position, covariance unknown.
                    no_fixes += 1;
                    assert!(f.latitude.is_nan() && f.longitude.is_nan() && f.altitude.is_nan());
                    assert_eq!(
                        f.position_covariance_type,
                        NavSatFix::COVARIANCE_TYPE_UNKNOWN
                    );
                    continue;
                }
                fixes += 1;
                let mut values = vec![f.latitude, f.longitude, f.altitude];
                values.extend(f.position_covariance);
                assert!(values.iter().all(|v| v.is_finite()), "{f:?}");
                assert!((0..3).all(|k| f.position_covariance[4 * k] >= 0.0));
            }
            _ => {}
        }
    }
    assert_eq!((odometry, fixes), (rows.len(), rows.len()));
    // Every refused solution says NO_FIX at its stamp (and so do the epochs before the
    // start and after a reset, at theirs).
    assert!(no_fixes >= non_finite + negative, "{no_fixes} NO_FIX");
}
