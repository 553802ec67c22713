//! Independent proof that the bags this crate writes are valid ROS 2 MCAP bags: the
//! Python package `rosbags` (pinned in tools/requirements-test-peers.txt) opens one,
//! deserializes every message with the definitions stored in the bag, and its summary
//! (tools/check_bag_with_rosbags.py) must match what was written. The stored definitions
//! are also checked against rosbags' ROS 2 Jazzy types and against msg/*.msg.
//!
//! The same bag is checked with uncompressed and with zstd-compressed chunks.
//!
//! Needs the venv made by `scripts/setup_test_peers.sh` (CI runs it first).

mod bag_support;
mod venv_support;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use adaptive_gnss_ins::ros::bag::{
    BagError, BagReader, BagWriteOptions, ChunkCompression, Durability, OfferedQos, Reliability,
};
use adaptive_gnss_ins::ros::msg::{
    Clock, DiagnosticArray, DiagnosticStatus, GnssMeasurements, Imu, KeyValue, NavSatFix,
    NoiseEstimates, Odometry, RosMessage, TFMessage, Transform, TransformStamped,
    TwistWithCovarianceStamped,
};
use bag_support::{fix, gnss, header, imu, noise, odometry, stamp, Recorder, START_NS};
use serde::Serialize;
use serde_json::{json, Value};

/// What one topic of the bag must look like in the rosbags summary.
struct ExpectedTopic {
    type_name: &'static str,
    qos: OfferedQos,
    count: u64,
    first: (u64, Value),
    last: (u64, Value),
}

/// Writes messages and remembers, per topic, what rosbags must report.
struct Bag {
    recorder: Recorder,
    topics: BTreeMap<String, ExpectedTopic>,
}

impl Bag {
    fn add<T: RosMessage>(&mut self, topic: &str, qos: OfferedQos) {
        self.recorder
            .writer
            .add_topic_with_qos::<T>(topic, &qos)
            .unwrap();
        self.topics.insert(
            topic.to_string(),
            ExpectedTopic {
                type_name: T::TYPE_NAME,
                qos,
                count: 0,
                first: (0, Value::Null),
                last: (0, Value::Null),
            },
        );
    }

    fn write<T: RosMessage + Serialize>(&mut self, topic: &str, message: &T, t_ns: u64) {
        self.recorder.write(topic, message, t_ns);
        let expected = self.topics.get_mut(topic).unwrap();
        let value = serde_json::to_value(message).unwrap();
        if expected.count == 0 {
            expected.first = (t_ns, value.clone());
        }
        expected.last = (t_ns, value);
        expected.count += 1;
    }
}

fn diagnostics(t_ns: u64) -> DiagnosticArray {
    DiagnosticArray {
        header: header(t_ns, ""),
        status: vec![DiagnosticStatus {
            level: DiagnosticStatus::WARN,
            name: "gnss_ins: noise".to_string(),
            message: "few satellites".to_string(),
            hardware_id: "ublox-f9p".to_string(),
            values: vec![KeyValue {
                key: "satellites_used".to_string(),
                value: "4".to_string(),
            }],
        }],
    }
}

fn velocity(t_ns: u64) -> TwistWithCovarianceStamped {
    let mut twist = TwistWithCovarianceStamped {
        header: header(t_ns, "gnss_antenna"),
        ..TwistWithCovarianceStamped::default()
    };
    twist.twist.twist.linear.x = 1.5;
    twist.twist.covariance[7] = 0.04;
    twist
}

fn tf_static(t_ns: u64) -> TFMessage {
    let mut transform = Transform::default();
    transform.translation.z = 0.3;
    transform.rotation.z = std::f64::consts::FRAC_1_SQRT_2;
    transform.rotation.w = std::f64::consts::FRAC_1_SQRT_2;
    TFMessage {
        transforms: vec![TransformStamped {
            header: header(t_ns, "base_link"),
            child_frame_id: "imu_link".to_string(),
            transform,
        }],
    }
}

