//! Solutions compared: the messages of a bag's topic, and the largest difference between
//! two Odometry messages.
#![allow(dead_code)]

use std::path::Path;

use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::ros::cdr;
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
