//! Logging to stderr (env_logger) and to `/rosout` (rcl_interfaces/Log).
//!
//! A logger in front of env_logger hands every line of this crate that env_logger prints
//! to the node's event loop, which publishes it on `/rosout` stamped with the node's
//! time. Repeated warnings are limited before they are logged ([`crate::ros::log_limit`]), so
//! `/rosout` carries exactly the lines stderr does.

use std::sync::Mutex;

use futures::channel::mpsc;
use log::{Level, Metadata, Record};

use crate::ros::msg::{Log, Time};

/// Lines waiting for the event loop. Choice: a line that finds the queue full is dropped
/// from `/rosout` (it is still on stderr) rather than blocking the thread that logged.
pub const ROSOUT_QUEUE: usize = 256;

/// Only these crates' lines go to `/rosout`: the node's own. Choice: the DDS libraries'
/// lines stay on stderr, since publishing a line can make them log again.
const OWN_TARGETS: [&str; 2] = ["adaptive_gnss_ins", "gnss_ins_node"];

/// One log line for `/rosout`, before it gets its stamp and logger name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogLine {
    /// rcl_interfaces/Log level.
    pub level: u8,
    /// The text.
    pub msg: String,
    /// Source file.
    pub file: String,
    /// Module path.
    pub function: String,
    /// Source line.
    pub line: u32,
}

/// The receiving end: the event loop's stream of lines.
pub type LogLines = mpsc::Receiver<LogLine>;

struct RosoutLogger {
    stderr: env_logger::Logger,
    lines: Mutex<mpsc::Sender<LogLine>>,
}

fn level_of(level: Level) -> u8 {
    match level {
        Level::Error => Log::ERROR,
        Level::Warn => Log::WARN,
        Level::Info => Log::INFO,
        Level::Debug | Level::Trace => Log::DEBUG,
    }
}

fn is_own(target: &str) -> bool {
    OWN_TARGETS
        .iter()
        .any(|own| target == *own || target.starts_with(&format!("{own}::")))
}

impl log::Log for RosoutLogger {
    fn enabled(&self, metadata: &Metadata) -> bool {
        self.stderr.enabled(metadata)
    }

    fn log(&self, record: &Record) {
        if !self.stderr.matches(record) {
            return;
        }
        self.stderr.log(record);
        if !is_own(record.target()) {
            return;
        }
        let line = LogLine {
            level: level_of(record.level()),
            msg: record.args().to_string(),
            file: record.file().unwrap_or_default().to_owned(),
            function: record.module_path().unwrap_or_default().to_owned(),
            line: record.line().unwrap_or(0),
        };
        if let Ok(mut sender) = self.lines.lock() {
            // Full or closed: the line is on stderr only (see ROSOUT_QUEUE).
            let _ = sender.try_send(line);
        }
    }

    fn flush(&self) {
        self.stderr.flush();
    }
}

/// Installs the logger: env_logger configured by `RUST_LOG`, or by `default_filter`
/// without it. Returns the lines for `/rosout`, or None when a logger was already set
/// (then nothing goes to `/rosout`).
pub fn init_logging(default_filter: &str) -> Option<LogLines> {
    let stderr =
        env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(default_filter))
            .build();
    let max_level = stderr.filter();
    let (sender, receiver) = mpsc::channel(ROSOUT_QUEUE);
    let logger = RosoutLogger {
        stderr,
        lines: Mutex::new(sender),
    };
    log::set_boxed_logger(Box::new(logger)).ok()?;
    log::set_max_level(max_level);
    Some(receiver)
}

/// The ROS logger name of the node `fqn` (`/ns/node` → `ns.node`), as rcl names it.
pub fn logger_name(fqn: &str) -> String {
    fqn.trim_start_matches('/').replace('/', ".")
}

/// The `/rosout` message of `line`, logged by `logger` at `stamp`.
pub fn rosout_message(line: LogLine, logger: &str, stamp: Time) -> Log {
    Log {
        stamp,
        level: line.level,
        name: logger.to_owned(),
        msg: line.msg,
        file: line.file,
        function: line.function,
        line: line.line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_levels_and_targets() {
        assert_eq!(logger_name("/interop/ins"), "interop.ins");
        assert_eq!(logger_name("/gnss_ins_node"), "gnss_ins_node");
        assert_eq!(level_of(Level::Warn), Log::WARN);
        assert_eq!(level_of(Level::Trace), Log::DEBUG);
        assert!(is_own("adaptive_gnss_ins::ros::node"));
        assert!(is_own("gnss_ins_node"));
        assert!(!is_own("rustdds::rtps"));
        assert!(!is_own("adaptive_gnss_ins_other"));
    }

    #[test]
    fn message_carries_the_line() {
        let line = LogLine {
            level: Log::WARN,
            msg: "m".into(),
            file: "f.rs".into(),
            function: "a::b".into(),
            line: 7,
        };
        let stamp = Time { sec: 3, nanosec: 4 };
        let m = rosout_message(line, "ns.n", stamp);
        assert_eq!((m.level, m.line, m.stamp), (Log::WARN, 7, stamp));
        assert_eq!((m.name.as_str(), m.msg.as_str()), ("ns.n", "m"));
    }
}
