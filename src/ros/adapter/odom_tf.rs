//! The TF the node publishes (`tf_mode`) and, in `map_to_odom` mode, the base
//! controller's `odom → base` transforms heard on `/tf`, from which `map → odom` is
//! composed so that `map → odom → base` is the fused pose (REP-105; as
//! robot_localization publishes it). No DDS: the node feeds `/tf` messages in.

use std::collections::VecDeque;

use nalgebra::{Isometry3, Quaternion as NaQuaternion, Translation3, UnitQuaternion};

use crate::ros::msg::{Header, Odometry, Quaternion, TFMessage, Time, Vector3};
use crate::ros::outbound;

/// What the node publishes on `/tf` with each Odometry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TfMode {
    /// `map_frame → base_frame`: the fused pose itself (no other source of the base's
    /// parent).
    MapToBaseLink,
    /// `map_frame → odom_frame`, composed with the base controller's `odom_frame →
    /// base_frame` heard on `/tf` (base_frame keeps one parent).
    MapToOdom,
    /// Nothing.
    None,
}

impl TfMode {
    /// Every mode, in the order the manual lists them.
    pub const ALL: [TfMode; 3] = [TfMode::MapToBaseLink, TfMode::MapToOdom, TfMode::None];

    /// The parameter value naming the mode.
    pub fn name(self) -> &'static str {
        match self {
            TfMode::MapToBaseLink => "map_to_base_link",
            TfMode::MapToOdom => "map_to_odom",
            TfMode::None => "none",
        }
    }

    /// The mode named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// Choice: transforms kept. A base controller publishes `odom → base` at 20–100 Hz; 256
/// hold 2.5 s at 100 Hz, far more than the latency between an IMU sample and its
/// Odometry (under a millisecond, issue 16), and the look-up walks back from the newest.
const REMEMBERED_TRANSFORMS: usize = 256;

/// Choice: how far an Odometry stamp may lie past the newest `odom → base` for that one to
/// be used as it is. The controller's next transform usually arrives after the IMU sample
/// of the same time; tf2 would refuse to extrapolate and robot_localization then falls
/// back to the latest transform. 0.1 s is five periods of a 50 Hz controller: a silent
/// controller stops `map → odom` after it instead of freezing a stale one.
const MAX_HOLD_NS: i64 = 100_000_000;

/// Choice: a transform this much older than the newest is a time jump (a bag played
/// again, a restarted simulation): the history is cleared, as tf2 clears its buffer on a
/// jump back.
const JUMP_BACK_NS: i64 = 1_000_000_000;

/// The stamp in integer nanoseconds.
fn nanos(t: &Time) -> i64 {
    i64::from(t.sec) * 1_000_000_000 + i64::from(t.nanosec)
}

/// tf2 ignores a leading `/` of a frame id.
fn same_frame(a: &str, b: &str) -> bool {
    a.trim_start_matches('/') == b.trim_start_matches('/')
}

/// The rigid transform of a `geometry_msgs/Transform`-like pair, None when a number is not
/// finite or the quaternion has no direction.
fn isometry(t: &Vector3, q: &Quaternion) -> Option<Isometry3<f64>> {
    let q = NaQuaternion::new(q.w, q.x, q.y, q.z);
    let values = [t.x, t.y, t.z, q.w, q.i, q.j, q.k];
    if !values.iter().all(|v| v.is_finite()) || q.norm() < 1e-9 {
        return None;
    }
    Some(Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::from_quaternion(q),
    ))
}

/// What became of the base controller's transforms in `map_to_odom` mode (on the node's
/// /diagnostics as `odom_tf_received`, `odom_tf_unusable` and `map_to_odom_missing`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OdomTfCounts {
    /// `odom → base` transforms taken.
    pub received: u64,
    /// `odom → base` transforms with a non-finite value or no rotation: dropped.
    pub unusable: u64,
    /// Odometry messages without a `map → odom` (no `odom → base` near their stamp).
    pub map_to_odom_missing: u64,
}

/// The recent `odom_frame → base_frame` transforms of the base controller, by stamp.
#[derive(Debug, Clone)]
pub(super) struct OdomHistory {
    odom_frame: String,
    base_frame: String,
    /// (stamp in ns, transform), oldest first, stamps strictly increasing.
    recent: VecDeque<(i64, Isometry3<f64>)>,
    /// `odom → base` transforms taken.
    pub(super) heard: u64,
    /// `odom → base` transforms with a non-finite value or no rotation: dropped.
    pub(super) unusable: u64,
    /// Odometry messages without a `map → odom` (no `odom → base` near their stamp).
    pub(super) missing: u64,
}

impl OdomHistory {
    pub(super) fn new(odom_frame: &str, base_frame: &str) -> Self {
        Self {
            odom_frame: odom_frame.to_owned(),
            base_frame: base_frame.to_owned(),
            recent: VecDeque::new(),
            heard: 0,
            unusable: 0,
            missing: 0,
        }
    }

    pub(super) fn counts(&self) -> OdomTfCounts {
        OdomTfCounts {
            received: self.heard,
            unusable: self.unusable,
            map_to_odom_missing: self.missing,
        }
    }

