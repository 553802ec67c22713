//! The `gnss_ins_node` binary with `dual_antenna.enabled` over DDS (issue 14, item 4): a
//! peer standing in for ublox_dgnss publishes ublox_ubx_msgs/UBXNavRelPosNED on the
//! remapped `ubx_nav_rel_pos_ned`; the node's /diagnostics counts them as received, one
//! without a carrier solution as unconvertible, a float solution as rejected, and reports
//! the stream's age.
//!
//! DDS traffic stays on this machine: the test re-executes itself inside a private network
//! namespace with only loopback (tests/netns_support, needs root).

mod netns_support;
mod static_node_support;

use adaptive_gnss_ins::engine::{BaselineHeadingReading, CarrierSolution};
use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::{CarrSoln, UbxNavRelPosNed};
use adaptive_gnss_ins::ros::rel_pos_ned::message_of_reading;
use netns_support::reexec_in_private_netns;
use static_node_support::{
    diagnostic_count, diagnostic_value, publish_until_counted, start_node, static_scenario, Peer,
};

const DOMAIN_ID: u16 = 24;

fn rel_pos_ned(t_s: f64, carrier: CarrierSolution) -> UbxNavRelPosNed {
    let reading = BaselineHeadingReading {
        t_s,
        heading_rad: 0.0,
        sigma_rad: 0.005,
        length_m: 1.0,
        carrier,
    };
    message_of_reading(&reading, seconds_to_time(t_s).unwrap(), "pair")
}

#[test]
fn the_node_counts_the_relposned_of_a_remapped_topic() {
    if reexec_in_private_netns("the_node_counts_the_relposned_of_a_remapped_topic") {
        return;
    }
    let scenario = static_scenario();
    let _node = start_node(
        DOMAIN_ID,
        &scenario,
        &[
            "-p",
            "dual_antenna.enabled:=true",
            "-r",
            "ubx_nav_rel_pos_ned:=pair/ubx_nav_rel_pos_ned",
            // The peer waits for the node's /tf.
            "-p",
            "publish_tf:=true",
        ],
    );
    let mut peer = Peer::matched(DOMAIN_ID, "ublox_dgnss", "/test/imu", false);
    let pair = peer.publisher::<UbxNavRelPosNed>("/test/pair/ubx_nav_rel_pos_ned");
    let count = |d: &_, key| diagnostic_count(d, key).unwrap_or(0);
    let mut t_s = 1.0;
    let d = publish_until_counted(
        &mut peer,
        || {
            let mut no_carrier = rel_pos_ned(t_s, CarrierSolution::Fixed);
            no_carrier.carr_soln.status = CarrSoln::NO_CARRIER_RANGE_SOLUTION;
            pair.publish(no_carrier).unwrap();
            pair.publish(rel_pos_ned(t_s + 0.5, CarrierSolution::Float))
                .unwrap();
            t_s += 1.0;
        },
        |d| {
            count(d, "unconvertible_rel_pos_ned") > 0
                && count(d, "rejected_baseline_heading_float") > 0
        },
    );
    let received = count(&d, "rel_pos_ned_received");
    let unconvertible = count(&d, "unconvertible_rel_pos_ned");
    let float = count(&d, "rejected_baseline_heading_float");
    println!(
        "node: UBXNavRelPosNED received {received}, unconvertible {unconvertible}, float \
         {float}"
    );
    assert_eq!(received, unconvertible + float, "{d:?}");
    let since = diagnostic_value(&d, "rel_pos_ned_since_last_s").unwrap();
    assert_ne!(since, "never", "{d:?}");
}
