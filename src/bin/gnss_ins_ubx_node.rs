//! `gnss_ins_ubx_node`: a u-blox receiver's raw GNSS (ublox_dgnss RAWX/SFRBX messages or
//! the ublox_gps byte stream) -> GnssMeasurements for `gnss_ins_node`. Takes ROS
//! arguments as rcl does (`gnss_ins_ubx_node --help` lists them).

use std::process::ExitCode;

use adaptive_gnss_ins::ros::node::startup;
use adaptive_gnss_ins::ros::ubx_node::{self, params, DEFAULT_NODE_NAME, USAGE};

fn main() -> ExitCode {
    startup::main("gnss_ins_ubx_node", DEFAULT_NODE_NAME, USAGE, |s| {
        let params = params::load(&s.args).map_err(|e| e.to_string())?;
        ubx_node::run(&s.args, params, s.dds, s.log_lines).map_err(|e| e.to_string())
    })
}