/// Writes a bag holding every message type of the crate.
fn write_bag(path: &Path, compression: ChunkCompression) -> BTreeMap<String, ExpectedTopic> {
    let recorder = Recorder::create(
        path,
        BagWriteOptions {
            chunk_size_bytes: 8192,
            compression,
        },
    );
    let mut bag = Bag {
        recorder,
        topics: BTreeMap::new(),
    };
    let latched = OfferedQos {
        reliability: Reliability::Reliable,
        durability: Durability::TransientLocal,
        depth: 1,
    };
    let best_effort = OfferedQos {
        reliability: Reliability::BestEffort,
        durability: Durability::Volatile,
        depth: 5,
    };
    bag.add::<TFMessage>("/tf_static", latched);
    bag.add::<Imu>("/imu/data", best_effort);
    bag.add::<GnssMeasurements>("/gnss/measurements", OfferedQos::default());
    bag.add::<NavSatFix>("/gnss/fix", OfferedQos::default());
    bag.add::<TwistWithCovarianceStamped>("/gnss/velocity", OfferedQos::default());
    bag.add::<Odometry>("/odometry/filtered", OfferedQos::default());
    bag.add::<NoiseEstimates>("/diagnostics/noise", OfferedQos::default());
    bag.add::<DiagnosticArray>("/diagnostics", OfferedQos::default());
    bag.add::<Clock>("/clock", best_effort);

    bag.write("/tf_static", &tf_static(START_NS), START_NS);
    for k in 0..250_u64 {
        let t_ns = START_NS + k * 10_000_000;
        bag.write("/imu/data", &imu(k, t_ns), t_ns);
        if k % 100 == 0 {
            let epoch = k / 100;
            bag.write("/gnss/measurements", &gnss(epoch, t_ns), t_ns);
            bag.write("/gnss/fix", &fix(epoch, t_ns), t_ns);
            bag.write("/gnss/velocity", &velocity(t_ns), t_ns);
            bag.write("/diagnostics/noise", &noise(epoch, t_ns), t_ns);
            bag.write("/diagnostics", &diagnostics(t_ns), t_ns);
        }
        if k % 10 == 5 {
            bag.write("/odometry/filtered", &odometry(k / 10, t_ns), t_ns);
            bag.write("/clock", &Clock { clock: stamp(t_ns) }, t_ns);
        }
    }
    bag.recorder.finish().unwrap();
    bag.topics
}

/// Runs tools/check_bag_with_rosbags.py on `bag` and parses its JSON summary.
fn rosbags_summary(bag: &Path) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/check_bag_with_rosbags.py");
    let output = Command::new(venv_support::python())
        .arg(&script)
        .arg(bag)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "rosbags could not read {}: {}",
        bag.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn rosbags_reads_every_message_with_the_definitions_stored_in_the_bag() {
    let dir = tempfile::tempdir().unwrap();
    for compression in [ChunkCompression::None, ChunkCompression::Zstd] {
        let path = dir.path().join(format!("interop_{compression:?}.mcap"));
        let expected = write_bag(&path, compression);
        check_summary(&rosbags_summary(&path), &expected);
    }
}

