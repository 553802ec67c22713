//! `tf_mode` `map_to_odom` over DDS (issue 16, items 2 and 7): a stand-in base controller
//! publishes `odom → base_link` on `/tf` at 50 Hz with a moving drift, while the node runs
//! on a simulated static receiver; the node's `map → odom` composed with the controller's
//! `odom → base_link` of the same stamp must be the node's Odometry pose, and the node
//! must never publish a parent of `base_link` (base_link keeps the controller's `odom`).
//!
//! DDS traffic stays on this machine: the test re-executes itself inside a private
//! network namespace that has only loopback (tests/netns_support).

mod netns_support;
mod static_node_support;
mod tf_support;

use std::time::{Duration, Instant};

use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::GnssMeasurements;
use adaptive_gnss_ins::ros::outbound;
use adaptive_gnss_ins::sim::SimEvent;
use netns_support::reexec_in_private_netns;
use static_node_support::{
    collect_outputs, diagnostic_count, start_node, static_scenario, Outputs, Peer,
};
use tf_support::{
    chain, controller_tf, drift, map_to_odom_by_stamp, nanos, Chain, CONTROLLER_PERIOD_NS,
    TOLERANCE,
};

const DOMAIN_ID: u16 = 19;
/// Scenario seconds streamed, and how much faster than real time.
const STREAM_S: f64 = 20.0;
const SPEED_UP: f64 = 10.0;
/// How far (scenario time) the controller's `/tf` runs ahead of the IMU, so that every
/// Odometry stamp lies between two controller stamps the node has heard: 0.2 s are 20 ms
/// of wall time at 10x, against sub-millisecond loopback latencies.
const CONTROLLER_LEAD_NS: i64 = 200_000_000;

#[test]
fn map_to_odom_chained_with_the_controllers_odom_is_the_fused_pose() {
    if reexec_in_private_netns("map_to_odom_chained_with_the_controllers_odom_is_the_fused_pose") {
        return;
    }
    let scenario = static_scenario();
    let _node = start_node(
        DOMAIN_ID,
        &scenario,
        &["-p", "publish_tf:=true", "-p", "tf_mode:=map_to_odom"],
    );
    let Peer {
        node: _peer,
        imu: imu_pub,
        gnss: gnss_pub,
        tf_out,
        odometry: odom_sub,
        diagnostics: diag_sub,
        tf: tf_sub,
    } = Peer::matched(DOMAIN_ID, "base_controller", "/test/imu", true);
    let tf_pub = tf_out.unwrap();

    let first_imu_ns = scenario
        .events()
        .map(Result::unwrap)
        .find_map(|e| match e {
            SimEvent::Imu(s) => Some(nanos(&seconds_to_time(s.t_s).unwrap())),
            _ => None,
        })
        .unwrap();
    // Our side having matched does not mean the node's best-effort readers have matched
    // our writers: repeat the controller's first transform and an empty GNSS epoch until
    // the node's diagnostics count both.
    let deadline = Instant::now() + Duration::from_secs(20);
    let (mut tf_heard, mut gnss_heard) = (0, 0);
    while tf_heard == 0 || gnss_heard == 0 {
        assert!(
            Instant::now() < deadline,
            "the node never reported the controller's transform and the empty epoch"
        );
        let first = controller_tf(first_imu_ns, &drift(first_imu_ns, first_imu_ns));
        tf_pub.publish(first).unwrap();
        gnss_pub.publish(GnssMeasurements::default()).unwrap();
        std::thread::sleep(Duration::from_millis(250));
        while let Ok(Some((d, _))) = diag_sub.take() {
            tf_heard = diagnostic_count(&d, "odom_tf_received").unwrap_or(0);
            gnss_heard = diagnostic_count(&d, "gnss_received").unwrap_or(0);
        }
    }

    // Stream the scenario, the controller's /tf running CONTROLLER_LEAD_NS ahead.
    let start = Instant::now();
    let mut next_tf_ns = first_imu_ns + CONTROLLER_PERIOD_NS;
    let mut controller_sent = 0u64;
    for event in scenario.events() {
        let event = event.unwrap();
        let t_s = event.t_s();
        if t_s > STREAM_S {
            break;
        }
        let due = Duration::from_secs_f64(t_s / SPEED_UP);
        if let Some(wait) = due.checked_sub(start.elapsed()) {
            std::thread::sleep(wait);
        }
        let stamp = seconds_to_time(t_s).unwrap();
        while next_tf_ns <= nanos(&stamp) + CONTROLLER_LEAD_NS {
            let tf = controller_tf(next_tf_ns, &drift(next_tf_ns, first_imu_ns));
            tf_pub.publish(tf).unwrap();
            controller_sent += 1;
            next_tf_ns += CONTROLLER_PERIOD_NS;
        }
        match event {
            SimEvent::Imu(s) => imu_pub
                .publish(outbound::imu(&s, stamp, "imu_link"))
                .unwrap(),
            SimEvent::Gnss { epoch, .. } => gnss_pub
                .publish(outbound::gnss_measurements(&epoch, 0, stamp, "gnss"))
                .unwrap(),
            _ => {}
        }
    }

    let Outputs {
        odometry,
        transforms,
        last_diagnostics,
    } = collect_outputs(&odom_sub, &tf_sub, &diag_sub, 3);

    // base_link has one parent: the controller's odom. Everything else on /tf is the
    // node's map -> odom.
    let map_to_odom = map_to_odom_by_stamp(&transforms);
    // One Odometry per IMU sample from the initialization at 1 s: about 1900.
    assert!(
        odometry.len() > 1500,
        "only {} Odometry messages received",
        odometry.len()
    );
    let Chain {
        matched,
        worst_m,
        worst_rad,
    } = chain(&odometry, &map_to_odom, |ns| drift(ns, first_imu_ns));
    eprintln!(
        "{} Odometry, {} map -> odom, {matched} matched, {controller_sent} controller \
         transforms sent; largest chain error {worst_m:.3e} m, {worst_rad:.3e} rad",
        odometry.len(),
        map_to_odom.len()
    );
    assert!(
        matched * 100 >= odometry.len() * 99,
        "{matched} of {} Odometry messages have a map -> odom at their stamp",
        odometry.len()
    );
    assert!(
        worst_m < TOLERANCE && worst_rad < TOLERANCE,
        "map -> odom -> base_link differs from the Odometry by {worst_m} m, {worst_rad} rad"
    );
    // The drift moved odom away from map: the node did not just publish the identity.
    let last = odometry.last().unwrap();
    let last_map_odom = map_to_odom[&nanos(&last.header.stamp)];
    let offset = &last_map_odom.transform.translation;
    assert!(offset.x.hypot(offset.y) > 5.0, "map -> odom {offset:?}");

    let diagnostics = last_diagnostics.expect("no /diagnostics received");
    let value = |key: &str| diagnostic_count(&diagnostics, key);
    eprintln!("diagnostics: {:?}", diagnostics.status[0].values);
    assert!(value("odom_tf_received").unwrap() >= controller_sent);
    assert_eq!(value("odom_tf_unusable"), Some(0));
    assert_eq!(
        value("map_to_odom_missing"),
        Some(0),
        "every Odometry had a controller transform around its stamp"
    );
}
