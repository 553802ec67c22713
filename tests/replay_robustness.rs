//! `gnss_ins replay` on damaged or unexpected bags: a truncated bag and a corrupt chunk
//! give partial results and name the damage; unknown topics, topics of an unexpected type
//! and messages that do not decode are counted and skipped; a bag with no IMU fails with
//! a clear message. The binary exits non-zero only when nothing usable is left.
//!
//! The bags are made from the golden fixture (tests/data/fixture_small.mcap, 36 s).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriteOptions, BagWriter};
use adaptive_gnss_ins::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry, RosMessage,
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
