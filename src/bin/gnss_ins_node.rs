//! `gnss_ins_node`: the ROS 2 node. Takes ROS arguments as rcl does, e.g.
//! `gnss_ins_node --ros-args --params-file params/defaults.yaml -r imu:=/sensors/imu`
//! (`gnss_ins_node --help` lists them).

use std::process::ExitCode;

use adaptive_gnss_ins::ros::args::{DEFAULT_NODE_NAME, USAGE};
use adaptive_gnss_ins::ros::node::{self, startup};

fn main() -> ExitCode {
    startup::main("gnss_ins_node", DEFAULT_NODE_NAME, USAGE, |s| {
        let params = node::params::load(&s.args).map_err(|e| e.to_string())?;
        node::run(&s.args, params, s.dds, s.log_lines).map_err(|e| e.to_string())
    })
}
