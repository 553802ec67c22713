//! `gnss_ins_node`: the ROS 2 node. Takes ROS arguments as rcl does, e.g.
//! `gnss_ins_node --ros-args --params-file params/ekf.yaml -r imu:=/sensors/imu`
//! (`gnss_ins_node --help` lists them).

use std::process::ExitCode;

use adaptive_gnss_ins::ros::{args, log_level, node};

fn main() -> ExitCode {
    let cli = match args::parse(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => return fail(&e),
    };
    if cli.help {
        print!("{}", args::USAGE);
        return ExitCode::SUCCESS;
    }
    let logger = node::rosout::logger_name(&cli.fully_qualified_name());
    let (filter, unknown_loggers) = log_level::env_filter(&cli.log_levels, &logger);
    let log_lines = node::rosout::init_logging(&filter);
    for warning in cli.ignored.iter().chain(&unknown_loggers) {
        log::warn!("{warning}");
    }
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
