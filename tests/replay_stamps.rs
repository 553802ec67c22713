//! `gnss_ins replay` keeps every input's stamp to the nanosecond (issue 16, item 3): the
//! golden fixture restamped into this decade, where `f64` seconds resolve only 238 ns,
//! with IMU stamps at x.0025 s (every other one a nanosecond later) and GNSS epochs at
//! x.000000001 s, gives Odometry, NavSatFix and /tf at exactly an IMU stamp and
//! NoiseEstimates at exactly an epoch's; each NavSatFix names only constellations an
//! update used, and those before the start say NO_FIX at an epoch's stamp (issue 16,
//! item 4).

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
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};

const NS_PER_S: u64 = 1_000_000_000;
/// 2025-11-24, in unix seconds.
const SEC_2025: u64 = 1_764_000_000;

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
/// moved into this decade by `SEC_2025` s and the odd nanoseconds of the module
/// documentation; returns the IMU and the epoch stamps written.
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
                let ns = total_ns(&imu.header.stamp) + SEC_2025 * NS_PER_S + odd_ns;
                imu.header.stamp = time_of(ns);
                imu_stamps.insert(imu.header.stamp);
                writer.write("/imu", &imu, ns).unwrap();
            }
            "/gnss/measurements" => {
                let mut epoch: GnssMeasurements = cdr::decode(&message.data).unwrap();
                let ns = total_ns(&epoch.header.stamp) + SEC_2025 * NS_PER_S + 1;
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

#[test]
fn replay_outputs_carry_their_inputs_stamps_to_the_nanosecond() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("2025.mcap");
    let (imu_stamps, epoch_stamps) = restamped_fixture(&bag);
    let out = dir.path().join("out.mcap");
    let options = ReplayOptions {
        out_bag: Some(&out),
        frames: OutputFrames {
            publish_tf: true,
            ..OutputFrames::default()
        },
        ..ReplayOptions::default()
    };
    replay(
        &bag,
        &Config::default(),
        TruthSource::None,
        &options,
        |_| {},
    )
    .unwrap();
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