    /// Takes the `odom_frame → base_frame` transforms of a `/tf` message (others, such as
    /// the node's own `map → odom`, are not ours and ignored).
    pub(super) fn on_tf(&mut self, msg: &TFMessage) {
        for t in &msg.transforms {
            if !same_frame(&t.header.frame_id, &self.odom_frame)
                || !same_frame(&t.child_frame_id, &self.base_frame)
            {
                continue;
            }
            match isometry(&t.transform.translation, &t.transform.rotation) {
                Some(pose) => {
                    self.heard += 1;
                    self.insert(nanos(&t.header.stamp), pose);
                }
                None => self.unusable += 1,
            }
        }
    }

    fn insert(&mut self, stamp_ns: i64, pose: Isometry3<f64>) {
        if self
            .recent
            .back()
            .is_some_and(|&(newest, _)| stamp_ns < newest - JUMP_BACK_NS)
        {
            self.recent.clear();
        }
        // Usually the newest; DDS may reorder a little.
        let at = self.recent.partition_point(|&(t, _)| t < stamp_ns);
        match self.recent.get_mut(at) {
            Some(entry) if entry.0 == stamp_ns => entry.1 = pose,
            _ => self.recent.insert(at, (stamp_ns, pose)),
        }
        if self.recent.len() > REMEMBERED_TRANSFORMS {
            self.recent.pop_front();
        }
    }

    /// `odom → base` at `stamp_ns`: the transform of that stamp, else interpolated
    /// between the two around it (translation linearly, rotation by slerp, as tf2 does),
    /// else the newest when the stamp lies at most [`MAX_HOLD_NS`] past it; None before
    /// the oldest, after a longer silence, or before anything was heard.
    pub(super) fn at(&self, stamp_ns: i64) -> Option<Isometry3<f64>> {
        let after = self.recent.partition_point(|&(t, _)| t < stamp_ns);
        match (
            after.checked_sub(1).map(|i| self.recent[i]),
            self.recent.get(after),
        ) {
            (_, Some(&(t, pose))) if t == stamp_ns => Some(pose),
            (Some((t0, p0)), Some(&(t1, p1))) => {
                let s = (stamp_ns - t0) as f64 / (t1 - t0) as f64;
                let mut pose = p0.lerp_slerp(&p1, s);
                // nalgebra's slerp of two close rotations (acos near 1) leaves the norm
                // off by ~1e-11, which the composition below would turn into ~1e-9 m at
                // a 10 m lever arm.
                pose.rotation.renormalize();
                Some(pose)
            }
            (Some((t0, p0)), None) if stamp_ns - t0 <= MAX_HOLD_NS => Some(p0),
            _ => None,
        }
    }