/// The rosbags summary of a bag written by [`write_bag`] against what was written.
fn check_summary(summary: &Value, expected: &BTreeMap<String, ExpectedTopic>) {
    assert_eq!(summary["reader"], "rosbags 0.11.9");
    let total: u64 = expected.values().map(|topic| topic.count).sum();
    assert_eq!(summary["message_count"], total);
    assert_eq!(summary["message_count_in_index"], total);
    assert_eq!(summary["start_time_ns"], START_NS);
    // rosbags reports the end as one past the last log time.
    assert_eq!(summary["end_time_ns"], START_NS + 249 * 10_000_000 + 1);
    assert_eq!(summary["log_time_order"], true);

    let topics = summary["topics"].as_object().unwrap();
    assert_eq!(
        topics.keys().collect::<Vec<_>>(),
        expected.keys().collect::<Vec<_>>()
    );
    for (name, want) in expected {
        let got = &topics[name];
        assert_eq!(got["type"], want.type_name, "{name}");
        assert_eq!(got["encoding"], "cdr", "{name}");
        assert_eq!(got["count"], want.count, "{name}");
        assert_eq!(got["count_in_index"], want.count, "{name}");
        assert_eq!(got["first_log_time_ns"], want.first.0, "{name}");
        assert_eq!(got["last_log_time_ns"], want.last.0, "{name}");
        assert_eq!(got["first"], want.first.1, "{name}: first message");
        assert_eq!(got["last"], want.last.1, "{name}: last message");
        let reliability = match want.qos.reliability {
            Reliability::Reliable => "reliable",
            Reliability::BestEffort => "best_effort",
        };
        let durability = match want.qos.durability {
            Durability::Volatile => "volatile",
            Durability::TransientLocal => "transient_local",
        };
        assert_eq!(
            got["qos"],
            json!([{
                "history": "keep_last",
                "depth": want.qos.depth,
                "reliability": reliability,
                "durability": durability,
            }]),
            "{name}"
        );
    }

    // Every type stored in the bag's definitions, nested ones included, matches its
    // independent reference.
    let definitions = summary["definitions"].as_object().unwrap();
    for (type_name, verdict) in definitions {
        let reference = if type_name.starts_with("adaptive_gnss_ins/") {
            "matches msg/"
        } else {
            "matches jazzy"
        };
        assert_eq!(verdict, reference, "{type_name}");
    }
    for type_name in [
        "builtin_interfaces/msg/Time",
        "std_msgs/msg/Header",
        "geometry_msgs/msg/Point",
        "geometry_msgs/msg/Vector3",
        "geometry_msgs/msg/Quaternion",
        "geometry_msgs/msg/Pose",
        "geometry_msgs/msg/PoseWithCovariance",
        "geometry_msgs/msg/Twist",
        "geometry_msgs/msg/TwistWithCovariance",
        "geometry_msgs/msg/TwistWithCovarianceStamped",
        "geometry_msgs/msg/Transform",
        "geometry_msgs/msg/TransformStamped",
        "sensor_msgs/msg/Imu",
        "sensor_msgs/msg/NavSatStatus",
        "sensor_msgs/msg/NavSatFix",
        "nav_msgs/msg/Odometry",
        "diagnostic_msgs/msg/KeyValue",
        "diagnostic_msgs/msg/DiagnosticStatus",
        "diagnostic_msgs/msg/DiagnosticArray",
        "tf2_msgs/msg/TFMessage",
        "rosgraph_msgs/msg/Clock",
        "adaptive_gnss_ins/msg/SatelliteMeasurement",
        "adaptive_gnss_ins/msg/GnssMeasurements",
        "adaptive_gnss_ins/msg/SatelliteNoise",
        "adaptive_gnss_ins/msg/NoiseEstimates",
    ] {
        assert!(
            definitions.contains_key(type_name),
            "{type_name} not checked"
        );
    }
}

/// A rosbag2 sqlite3 bag, as `ros2 bag record` wrote by default before Iron, written by
/// rosbags: refused as a bag directory and as a `.db3` file, with how to convert it.
#[test]
fn a_sqlite3_bag_is_refused_with_how_to_convert_it() {
    let dir = tempfile::tempdir().unwrap();
    let bag_dir = dir.path().join("old_bag");
    let script = "import sys\n\
        from rosbags.rosbag2 import Writer, StoragePlugin\n\
        from rosbags.typesys import Stores, get_typestore\n\
        store = get_typestore(Stores.ROS2_JAZZY)\n\
        Clock = store.types['rosgraph_msgs/msg/Clock']\n\
        Time = store.types['builtin_interfaces/msg/Time']\n\
        with Writer(sys.argv[1], version=9, storage_plugin=StoragePlugin.SQLITE3) as w:\n\
        \x20   c = w.add_connection('/clock', Clock.__msgtype__, typestore=store)\n\
        \x20   w.write(c, 1, store.serialize_cdr(Clock(clock=Time(sec=0, nanosec=1)), Clock.__msgtype__))\n";
    let status = Command::new(venv_support::python())
        .args(["-c", script])
        .arg(&bag_dir)
        .status()
        .unwrap();
    assert!(status.success(), "rosbags could not write the sqlite3 bag");
    let db3 = std::fs::read_dir(&bag_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "db3"))
        .expect("rosbags wrote a .db3 file");
    for path in [&bag_dir, &db3] {
        let error = BagReader::open(path).err().expect("a .db3 bag is refused");
        assert!(matches!(error, BagError::Sqlite3 { .. }), "{error}");
        assert!(error.to_string().contains("ros2 bag convert"), "{error}");
    }
}
