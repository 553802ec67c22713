//! `gnss_ins_node`: the ROS 2 node. Takes only ROS arguments, e.g.
//! `gnss_ins_node --ros-args --params-file params/ekf.yaml -r imu:=/sensors/imu`.

use std::process::ExitCode;

use adaptive_gnss_ins::ros::{args, node};

fn main() -> ExitCode {
    let cli = match args::parse(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => return fail(&e),
    };
    // Choice: without RUST_LOG, RustDDS logs only errors (its warnings about unreachable
    // locators flood a host without multicast), ros2-client warnings, the rest at --log-level.
    let level = cli.log_level.as_deref().unwrap_or("info");
    let filter = format!("{level},rustdds=error,ros2_client=warn");
    let log_lines = node::rosout::init_logging(&filter);
    let params = match node::params::load(&cli) {
        Ok(c) => c,
        Err(e) => return fail(&e),
    };
    let domain_id = match node::domain_id_from(std::env::var("ROS_DOMAIN_ID").ok().as_deref()) {
        Ok(d) => d,
        Err(e) => return fail(&e),
    };
    let rmw = std::env::var("RMW_IMPLEMENTATION").ok();
    let dds = node::DdsOptions {
        domain_id,
        service_mapping: node::service_mapping_from(rmw.as_deref()),
    };
    match node::run(&cli, params, dds, log_lines) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => fail(&e),
    }
}

fn fail(e: &dyn std::fmt::Display) -> ExitCode {
    eprintln!("gnss_ins_node: {e}");
    ExitCode::FAILURE
}
