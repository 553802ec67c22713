//! What every node executable does before its loop: the command line parsed as rcl does
//! (`--help` printed), logging set up with its `--log-level` rules and `/rosout`, the DDS
//! domain from `ROS_DOMAIN_ID` and the service mapping from `RMW_IMPLEMENTATION`; and an
//! error printed with the program's name and a failure exit code.

use std::process::ExitCode;

use crate::ros::args::{self, NodeArgs};
use crate::ros::log_level;

use super::dds::{domain_id_from, DdsOptions};
use super::rosout::{self, LogLines};
use super::services::service_mapping_from;

/// A started node executable: its arguments, its DDS options and the log lines for
/// `/rosout`.
pub struct Started {
    pub args: NodeArgs,
    pub dds: DdsOptions,
    pub log_lines: Option<LogLines>,
}

/// The program `program` (default node name `default_node_name`, usage text `usage`):
/// starts, then runs `run`; the exit code says whether all went well.
pub fn main<E: std::fmt::Display>(
    program: &str,
    default_node_name: &str,
    usage: &str,
    run: impl FnOnce(Started) -> Result<(), E>,
) -> ExitCode {
    let fail = |e: &dyn std::fmt::Display| {
        eprintln!("{program}: {e}");
        ExitCode::FAILURE
    };
    let cli = match args::parse_as(default_node_name, std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => return fail(&e),
    };
    if cli.help {
        print!("{usage}");
        return ExitCode::SUCCESS;
    }
    let logger = rosout::logger_name(&cli.fully_qualified_name());
    let (filter, unknown_loggers) = log_level::env_filter(&cli.log_levels, &logger);
    let log_lines = rosout::init_logging(&filter);
    for warning in cli.ignored.iter().chain(&unknown_loggers) {
        log::warn!("{warning}");
    }
    let domain_id = match domain_id_from(std::env::var("ROS_DOMAIN_ID").ok().as_deref()) {
        Ok(d) => d,
        Err(e) => return fail(&e),
    };
    let rmw = std::env::var("RMW_IMPLEMENTATION").ok();
    let dds = DdsOptions {
        domain_id,
        service_mapping: service_mapping_from(rmw.as_deref()),
    };
    let started = Started {
        args: cli,
        dds,
        log_lines,
    };
    match run(started) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => fail(&e),
    }
}
