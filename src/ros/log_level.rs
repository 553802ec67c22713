//! `--log-level [LOGGER:=]LEVEL` as rcl reads it, and the env_logger filter it gives.
//!
//! rcl: a bare LEVEL sets the default level of every logger; `LOGGER:=LEVEL` the level of
//! one logger (a later rule for the same logger wins). LEVEL is one of `debug`, `info`,
//! `warn`, `error`, `fatal`, `unset`, in any case. The node's logger is named after the
//! node (`/robot/ins` → `robot.ins`); here it stands for every log line of this crate.

/// A severity of rcutils.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    Unset,
    Debug,
    Info,
    Warn,
    Error,
    Fatal,
}

impl Severity {
    /// rcutils' names, compared without case.
    fn parse(text: &str) -> Option<Self> {
        Some(match text.to_ascii_uppercase().as_str() {
            "UNSET" => Self::Unset,
            "DEBUG" => Self::Debug,
            "INFO" => Self::Info,
            "WARN" => Self::Warn,
            "ERROR" => Self::Error,
            "FATAL" => Self::Fatal,
            _ => return None,
        })
    }

    /// The env_logger level; None for `unset` (the logger keeps its default).
    ///
    /// Choice: `fatal` shows errors (the log crate has no fatal level).
    fn env_logger_level(self) -> Option<&'static str> {
        match self {
            Self::Unset => None,
            Self::Debug => Some("debug"),
            Self::Info => Some("info"),
            Self::Warn => Some("warn"),
            Self::Error | Self::Fatal => Some("error"),
        }
    }
}

/// One `--log-level` argument.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogLevelRule {
    /// The logger it is for; None: every logger (the default level).
    pub logger: Option<String>,
    pub level: Severity,
}

/// A `--log-level` value rcl refuses.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("--log-level `{0}`: expected LEVEL or LOGGER:=LEVEL with LEVEL one of debug, info, warn, error, fatal, unset")]
pub struct LogLevelError(pub String);

impl LogLevelRule {
    /// Parses `LEVEL` or `LOGGER:=LEVEL`.
    pub fn parse(text: &str) -> Result<Self, LogLevelError> {
        let error = || LogLevelError(text.to_owned());
        let (logger, level) = match text.split_once(":=") {
            Some(("", _)) => return Err(error()),
            Some((logger, level)) => (Some(logger.to_owned()), level),
            None => (None, text),
        };
        let level = Severity::parse(level).ok_or_else(error)?;
        Ok(Self { logger, level })
    }
}

/// The DDS libraries, the node's counterparts of rcl's and the rmw's loggers, and their
/// default levels.
///
/// Choice: without a rule for them, RustDDS logs only errors (its warnings about
/// unreachable locators flood a host without multicast), ros2-client warnings.
const LIBRARIES: [(&str, &str); 2] = [("rustdds", "error"), ("ros2_client", "warn")];
/// The log targets of this crate: what the node's logger stands for.
const OWN_TARGETS: [&str; 2] = ["adaptive_gnss_ins", "gnss_ins_node"];

/// The env_logger filter of `rules` for the node whose logger is `node_logger`, and a
/// warning for each rule about a logger this process does not have.
pub fn env_filter(rules: &[LogLevelRule], node_logger: &str) -> (String, Vec<String>) {
    let mut default = "info";
    let mut own: Option<&str> = None;
    let mut libraries = LIBRARIES;
    let mut warnings = Vec::new();
    for rule in rules {
        let level = rule.level.env_logger_level();
        match rule.logger.as_deref() {
            None => default = level.unwrap_or("info"),
            Some(name) if name == node_logger => own = level,
            Some(name) => match libraries.iter_mut().find(|(lib, _)| *lib == name) {
                Some((_, lib_level)) => {
                    let defaults = LIBRARIES.iter().find(|(lib, _)| *lib == name);
                    *lib_level = level.or(defaults.map(|(_, l)| *l)).unwrap_or("warn");
                }
                None => warnings.push(format!(
                    "--log-level {name}:=...: no logger `{name}` here (the node's logger is \
                     `{node_logger}`; rustdds and ros2_client are its DDS libraries); ignored"
                )),
            },
        }
    }
    let own = own.unwrap_or(default);
    let mut filter = default.to_owned();
    for target in OWN_TARGETS {
        filter.push_str(&format!(",{target}={own}"));
    }
    for (lib, level) in libraries {
        filter.push_str(&format!(",{lib}={level}"));
    }
    (filter, warnings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rules(args: &[&str]) -> Vec<LogLevelRule> {
        args.iter()
            .map(|a| LogLevelRule::parse(a).unwrap())
            .collect()
    }

    fn enabled(filter: &str, target: &str, level: log::Level) -> bool {
        use log::Log;
        let logger = env_logger::Builder::new().parse_filters(filter).build();
        logger.enabled(&log::Metadata::builder().target(target).level(level).build())
    }

    #[test]
    fn rcl_forms_parse() {
        let r = LogLevelRule::parse("gnss_ins_node:=DEBUG").unwrap();
        assert_eq!(r.logger.as_deref(), Some("gnss_ins_node"));
        assert_eq!(r.level, Severity::Debug);
        assert_eq!(LogLevelRule::parse("Warn").unwrap().level, Severity::Warn);
        for bad in ["verbose", ":=debug", "node:=loud", ""] {
            assert!(LogLevelRule::parse(bad).is_err(), "{bad}");
        }
    }

    /// Issue 16: `--log-level gnss_ins_node:=debug` set no level and silenced the node.
    #[test]
    fn the_nodes_logger_sets_the_crates_level() {
        let (filter, warnings) = env_filter(&rules(&["gnss_ins_node:=debug"]), "gnss_ins_node");
        assert!(warnings.is_empty());
        let own = "adaptive_gnss_ins::ros::node";
        assert!(enabled(&filter, own, log::Level::Debug), "{filter}");
        assert!(enabled(&filter, own, log::Level::Info), "{filter}");
        assert!(
            !enabled(&filter, "rustdds::rtps", log::Level::Warn),
            "{filter}"
        );
        let (filter, _) = env_filter(&rules(&["warn"]), "gnss_ins_node");
        assert!(
            !enabled(&filter, own, log::Level::Info) && enabled(&filter, own, log::Level::Warn)
        );
        let (filter, _) = env_filter(&rules(&["error", "robot.ins:=info"]), "robot.ins");
        assert!(enabled(&filter, own, log::Level::Info), "{filter}");
        let (filter, _) = env_filter(&rules(&["rustdds:=warn"]), "gnss_ins_node");
        assert!(
            enabled(&filter, "rustdds::rtps", log::Level::Warn),
            "{filter}"
        );
        let (_, warnings) = env_filter(&rules(&["rcl:=debug"]), "gnss_ins_node");
        assert!(warnings[0].contains("rcl"), "{warnings:?}");
    }
}
