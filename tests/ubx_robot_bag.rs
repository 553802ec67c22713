//! `gnss_ins convert --bag` (issue 13): the walk_0827 UBX log turned into robot bags as
//! the u-blox ROS 2 drivers would have recorded them — ublox_dgnss UBXRxmRawx/Sfrbx
//! messages, and ublox_gps's byte stream as UInt8MultiArray cut at random places and at
//! the logger's own reads — each with the walk's IMU on /imu/data. Converting each gives
//! exactly the GnssMeasurements (and IMU) of `convert --ubx --ephemeris as-received`,
//! and the adapter measures the receiver-to-host latency the time tag recorded.

mod ubx_robot_support;

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::gnss::ionosphere::IonosphereMode;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriter};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{Imu, UInt8MultiArray, UbxRxmRawx, UbxRxmSfrbx};
use adaptive_gnss_ins::ros::ubx_adapter::{TimeBase, DEFAULT_HOST_LATENCY_S};
use adaptive_gnss_ins::tools::convert::{
    convert, ConvertOptions, ConvertSummary, EphemerisMode, GnssSource, ImuInput, TruthInput,
};
use adaptive_gnss_ins::tools::convert_bag::{RobotBag, RobotBagTopics, UbxInput};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ubx_robot_support::{
    driver_messages, host_ns, stream_chunk, walk_imu_input, walk_log, walk_path, DriverMessage,
};

const GNSS_OUT: &str = "/gnss/measurements";
const IMU_OUT: &str = "/imu";

fn options(gnss: GnssSource, imu: Option<ImuInput>) -> ConvertOptions {
    ConvertOptions {
        gnss,
        imu,
        truth: TruthInput::None,
        leap_seconds: 18.0,
        ephemeris: EphemerisMode::AsReceived,
        ionosphere: IonosphereMode::IonoFree,
    }
}

/// `convert --ubx gnss_1730.ubx --ephemeris as-received` with the walk's IMU.
fn reference_bag(dir: &Path) -> (PathBuf, ConvertSummary) {
    let imu = walk_imu_input([0.0; 3]);
    let out = dir.join("reference.mcap");
    let summary = convert(
        &options(GnssSource::Ubx(walk_path("gnss_1730.ubx")), Some(imu)),
        &out,
    )
    .unwrap();
    (out, summary)
}

/// (log time, CDR payload) of every message on `topic`.
fn messages(bag: &Path, topic: &str) -> Vec<(u64, Vec<u8>)> {
    BagReader::open(bag)
        .unwrap()
        .messages()
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.topic == topic)
        .map(|m| (m.log_time_ns, m.data))
        .collect()
}

/// The reference's IMU messages as a robot records them on /imu/data: received 1 ms
/// after their stamp.
fn robot_imu(reference: &Path) -> Vec<(u64, Imu)> {
    messages(reference, IMU_OUT)
        .into_iter()
        .map(|(ns, data)| (ns + 1_000_000, cdr::decode::<Imu>(&data).unwrap()))
        .collect()
}

/// A message of a robot bag.
enum Robot {
    Rawx(UbxRxmRawx),
    Sfrbx(UbxRxmSfrbx),
    Stream(UInt8MultiArray),
    Imu(Box<Imu>),
}

/// Writes `items` (stably sorted by log time) as a robot bag.
fn write_robot_bag(path: &Path, mut items: Vec<(u64, Robot)>) {
    items.sort_by_key(|(ns, _)| *ns);
    let topics = RobotBagTopics::default();
    let mut bag = BagWriter::create(path).unwrap();
    bag.add_topic::<Imu>(&topics.imu).unwrap();
    let stream = items.iter().any(|(_, m)| matches!(m, Robot::Stream(_)));
    if stream {
        bag.add_topic::<UInt8MultiArray>(&topics.stream).unwrap();
    } else {
        bag.add_topic::<UbxRxmRawx>(&topics.rawx).unwrap();
        bag.add_topic::<UbxRxmSfrbx>(&topics.sfrbx).unwrap();
    }
    for (ns, item) in &items {
        match item {
            Robot::Rawx(m) => bag.write(&topics.rawx, m, *ns),
            Robot::Sfrbx(m) => bag.write(&topics.sfrbx, m, *ns),
            Robot::Stream(m) => bag.write(&topics.stream, m, *ns),
            Robot::Imu(m) => bag.write(&topics.imu, m.as_ref(), *ns),
        }
        .unwrap();
    }
    bag.finish().unwrap();
}

fn convert_robot_bag(bag: &Path, out: &Path) -> ConvertSummary {
    let source = GnssSource::Bag {
        bag: RobotBag {
            path: bag.to_path_buf(),
            topics: RobotBagTopics::default(),
        },
        time_base: TimeBase::Gnss,
        host_latency_s: DEFAULT_HOST_LATENCY_S,
    };
    convert(&options(source, None), out).unwrap()
}

