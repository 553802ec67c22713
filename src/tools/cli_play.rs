//! `gnss_ins play`: a recorded bag published onto DDS (see [`crate::ros::player`]).

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use crate::ros::node::domain_id_from;
use crate::ros::player::{self, PlayOptions};

use super::progress::Progress;

#[derive(Args)]
pub struct PlayArgs {
    /// The bag to play: an .mcap file or a rosbag2 directory holding one.
    bag: PathBuf,
    /// Speed factor (2 plays twice as fast as recorded), 0.001 to 1000.
    #[arg(long, default_value_t = 1.0)]
    rate: f64,
    /// Publish /clock (rosgraph_msgs/Clock) with the bag's time, for use_sim_time.
    #[arg(long)]
    clock: bool,
    /// Rate of /clock in bag time (Hz), 0.01 to 10000.
    #[arg(long, default_value_t = 40.0)]
    clock_hz: f64,
    /// Play again from the start when the bag ends, until stopped.
    #[arg(long = "loop")]
    repeat: bool,
    /// Seconds to wait after creating the publishers, before the first message.
    #[arg(long, default_value_t = 0.0)]
    delay: f64,
    /// Seconds of the bag to skip at its start (each pass with --loop): join a recording
    /// in its middle, as after a crash or a re-launch.
    #[arg(long, default_value_t = 0.0)]
    start_offset: f64,
    /// A topic that must have a matched subscriber before playing starts (repeatable).
    #[arg(long = "wait-for")]
    wait_for: Vec<String>,
}

pub fn play(args: PlayArgs) -> Result<(), String> {
    let domain_id = domain_id_from(std::env::var("ROS_DOMAIN_ID").ok().as_deref())
        .map_err(|e| e.to_string())?;
    let delay = Duration::try_from_secs_f64(args.delay).map_err(|_| {
        format!(
            "--delay must be a non-negative number of seconds, got {}",
            args.delay
        )
    })?;
    let start_offset = Duration::try_from_secs_f64(args.start_offset).map_err(|_| {
        format!(
            "--start-offset must be a non-negative number of seconds, got {}",
            args.start_offset
        )
    })?;
    let options = PlayOptions {
        rate: args.rate,
        clock: args.clock,
        clock_hz: args.clock_hz,
        repeat: args.repeat,
        delay,
        start_offset,
        wait_for_topics: args.wait_for,
        domain_id,
    };
    let line = Progress::new();
    let report = player::play(&args.bag, &options, |pass, f| {
        let what = if options.repeat {
            format!("play, pass {}", pass + 1)
        } else {
            "play".to_owned()
        };
        line.fraction(&what, f)
    });
    line.end();
    let report = report.map_err(|e| e.to_string())?;
    for (topic, n) in &report.published {
        println!("{topic}: {n} published");
    }
    for (reason, n) in &report.skipped {
        println!("skipped ({reason}): {n}");
    }
    Ok(())
}
