//! Solutions compared: the messages of a bag's topic, and the largest difference between
//! two Odometry messages.
#![allow(dead_code)]

use std::path::Path;

use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::convert::time_to_seconds;
use adaptive_gnss_ins::ros::msg::{Odometry, RosMessage};

/// The messages of `topic` in `bag`, in log-time order.
pub fn decoded<M: RosMessage>(bag: &Path, topic: &str) -> Vec<M> {
    BagReader::open(bag)
        .unwrap()
        .messages()
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.topic == topic)
        .map(|m| cdr::decode::<M>(&m.data).unwrap())
        .collect()
}

/// Largest difference between two solutions' positions, velocities and orientations.
pub fn largest_difference(a: &Odometry, b: &Odometry) -> f64 {
    let (pa, pb) = (&a.pose.pose.position, &b.pose.pose.position);
    let (va, vb) = (&a.twist.twist.linear, &b.twist.twist.linear);
    let (qa, qb) = (&a.pose.pose.orientation, &b.pose.pose.orientation);
    [
        pa.x - pb.x,
        pa.y - pb.y,
        pa.z - pb.z,
        va.x - vb.x,
        va.y - vb.y,
        va.z - vb.z,
        qa.x - qb.x,
        qa.y - qb.y,
        qa.z - qb.z,
        qa.w - qb.w,
    ]
    .iter()
    .fold(0.0_f64, |m, d| m.max(d.abs()))
}

/// Largest [`largest_difference`] between two runs' solutions, asserting that they have
/// the same number of solutions at the same stamps (`what` names the two runs).
pub fn largest_difference_of_runs(live: &[Odometry], offline: &[Odometry], what: &str) -> f64 {
    assert_eq!(live.len(), offline.len(), "Odometry messages: {what}");
    live.iter()
        .zip(offline)
        .map(|(a, b)| {
            assert_eq!(a.header.stamp, b.header.stamp, "{what}");
            largest_difference(a, b)
        })
        .fold(0.0_f64, f64::max)
}

/// Solutions equal within this are the same.
pub const SAME: f64 = 1e-9;

/// A live node's solutions against the replay's of the same data.
#[derive(Debug)]
pub struct LiveAgainstReplay {
    pub solutions: usize,
    /// Runs of solutions that differ: each published before a late measurement arrived.
    pub late_runs: usize,
    /// Largest difference in them.
    pub worst_late: f64,
    /// Largest difference elsewhere (at most [`SAME`]).
    pub worst_in_time: f64,
}

/// Compares a live node's solutions with the replay's of the same data (same stamps
/// asserted). Over DDS the IMU and a measurement have no common order: one that arrived
/// after the IMU passed its stamp was applied by a roll-back, so only the solutions the
/// node published in between lacked it. Asserts that every solution differing by more
/// than [`SAME`] is such: it lies in a run that begins at the first solution after a
/// measurement's stamp (`measurement_t_s`, sorted) and ends before the next measurement's,
/// and there are at most `late` runs (the node's `late_measurements`).
pub fn assert_live_matches_replay(
    live: &[Odometry],
    offline: &[Odometry],
    measurement_t_s: &[f64],
    late: u64,
    what: &str,
) -> LiveAgainstReplay {
    assert_eq!(live.len(), offline.len(), "Odometry messages: {what}");
    let seconds = |o: &Odometry| time_to_seconds(&o.header.stamp).unwrap();
    let mut result = LiveAgainstReplay {
        solutions: live.len(),
        late_runs: 0,
        worst_late: 0.0,
        worst_in_time: 0.0,
    };
    // The stamp the current run must end at or before.
    let mut run_ends_by: Option<f64> = None;
    for (k, (a, b)) in live.iter().zip(offline).enumerate() {
        assert_eq!(a.header.stamp, b.header.stamp, "{what}");
        let d = largest_difference(a, b);
        let t = seconds(a);
        if d <= SAME {
            result.worst_in_time = result.worst_in_time.max(d);
            run_ends_by = None;
            continue;
        }
        result.worst_late = result.worst_late.max(d);
        if let Some(end) = run_ends_by {
            assert!(
                t <= end,
                "{what}: solution at {t} differs by {d}, after the next measurement at {end}"
            );
            continue;
        }
        let before = if k == 0 {
            f64::NEG_INFINITY
        } else {
            seconds(&live[k - 1])
        };
        let at = measurement_t_s.partition_point(|&m| m < before);
        assert!(
            measurement_t_s.get(at).is_some_and(|&m| m < t),
            "{what}: solution at {t} differs by {d}, and no measurement is stamped in [{before}, {t})"
        );
        result.late_runs += 1;
        run_ends_by = Some(
            measurement_t_s
                .get(at + 1)
                .copied()
                .unwrap_or(f64::INFINITY),
        );
    }
    assert!(
        result.late_runs as u64 <= late,
        "{what}: {} runs of differing solutions, {late} late measurements: {result:?}",
        result.late_runs
    );
    result
}

/// Every number of an Odometry: pose, orientation, twist and both covariances.
pub fn numbers(o: &Odometry) -> Vec<f64> {
    let (p, t) = (&o.pose.pose, &o.twist.twist);
    let mut values = vec![
        p.position.x,
        p.position.y,
        p.position.z,
        p.orientation.x,
        p.orientation.y,
        p.orientation.z,
        p.orientation.w,
        t.linear.x,
        t.linear.y,
        t.linear.z,
        t.angular.x,
        t.angular.y,
        t.angular.z,
    ];
    values.extend(o.pose.covariance);
    values.extend(o.twist.covariance);
    values
}
