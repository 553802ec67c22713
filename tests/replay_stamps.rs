//! `gnss_ins replay` keeps every input's stamp to the nanosecond (issue 16, item 3): the
//! golden fixture (stamped by the simulator in this decade, where `f64` seconds resolve
//! only 238 ns) restamped with IMU stamps at x.0025 s (every other one a nanosecond later) and GNSS epochs at
//! x.000000001 s, gives Odometry, NavSatFix and /tf at exactly an IMU stamp and
//! NoiseEstimates at exactly an epoch's; each NavSatFix names only constellations an
//! update used, and those before the start say NO_FIX at an epoch's stamp (issue 16,
//! item 4).
//!
//! And the simulator stamps in real time: a scenario at 400 Hz starting on an odd
//! nanosecond gives a bag of this decade whose GNSS week and time of week are its stamps'
//! GPS time, and whose replay gives one Odometry at exactly each IMU stamp from the start.

use std::collections::HashSet;
use std::path::Path;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::gnss::Constellation;
use adaptive_gnss_ins::ros::adapter::OutputFrames;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriter};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{
    GnssMeasurements, Imu, NavSatFix, NavSatStatus, NoiseEstimates, Odometry, TFMessage, Time,
};
use adaptive_gnss_ins::ros::outbound::service_of;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::{simulate, time_base, GNSS_TOPIC, IMU_TOPIC};

const NS_PER_S: u64 = 1_000_000_000;
/// 2020-01-01 00:00:00 UTC, in unix seconds: where this decade begins.
const SEC_2020: u64 = 1_577_836_800;
/// The GPS epoch 1980-01-06 00:00:00 in unix seconds, GPS − UTC since 2017 (s), and a GPS
/// week in ns: the facts a GNSS receiver's week and time of week rest on.
const GPS_EPOCH_UNIX_S: u64 = 315_964_800;
const GPS_MINUS_UTC_S: u64 = 18;
const WEEK_NS: u64 = 604_800 * NS_PER_S;

fn total_ns(t: &Time) -> u64 {
    u64::try_from(t.sec).unwrap() * NS_PER_S + u64::from(t.nanosec)
}

fn time_of(ns: u64) -> Time {
    Time {
        sec: i32::try_from(ns / NS_PER_S).unwrap(),
        nanosec: u32::try_from(ns % NS_PER_S).unwrap(),
    }
}

/// Copies the fixture's /imu and /gnss/measurements to `out`, each stamp (and log time)
/// moved by the odd nanoseconds of the module documentation; returns the IMU and the
/// epoch stamps written.
fn restamped_fixture(out: &Path) -> (HashSet<Time>, HashSet<Time>) {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixture_small.mcap");
    let mut writer = BagWriter::create(out).unwrap();
    writer.add_topic::<Imu>("/imu").unwrap();
    writer
        .add_topic::<GnssMeasurements>("/gnss/measurements")
        .unwrap();
    let (mut imu_stamps, mut epoch_stamps) = (HashSet::new(), HashSet::new());
    for message in BagReader::open(fixture).unwrap().messages().unwrap() {
        let message = message.unwrap();
        match message.topic.as_str() {
            "/imu" => {
                let mut imu: Imu = cdr::decode(&message.data).unwrap();
                let odd_ns = 2_500_000 + imu_stamps.len() as u64 % 2;
                let ns = total_ns(&imu.header.stamp) + odd_ns;
                assert!(ns >= SEC_2020 * NS_PER_S, "the fixture is of this decade");
                imu.header.stamp = time_of(ns);
                imu_stamps.insert(imu.header.stamp);
                writer.write("/imu", &imu, ns).unwrap();
            }
            "/gnss/measurements" => {
                let mut epoch: GnssMeasurements = cdr::decode(&message.data).unwrap();
                let ns = total_ns(&epoch.header.stamp) + 1;
                epoch.header.stamp = time_of(ns);
                epoch_stamps.insert(epoch.header.stamp);
                writer.write("/gnss/measurements", &epoch, ns).unwrap();
            }
            _ => {}
        }
    }
    writer.finish().unwrap();
    (imu_stamps, epoch_stamps)
}

/// Replays `bag` with the default parameters and /tf into the bag `out`.
fn replay_with_tf(bag: &Path, out: &Path) {
    let options = ReplayOptions {
        out_bag: Some(out),
        frames: OutputFrames {
            publish_tf: true,
            ..OutputFrames::default()
        },
        ..ReplayOptions::default()
    };
    replay(bag, &Config::default(), TruthSource::None, &options, |_| {}).unwrap();
}