    /// The `map → odom` transform that makes `map → odom → base` the pose of `odometry`
    /// (header.frame_id the map, child the base) at its stamp: `T(map→odom) =
    /// T(map→base) · T(odom→base)⁻¹`; None (counted) without an `odom → base` there.
    pub(super) fn map_to_odom(&mut self, odometry: &Odometry) -> Option<TFMessage> {
        let pose = &odometry.pose.pose;
        let p = &pose.position;
        let map_base = isometry(
            &Vector3 {
                x: p.x,
                y: p.y,
                z: p.z,
            },
            &pose.orientation,
        );
        let (Some(map_base), Some(odom_base)) = (map_base, self.at(nanos(&odometry.header.stamp)))
        else {
            self.missing += 1;
            return None;
        };
        let map_odom = map_base * odom_base.inverse();
        let header = Header {
            stamp: odometry.header.stamp,
            frame_id: odometry.header.frame_id.clone(),
        };
        Some(TFMessage {
            transforms: vec![outbound::transform_stamped(
                header,
                &self.odom_frame,
                &map_odom,
            )],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::msg::{Point, Pose};

    fn time(ns: i64) -> Time {
        Time {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    fn quaternion(q: &UnitQuaternion<f64>) -> Quaternion {
        Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }
    }

    /// A base controller's `odom → base_link` drifting at 0.5 m/s east and 0.1 rad/s of
    /// yaw: the stand-in of a wheel odometry.
    fn drift(ns: i64) -> Isometry3<f64> {
        let t_s = (ns - 1_700_000_000_000_000_000) as f64 * 1e-9;
        Isometry3::from_parts(
            Translation3::new(0.5 * t_s, 0.02 * t_s, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.1 * t_s),
        )
    }

    fn tf(parent: &str, child: &str, ns: i64, pose: &Isometry3<f64>) -> TFMessage {
        let header = Header {
            stamp: time(ns),
            frame_id: parent.to_owned(),
        };
        TFMessage {
            transforms: vec![outbound::transform_stamped(header, child, pose)],
        }
    }

    fn odometry(ns: i64, pose: &Isometry3<f64>) -> Odometry {
        let t = pose.translation.vector;
        let mut o = Odometry::default();
        o.header.stamp = time(ns);
        o.header.frame_id = "map".to_owned();
        o.child_frame_id = "base_link".to_owned();
        o.pose.pose = Pose {
            position: Point {
                x: t.x,
                y: t.y,
                z: t.z,
            },
            orientation: quaternion(&pose.rotation),
        };
        o
    }

    fn transform_of(msg: &TFMessage) -> Isometry3<f64> {
        let t = &msg.transforms[0].transform;
        isometry(&t.translation, &t.rotation).unwrap()
    }

    /// Largest translation (m) and rotation (rad) difference of two transforms.
    fn difference(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
        let d = a.inverse() * b;
        (d.translation.vector.norm(), d.rotation.angle())
    }

    const T0_NS: i64 = 1_700_000_000_002_500_001;
    const PERIOD_NS: i64 = 20_000_000;

    #[test]
    fn modes_round_trip_their_names() {
        for m in TfMode::ALL {
            assert_eq!(TfMode::from_name(m.name()), Some(m));
        }
        assert_eq!(TfMode::from_name("map_to_base"), None);
    }

    #[test]
    fn map_to_odom_composes_to_the_fused_pose_between_controller_stamps() {
        let mut h = OdomHistory::new("odom", "base_link");
        // 20 s from the controller's start: a lever arm of 10 m.
        for k in 990..1000 {
            let ns = T0_NS + k * PERIOD_NS;
            h.on_tf(&tf("odom", "base_link", ns, &drift(ns)));
        }
        assert_eq!(h.heard, 10);
        let fused = Isometry3::from_parts(
            Translation3::new(12.0, -3.0, 0.5),
            UnitQuaternion::from_euler_angles(0.01, -0.02, 1.2),
        );
        // On a controller stamp, and at 200 Hz IMU stamps between them.
        for ns in [T0_NS + 993 * PERIOD_NS, T0_NS + 993 * PERIOD_NS + 5_000_001] {
            let msg = h.map_to_odom(&odometry(ns, &fused)).unwrap();
            let t = &msg.transforms[0];
            assert_eq!(t.header.stamp, time(ns), "the Odometry's stamp exactly");
            assert_eq!(
                (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
                ("map", "odom")
            );
            let chained = transform_of(&msg) * drift(ns);
            let (dt_m, dr_rad) = difference(&chained, &fused);
            // The yaw drift is linear in time, so slerp reproduces it; what is left is
            // f64 rounding of products of 10 m-scale poses (~1e-15 m). An interpolated
            // rotation not renormalized gave 3.7e-10 m here.
            assert!(dt_m < 1e-12 && dr_rad < 1e-12, "{dt_m} m, {dr_rad} rad");
        }
        assert_eq!(h.missing, 0);
    }

    #[test]
    fn no_map_to_odom_before_an_odom_transform_or_after_a_long_silence() {
        let mut h = OdomHistory::new("odom", "base_link");
        let fused = Isometry3::identity();
        assert!(h.map_to_odom(&odometry(T0_NS, &fused)).is_none());
        // Another pair of frames (our own map -> odom, a sensor mount) is not ours.
        h.on_tf(&tf("map", "odom", T0_NS, &drift(T0_NS)));
        h.on_tf(&tf("base_link", "imu_link", T0_NS, &drift(T0_NS)));
        assert!(h.map_to_odom(&odometry(T0_NS, &fused)).is_none());
        assert_eq!((h.heard, h.missing), (0, 2));
        // tf2's leading slash is the same frame.
        h.on_tf(&tf("/odom", "base_link", T0_NS, &drift(T0_NS)));
        assert!(
            h.map_to_odom(&odometry(T0_NS - 1, &fused)).is_none(),
            "before it"
        );
        assert!(h
            .map_to_odom(&odometry(T0_NS + MAX_HOLD_NS, &fused))
            .is_some());
        assert!(h
            .map_to_odom(&odometry(T0_NS + MAX_HOLD_NS + 1, &fused))
            .is_none());
        assert_eq!((h.heard, h.missing), (1, 4));
    }

    #[test]
    fn bad_transforms_are_counted_and_reordered_ones_sorted() {
        let mut h = OdomHistory::new("odom", "base_link");
        let mut bad = tf("odom", "base_link", T0_NS, &drift(T0_NS));
        bad.transforms[0].transform.rotation = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        h.on_tf(&bad);
        bad.transforms[0].transform.rotation.w = 1.0;
        bad.transforms[0].transform.translation.x = f64::NAN;
        h.on_tf(&bad);
        assert_eq!((h.heard, h.unusable), (0, 2));
        for k in [2, 0, 1] {
            let ns = T0_NS + k * PERIOD_NS;
            h.on_tf(&tf("odom", "base_link", ns, &drift(ns)));
        }
        let ns = T0_NS + PERIOD_NS / 2;
        let (dt_m, _) = difference(&h.at(ns).unwrap(), &drift(ns));
        assert!(dt_m < 1e-9, "{dt_m}");
        // A jump back in time (a bag played again) starts the history anew.
        h.on_tf(&tf(
            "odom",
            "base_link",
            T0_NS - 5 * JUMP_BACK_NS,
            &drift(T0_NS),
        ));
        assert!(h.at(T0_NS).is_none());
        assert_eq!(h.recent.len(), 1);
    }
}