/// The converted robot bag's GNSS and IMU messages equal the reference's, byte for byte
/// and at the same log times; the adapter's counts are as expected, and with
/// `real_arrivals` (messages received when the logger received their bytes) so is its
/// clock check.
fn check_against_reference(
    converted: &Path,
    summary: &ConvertSummary,
    reference: &Path,
    reference_summary: &ConvertSummary,
    input: UbxInput,
    real_arrivals: bool,
) {
    let expected = messages(reference, GNSS_OUT);
    let got = messages(converted, GNSS_OUT);
    assert_eq!(got.len(), expected.len());
    assert!(expected.len() > 300, "{} epochs", expected.len());
    for (k, (g, e)) in got.iter().zip(&expected).enumerate() {
        assert!(g == e, "GnssMeasurements #{k} differs");
    }
    assert!(messages(converted, IMU_OUT) == messages(reference, IMU_OUT));
    assert_eq!(summary.gnss_epochs, reference_summary.gnss_epochs);
    assert_eq!(summary.satellites, reference_summary.satellites);
    assert_eq!(summary.empty_epochs, reference_summary.empty_epochs);
    let robot = summary.robot_bag.as_ref().unwrap();
    println!("{input:?}: {:?}\n{:?}", robot.counts, robot.clock);
    assert_eq!(robot.input, input);
    let c = &robot.counts;
    assert_eq!(c.rawx, 536);
    assert_eq!(c.sfrbx, 2328);
    assert_eq!(c.published as usize, expected.len());
    assert_eq!(
        (
            c.malformed,
            c.undecodable,
            c.duplicate_epochs,
            c.time_backwards
        ),
        (0, 0, 0, 0)
    );
    assert_eq!((c.frames.bad_checksum, c.frames.truncated), (0, 0));
    assert_eq!(c.nav.decoder.rejected, 0);
    assert_eq!(robot.receiver_leap_seconds, Some(18));
    let (offset_s, jitter_s) = robot.clock.receiver_to_host_s.unwrap();
    if !real_arrivals {
        // Chunks cut after the reads arrive later than the reads did.
        assert!(offset_s > 0.03, "{offset_s}");
        return;
    }
    // The time tag recorded the host receiving each RAWX 14..60 ms after its epoch
    // (median 36 ms); the IMU, received 1 ms after its stamps, agrees with that.
    assert!((0.02..0.05).contains(&offset_s), "{offset_s}");
    assert!(jitter_s < 0.015, "{jitter_s}");
    let skew_s = robot.clock.imu_gnss_skew_s.unwrap();
    assert!(
        skew_s.abs() < 0.01 && !robot.clock.skew_exceeded,
        "{skew_s}"
    );
    assert_eq!(robot.receiver_leap_seconds, Some(18));
}

#[test]
fn driver_messages_convert_to_the_as_received_measurements() {
    let dir = tempfile::tempdir().unwrap();
    let (reference, reference_summary) = reference_bag(dir.path());
    let (log, tag) = walk_log();
    let mut items: Vec<(u64, Robot)> = driver_messages(&log, &tag)
        .into_iter()
        .map(|(ns, m)| match m {
            DriverMessage::Rawx(m) => (ns, Robot::Rawx(m)),
            DriverMessage::Sfrbx(m) => (ns, Robot::Sfrbx(m)),
        })
        .collect();
    items.extend(
        robot_imu(&reference)
            .into_iter()
            .map(|(ns, m)| (ns, Robot::Imu(Box::new(m)))),
    );
    let robot = dir.path().join("dgnss.mcap");
    write_robot_bag(&robot, items);
    let out = dir.path().join("dgnss_converted.mcap");
    let summary = convert_robot_bag(&robot, &out);
    // The command line gives the same bag.
    let cli_out = dir.path().join("dgnss_cli.mcap");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .args(["convert", "--bag"])
        .arg(&robot)
        .args(["--rawx-topic", "/ubx_rxm_rawx", "--imu-topic", "/imu/data"])
        .args(["--time-base", "gnss", "--out"])
        .arg(&cli_out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("UBXRxmRawx/UBXRxmSfrbx messages"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(&cli_out).unwrap(),
        std::fs::read(&out).unwrap()
    );
    check_against_reference(
        &out,
        &summary,
        &reference,
        &reference_summary,
        UbxInput::DriverMessages,
        true,
    );
}

/// The log as UInt8MultiArray chunks ending at `ends` (exclusive offsets, increasing,
/// the last = the log's length), each received when its last byte was.
fn stream_items(
    log: &[u8],
    tag: &adaptive_gnss_ins::tools::time_tag::TimeTag,
    ends: &[usize],
) -> Vec<(u64, Robot)> {
    let mut start = 0;
    ends.iter()
        .map(|&end| {
            let chunk = stream_chunk(&log[start..end]);
            start = end;
            (host_ns(tag, end), Robot::Stream(chunk))
        })
        .collect()
}

#[test]
fn a_byte_stream_cut_anywhere_converts_to_the_as_received_measurements() {
    let dir = tempfile::tempdir().unwrap();
    let (reference, reference_summary) = reference_bag(dir.path());
    let (log, tag) = walk_log();
    let imu = robot_imu(&reference);
    // Random cuts (frames split anywhere, up to ~1.5 kB per read), then the logger's own
    // reads as its time tag recorded them.
    let mut rng = ChaCha8Rng::seed_from_u64(0x0B_0827);
    let mut random_ends = Vec::new();
    let mut end = 0;
    while end < log.len() {
        end = (end + rng.random_range(1..1_500usize)).min(log.len());
        random_ends.push(end);
    }
    let mut tag_ends: Vec<usize> = tag.records.iter().map(|r| r.byte_offset as usize).collect();
    tag_ends.dedup();
    assert_eq!(tag_ends.last(), Some(&log.len()));
    for (name, ends) in [("random", random_ends), ("tag_reads", tag_ends)] {
        let mut items = stream_items(&log, &tag, &ends);
        items.extend(
            imu.iter()
                .map(|(ns, m)| (*ns, Robot::Imu(Box::new(m.clone())))),
        );
        let robot = dir.path().join(format!("stream_{name}.mcap"));
        write_robot_bag(&robot, items);
        let out = dir.path().join(format!("stream_{name}_converted.mcap"));
        let summary = convert_robot_bag(&robot, &out);
        check_against_reference(
            &out,
            &summary,
            &reference,
            &reference_summary,
            UbxInput::ByteStream,
            name == "tag_reads",
        );
        let frames = summary.robot_bag.unwrap().counts.frames;
        assert_eq!(frames.frames, 3400, "{name}: every frame of the log");
    }
}
