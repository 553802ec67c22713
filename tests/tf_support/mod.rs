//! The TF checks shared by the node's DDS test (node_tf) and replay's (replay_tf): a
//! stand-in base controller's drifting `odom → base_link`, and what the published `/tf`
//! must be next to the Odometry in each `tf_mode`.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::Path;

use adaptive_gnss_ins::ros::bag::BagWriter;
use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::{
    GnssMeasurements, Header, Imu, Odometry, Quaternion, TFMessage, Time, TransformStamped, Vector3,
};
use adaptive_gnss_ins::ros::outbound;
use adaptive_gnss_ins::sim::{Scenario, SimEvent};
use adaptive_gnss_ins::tools::replay::TF_TOPIC;
use adaptive_gnss_ins::tools::simulate::{GNSS_TOPIC, IMU_TOPIC};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// The preset the TF tests run the filter with (as static_node_support starts the node).
pub const PRESET: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/params/defaults.yaml");

/// The base controller's period: 50 Hz.
pub const CONTROLLER_PERIOD_NS: i64 = 20_000_000;
/// Choice of tolerance: the adapter interpolates between two controller stamps exactly as
/// the drift moves (linear translation, constant yaw rate: slerp is exact), and CDR
/// carries f64 unchanged, so what is left is the rounding of products of 10 m-scale
/// poses (~1e-14 m). 1e-12 m and rad catch a transform held one controller period
/// (0.5 m/s × 20 ms = 1 cm), a wrong composition order, and an interpolated rotation
/// left unnormalized (1.1e-9 m, measured by node_tf before the adapter renormalized it).
pub const TOLERANCE: f64 = 1e-12;

pub fn nanos(t: &Time) -> i64 {
    i64::from(t.sec) * 1_000_000_000 + i64::from(t.nanosec)
}

pub fn time(ns: i64) -> Time {
    Time {
        sec: ns.div_euclid(1_000_000_000) as i32,
        nanosec: ns.rem_euclid(1_000_000_000) as u32,
    }
}

/// The wheel odometry's `odom → base_link` at `ns`: drifting 0.5 m/s east, 0.1 m/s north
/// and 0.05 rad/s of yaw from `start_ns`.
pub fn drift(ns: i64, start_ns: i64) -> Isometry3<f64> {
    let t_s = (ns - start_ns) as f64 * 1e-9;
    Isometry3::from_parts(
        Translation3::new(0.5 * t_s, 0.1 * t_s, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 0.05 * t_s),
    )
}

/// The controller's `/tf` message at `ns`: `odom → base_link` at `pose`.
pub fn controller_tf(ns: i64, pose: &Isometry3<f64>) -> TFMessage {
    let header = Header {
        stamp: time(ns),
        frame_id: "odom".to_owned(),
    };
    TFMessage {
        transforms: vec![outbound::transform_stamped(header, "base_link", pose)],
    }
}

pub fn isometry(t: &Vector3, q: &Quaternion) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

pub fn transform_of(t: &TransformStamped) -> Isometry3<f64> {
    isometry(&t.transform.translation, &t.transform.rotation)
}

pub fn odometry_pose(o: &Odometry) -> Isometry3<f64> {
    let p = &o.pose.pose.position;
    isometry(
        &Vector3 {
            x: p.x,
            y: p.y,
            z: p.z,
        },
        &o.pose.pose.orientation,
    )
}