#[test]
fn replay_outputs_carry_their_inputs_stamps_to_the_nanosecond() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("2025.mcap");
    let (imu_stamps, epoch_stamps) = restamped_fixture(&bag);
    let out = dir.path().join("out.mcap");
    replay_with_tf(&bag, &out);
    let mut counts = std::collections::HashMap::<String, usize>::new();
    // The NavSatFix service bits, and those of every constellation an update used.
    let (mut services, mut used_service) = (HashSet::new(), 0);
    for m in BagReader::open(&out).unwrap().messages().unwrap() {
        let m = m.unwrap();
        let (stamp, at) = match m.topic.as_str() {
            "/odometry" => (
                cdr::decode::<Odometry>(&m.data).unwrap().header.stamp,
                &imu_stamps,
            ),
            "/fix/filtered" => {
                let fix: NavSatFix = cdr::decode(&m.data).unwrap();
                if fix.status.status == NavSatStatus::STATUS_NO_FIX {
                    // While initializing: at an epoch's stamp.
                    (fix.header.stamp, &epoch_stamps)
                } else {
                    services.insert(fix.status.service);
                    (fix.header.stamp, &imu_stamps)
                }
            }
            "/tf" => {
                let tf: TFMessage = cdr::decode(&m.data).unwrap();
                (tf.transforms[0].header.stamp, &imu_stamps)
            }
            "/noise_estimates" => {
                let noise: NoiseEstimates = cdr::decode(&m.data).unwrap();
                let used = noise.satellites.iter().filter(|s| s.used);
                used_service |=
                    service_of(used.map(|s| Constellation::from_code(s.constellation).unwrap()));
                (noise.header.stamp, &epoch_stamps)
            }
            other => panic!("unexpected topic {other}"),
        };
        assert!(at.contains(&stamp), "{} at {stamp:?}", m.topic);
        *counts.entry(m.topic).or_default() += 1;
    }
    let count = |topic: &str| counts.get(topic).copied().unwrap_or(0);
    assert!(count("/odometry") > 1000, "{counts:?}");
    assert!(
        count("/fix/filtered") > count("/odometry"),
        "NO_FIX before the start"
    );
    assert_eq!(count("/tf"), count("/odometry"));
    assert!(count("/noise_estimates") > 20, "{counts:?}");
    // Every fix names only constellations the filter used (issue 16, item 4); those
    // before the first update that used one say SERVICE_UNKNOWN (0).
    assert!(
        services.contains(&used_service) && services.iter().all(|&s| s & !used_service == 0),
        "{services:?} against {used_service}"
    );
}

/// The fixture's scenario with a 400 Hz IMU (steps of x.0025 s) starting 1 ns after a
/// whole second.
fn odd_nanosecond_scenario() -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixture_small.yaml");
    let mut spec = ScenarioSpec::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap();
    spec.imu.rate_hz = 400.0;
    spec.gnss.start_gps_s = 10_800.000_000_001;
    Scenario::new(spec, 1).unwrap()
}

#[test]
fn a_simulated_bag_is_stamped_in_gps_time_and_replays_to_the_nanosecond() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("sim.mcap");
    let scenario = odd_nanosecond_scenario();
    simulate(&scenario, &bag).unwrap();
    let (mut imu_stamps, mut epochs) = (Vec::new(), 0);
    for m in BagReader::open(&bag).unwrap().messages().unwrap() {
        let m = m.unwrap();
        if m.topic == IMU_TOPIC {
            let stamp = cdr::decode::<Imu>(&m.data).unwrap().header.stamp;
            assert_eq!(m.log_time_ns, total_ns(&stamp), "log time of {stamp:?}");
            imu_stamps.push(stamp);
        } else if m.topic == GNSS_TOPIC {
            // The epoch's week and time of week are its stamp's instant in GPS time.
            let epoch: GnssMeasurements = cdr::decode(&m.data).unwrap();
            let since_gps_epoch_ns = total_ns(&epoch.header.stamp) + GPS_MINUS_UTC_S * NS_PER_S
                - GPS_EPOCH_UNIX_S * NS_PER_S;
            assert_eq!(
                u64::from(epoch.gps_week),
                since_gps_epoch_ns / WEEK_NS,
                "{:?}",
                epoch.header.stamp
            );
            assert_eq!(
                (epoch.gps_time_of_week_s * 1e9).round() as u64,
                since_gps_epoch_ns % WEEK_NS,
                "{:?}",
                epoch.header.stamp
            );
            epochs += 1;
        }
    }
    assert_eq!(epochs, 37);
    // In this decade, from the scenario's start, at x.0025 s and odd nanoseconds.
    let first = total_ns(&imu_stamps[0]);
    assert_eq!(
        i64::try_from(first).unwrap(),
        scenario.clock().start_utc_ns()
    );
    assert!(first >= SEC_2020 * NS_PER_S, "{:?}", imu_stamps[0]);
    assert_eq!(imu_stamps[1].nanosec % 10_000_000, 2_500_001);
    assert!(imu_stamps.iter().all(|t| t.nanosec % 2 == 1));
    let second_ns = i64::try_from(total_ns(&imu_stamps[1])).unwrap();
    assert_eq!(scenario.clock().scenario_time_of_utc_ns(second_ns), 0.0025);
    // What `simulate` says of it: 2025-10-02 02:59:51 UTC (week 2386 began on Sunday
    // 2025-09-28; the constellation's Thursday 00:00:09 GPST plus 3 h, less 18 s).
    let said = time_base(&scenario);
    assert!(
        said.contains(
            "1759373991.000000001 s since 1970, GPS week 2386 time of week 356409.000000001 s"
        ),
        "{said}"
    );

    let out = dir.path().join("out.mcap");
    replay_with_tf(&bag, &out);
    let odometry: Vec<Time> = BagReader::open(&out)
        .unwrap()
        .messages()
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.topic == "/odometry")
        .map(|m| cdr::decode::<Odometry>(&m.data).unwrap().header.stamp)
        .collect();
    // One Odometry at each IMU stamp from the first solution to the end, to the ns.
    let from = imu_stamps
        .iter()
        .position(|t| Some(t) == odometry.first())
        .expect("the first Odometry is at no IMU stamp");
    assert!(odometry.len() > 10_000, "{} Odometry", odometry.len());
    assert_eq!(odometry, imu_stamps[from..]);
}
