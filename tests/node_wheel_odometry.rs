//! The `gnss_ins_node` binary with `wheel_odometry.enabled` over DDS (issue 14, item 3): a
//! peer standing in for a base controller publishes nav_msgs/Odometry on the remapped
//! `wheel/odometry`; the node's /diagnostics counts them as received, a NaN forward speed
//! as unconvertible, and a good one reaches the engine (which, before the filter runs,
//! rejects it as such); the stream's age is reported.
//!
//! DDS traffic stays on this machine: the test re-executes itself inside a private network
//! namespace with only loopback (tests/netns_support, needs root).

mod netns_support;
mod static_node_support;

use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::Odometry;
use netns_support::reexec_in_private_netns;
use static_node_support::{
    diagnostic_count, diagnostic_value, publish_until_counted, start_node, static_scenario, Peer,
};

const DOMAIN_ID: u16 = 23;

fn odometry(t_s: f64, speed_mps: f64) -> Odometry {
    let mut msg = Odometry::default();
    msg.header.stamp = seconds_to_time(t_s).unwrap();
    msg.header.frame_id = "odom".to_owned();
    msg.child_frame_id = "base_link".to_owned();
    msg.twist.twist.linear.x = speed_mps;
    msg.twist.covariance[0] = 0.01;
    msg
}

#[test]
fn the_node_counts_the_wheel_odometry_of_a_remapped_topic() {
    if reexec_in_private_netns("the_node_counts_the_wheel_odometry_of_a_remapped_topic") {
        return;
    }
    let scenario = static_scenario();
    let _node = start_node(
        DOMAIN_ID,
        &scenario,
        &[
            "-p",
            "wheel_odometry.enabled:=true",
            "-r",
            "wheel/odometry:=base/odom",
            // The peer waits for the node's /tf.
            "-p",
            "publish_tf:=true",
        ],
    );
    let mut peer = Peer::matched(DOMAIN_ID, "base_controller", "/test/imu", false);
    let wheels = peer.publisher::<Odometry>("/test/base/odom");
    let count = |d: &_, key| diagnostic_count(d, key).unwrap_or(0);
    let mut t_s = 1.0;
    let d = publish_until_counted(
        &mut peer,
        || {
            wheels.publish(odometry(t_s, 1.5)).unwrap();
            wheels.publish(odometry(t_s + 0.5, f64::NAN)).unwrap();
            t_s += 1.0;
        },
        |d| {
            count(d, "unconvertible_wheel_odometry") > 0
                && count(d, "rejected_wheel_speed_before_start") > 0
        },
    );
    let received = count(&d, "wheel_odometry_received");
    let unconvertible = count(&d, "unconvertible_wheel_odometry");
    let before_start = count(&d, "rejected_wheel_speed_before_start");
    println!(
        "node: wheel odometry received {received}, unconvertible {unconvertible}, before the \
         start {before_start}"
    );
    assert_eq!(received, unconvertible + before_start, "{d:?}");
    let since = diagnostic_value(&d, "wheel_odometry_since_last_s").unwrap();
    assert_ne!(since, "never", "{d:?}");
}
