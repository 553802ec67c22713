//! `gnss_ins replay` writes the `/tf` the node publishes, in each `tf_mode` (issue 16,
//! item 2), read from the same parameter files as the node: a bag of the simulated static
//! receiver with a stand-in base controller's `odom → base_link` on `/tf` (the stream
//! node_tf sends the node over DDS) replayed by the `gnss_ins` binary. `map_to_odom`
//! chained with the controller is the Odometry pose (node_tf's assertion), whether the
//! controller's transforms were logged ahead of the IMU or at their stamps (then the
//! newest is held, as the node does); `map_to_base_link` is the Odometry pose itself;
//! `none` and `publish_tf: false` write no `/tf`; the Odometry is the same in every mode.

mod odometry_support;
mod tf_support;

use std::path::Path;
use std::process::Command;

use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::ros::msg::{Odometry, TFMessage, TransformStamped};
use odometry_support::{decoded, largest_difference_of_runs};
use tf_support::{
    assert_map_to_base_link_is_the_odometry, chain, drift, map_to_odom_by_stamp, nanos,
    static_scenario, write_controller_bag, write_node_parameters, Chain, CONTROLLER_PERIOD_NS,
    PRESET, TOLERANCE,
};

/// Scenario seconds written, as node_tf streams them.
const STREAM_S: f64 = 20.0;
/// How far node_tf's controller runs ahead of the IMU (there in scenario time, here in
/// log time): every Odometry stamp then lies between two controller stamps already read.
const CONTROLLER_LEAD_NS: i64 = 200_000_000;

/// What one replay wrote and said.
struct Replayed {
    odometry: Vec<Odometry>,
    transforms: Vec<TransformStamped>,
    /// Whether the output bag has a `/tf` topic at all.
    tf_topic: bool,
    stderr: String,
}

/// `gnss_ins replay BAG --params params/defaults.yaml --params NODE --out OUT` with NODE a
/// launch-style `/**` file holding the node's datum and heading (as node_tf starts the
/// node) and `node_parameters`.
fn replay(bag: &Path, node_parameters: &str) -> Replayed {
    let dir = tempfile::tempdir().unwrap();
    let node_file = dir.path().join("node.yaml");
    write_node_parameters(&node_file, &static_scenario(), node_parameters);
    let out = dir.path().join("out.mcap");
    let run = Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .arg("replay")
        .arg(bag)
        .arg("--params")
        .arg(PRESET)
        .arg("--params")
        .arg(&node_file)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "replay failed: {stderr}");
    let tf_topic = BagReader::open(&out)
        .unwrap()
        .topics()
        .iter()
        .any(|t| t.topic == "/tf");
    Replayed {
        odometry: decoded::<Odometry>(&out, "/odometry"),
        transforms: decoded::<TFMessage>(&out, "/tf")
            .into_iter()
            .flat_map(|m| m.transforms)
            .collect(),
        tf_topic,
        stderr,
    }
}

fn controller_messages(bag: &Path) -> u64 {
    let reader = BagReader::open(bag).unwrap();
    reader
        .topics()
        .iter()
        .find(|t| t.topic == "/tf")
        .unwrap()
        .message_count
}

const MAP_TO_ODOM: &str = "    publish_tf: true\n    tf_mode: map_to_odom\n";

/// `map → odom` chained with `odom_base` at each Odometry stamp is the Odometry pose, for
/// every Odometry, and the replay counted every controller transform and no missing one.
fn assert_map_to_odom_chains_to_the_odometry(
    bag: &Path,
    odom_base: impl Fn(i64) -> nalgebra::Isometry3<f64>,
) -> Replayed {
    let replayed = replay(bag, MAP_TO_ODOM);
    let map_to_odom = map_to_odom_by_stamp(&replayed.transforms);
    let odometry = &replayed.odometry;
    // One Odometry per IMU sample from the initialization at 1 s: about 1900.
    assert!(odometry.len() > 1500, "{} Odometry", odometry.len());
    let Chain {
        matched,
        worst_m,
        worst_rad,
    } = chain(odometry, &map_to_odom, odom_base);
    eprintln!(
        "{} Odometry, {} map -> odom, {matched} matched; largest chain error {worst_m:.3e} m, \
         {worst_rad:.3e} rad",
        odometry.len(),
        map_to_odom.len()
    );
    assert_eq!(map_to_odom.len(), odometry.len(), "one map -> odom each");
    assert_eq!(matched, odometry.len());
    assert!(
        worst_m < TOLERANCE && worst_rad < TOLERANCE,
        "map -> odom -> base_link differs from the Odometry by {worst_m} m, {worst_rad} rad"
    );
    // The drift moved odom away from map: not the identity.
    let last = &map_to_odom[&nanos(&odometry.last().unwrap().header.stamp)];
    let offset = &last.transform.translation;
    assert!(offset.x.hypot(offset.y) > 5.0, "map -> odom {offset:?}");
    let counts = format!(
        "map -> odom: {} odom -> base transforms taken from /tf (odom_tf_received), 0 \
         unusable (odom_tf_unusable); 0 Odometry messages without a map -> odom \
         (map_to_odom_missing)",
        controller_messages(bag)
    );
    assert!(replayed.stderr.contains(&counts), "{}", replayed.stderr);
    replayed
}

#[test]
fn map_to_odom_chained_with_the_bags_controller_is_the_odometry_in_every_mode() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("controller.mcap");
    let first_imu_ns = write_controller_bag(&bag, &static_scenario(), STREAM_S, CONTROLLER_LEAD_NS);
    let to_odom = assert_map_to_odom_chains_to_the_odometry(&bag, |ns| drift(ns, first_imu_ns));

    let to_base = replay(&bag, "    publish_tf: true\n");
    assert_map_to_base_link_is_the_odometry(&to_base.odometry, &to_base.transforms);
    assert!(
        to_base
            .stderr
            .contains("messages on a topic this run does not use: /tf (tf2_msgs/msg/TFMessage)"),
        "the node does not subscribe /tf in this mode: {}",
        to_base.stderr
    );

    let none = replay(&bag, "    publish_tf: true\n    tf_mode: none\n");
    let off = replay(&bag, "    publish_tf: false\n    tf_mode: map_to_odom\n");
    let default = replay(&bag, "");
    for (what, r) in [
        ("none", &none),
        ("publish_tf false", &off),
        ("default", &default),
    ] {
        assert!(!r.tf_topic, "{what}: a /tf topic in the output bag");
        assert!(!r.stderr.contains("map -> odom:"), "{what}: {}", r.stderr);
    }
    // The TF does not touch the filter: the same Odometry in every mode.
    for (what, r) in [
        ("map_to_base_link", &to_base),
        ("none", &none),
        ("publish_tf false", &off),
    ] {
        let worst = largest_difference_of_runs(&to_odom.odometry, &r.odometry, what);
        assert_eq!(worst, 0.0, "{what}: Odometry differs from map_to_odom's");
    }
}

/// A recording of a live robot logs each controller transform at its stamp: at an IMU
/// sample between two of them only the older was heard, and the node (so the replay) holds
/// it rather than waiting; at a sample on a controller stamp that one is used.
#[test]
fn map_to_odom_of_a_live_recording_holds_the_newest_controller_transform() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("live.mcap");
    let first_imu_ns = write_controller_bag(&bag, &static_scenario(), STREAM_S, 0);
    assert_map_to_odom_chains_to_the_odometry(&bag, |ns| {
        let held_ns = ns - (ns - first_imu_ns).rem_euclid(CONTROLLER_PERIOD_NS);
        drift(held_ns, first_imu_ns)
    });
}