/// The node's `map → odom` transforms by stamp, after checking that `base_link` keeps one
/// parent (the controller's `odom`) and that everything else on `/tf` is `map → odom`.
pub fn map_to_odom_by_stamp(transforms: &[TransformStamped]) -> HashMap<i64, &TransformStamped> {
    for t in transforms {
        if t.child_frame_id == "base_link" {
            assert_eq!(
                t.header.frame_id, "odom",
                "a second parent of base_link: {t:?}"
            );
        } else {
            assert_eq!(
                (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
                ("map", "odom"),
                "{t:?}"
            );
        }
    }
    transforms
        .iter()
        .filter(|t| t.child_frame_id == "odom")
        .map(|t| (nanos(&t.header.stamp), t))
        .collect()
}

/// How `map → odom` chained with the controller's `odom → base_link` compares with the
/// Odometry poses.
#[derive(Debug, Clone, Copy)]
pub struct Chain {
    /// Odometry messages with a `map → odom` at their stamp.
    pub matched: usize,
    /// Largest translation (m) and rotation (rad) between the chain and the Odometry.
    pub worst_m: f64,
    pub worst_rad: f64,
}

/// Chains each Odometry's `map → odom` (by stamp) with `odom_base(stamp)`, the
/// controller's `odom → base_link` there, and measures the distance to the Odometry pose;
/// asserts that every Odometry keeps its REP-105 frames.
pub fn chain(
    odometry: &[Odometry],
    map_to_odom: &HashMap<i64, &TransformStamped>,
    odom_base: impl Fn(i64) -> Isometry3<f64>,
) -> Chain {
    let mut c = Chain {
        matched: 0,
        worst_m: 0.0,
        worst_rad: 0.0,
    };
    for o in odometry {
        assert_eq!(
            (o.header.frame_id.as_str(), o.child_frame_id.as_str()),
            ("map", "base_link"),
            "the Odometry keeps its REP-105 meaning"
        );
        let ns = nanos(&o.header.stamp);
        let Some(t) = map_to_odom.get(&ns) else {
            continue;
        };
        let chained = transform_of(t) * odom_base(ns);
        let d = chained.inverse() * odometry_pose(o);
        c.worst_m = c.worst_m.max(d.translation.vector.norm());
        c.worst_rad = c.worst_rad.max(d.rotation.angle());
        c.matched += 1;
    }
    c
}

/// `map_to_base_link`: one `map → base_link` per Odometry, at its stamp, equal to its pose
/// (the same numbers: CDR carries f64 unchanged), and no other transform.
pub fn assert_map_to_base_link_is_the_odometry(
    odometry: &[Odometry],
    transforms: &[TransformStamped],
) {
    assert_eq!(
        transforms.len(),
        odometry.len(),
        "one transform per Odometry"
    );
    for (o, t) in odometry.iter().zip(transforms) {
        assert_eq!(t.header, o.header, "the Odometry's stamp and parent frame");
        assert_eq!(t.child_frame_id, o.child_frame_id);
        let p = &o.pose.pose.position;
        let v = &t.transform.translation;
        assert_eq!([v.x, v.y, v.z], [p.x, p.y, p.z]);
        assert_eq!(t.transform.rotation, o.pose.pose.orientation);
    }
}

/// Writes the first `stream_s` seconds of `scenario` (its IMU samples and GNSS epochs, as
/// node_tf streams them) into a bag with a base controller's `/tf` at 50 Hz drifting from
/// the first IMU stamp, each transform logged `lead_ns` before its stamp (0: at its
/// stamp, as a recording of a live robot has it). Returns the first IMU stamp (ns).
pub fn write_controller_bag(path: &Path, scenario: &Scenario, stream_s: f64, lead_ns: i64) -> i64 {
    let mut bag = BagWriter::create(path).unwrap();
    bag.add_topic::<Imu>(IMU_TOPIC).unwrap();
    bag.add_topic::<GnssMeasurements>(GNSS_TOPIC).unwrap();
    bag.add_topic::<TFMessage>(TF_TOPIC).unwrap();
    let mut first_imu_ns = None;
    let mut next_tf_ns = 0;
    for event in scenario.events() {
        let event = event.unwrap();
        let t_s = event.t_s();
        if t_s > stream_s {
            break;
        }
        let stamp = seconds_to_time(t_s).unwrap();
        let ns = nanos(&stamp);
        let log_ns = u64::try_from(ns).unwrap();
        match event {
            SimEvent::Imu(s) => {
                let start_ns = *first_imu_ns.get_or_insert_with(|| {
                    next_tf_ns = ns;
                    ns
                });
                // The controller's transforms due by now, in log-time order before the sample.
                while next_tf_ns <= ns + lead_ns {
                    let tf = controller_tf(next_tf_ns, &drift(next_tf_ns, start_ns));
                    bag.write(TF_TOPIC, &tf, log_ns).unwrap();
                    next_tf_ns += CONTROLLER_PERIOD_NS;
                }
                let imu = outbound::imu(&s, stamp, "imu_link");
                bag.write(IMU_TOPIC, &imu, log_ns).unwrap();
            }
            SimEvent::Gnss { epoch, .. } => {
                let msg = outbound::gnss_measurements(&epoch, 0, stamp, "gnss");
                bag.write(GNSS_TOPIC, &msg, log_ns).unwrap();
            }
            _ => {}
        }
    }
    bag.finish().unwrap();
    first_imu_ns.unwrap()
}

/// The static receiver of node_tf (static_node_support).
pub fn static_scenario() -> Scenario {
    Scenario::builtin("static", 3).unwrap()
}

/// Writes a launch-style `/**` parameter file for the node and `replay` with the datum at
/// `scenario`'s start and a known heading (as static_node_support starts the node),
/// followed by `node_parameters` (YAML lines indented by 4).
pub fn write_node_parameters(path: &Path, scenario: &Scenario, node_parameters: &str) {
    let spec = &scenario.spec().trajectory;
    std::fs::write(
        path,
        format!(
            "/**:\n  ros__parameters:\n    init.heading_deg: 0.0\n    \
             output.datum_llh_deg_m: [{}, {}, {}]\n{node_parameters}",
            spec.start_lat_deg, spec.start_lon_deg, spec.start_height_m
        ),
    )
    .unwrap();
}
