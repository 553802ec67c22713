//! The node's command line, parsed as rcl parses it and without side effects (no file is
//! read here).
//!
//! After `--ros-args` (which may appear several times; `--` ends a block), in order:
//! `--params-file FILE` (any number; rcl reads them in order, a later value wins),
//! `-p|--param [NODE:]name:=value`, `-r|--remap [NODE:]from:=to` (topic names, plus the
//! special `__node:=NAME` and `__ns:=/NS`), `--log-level [LOGGER:=]LEVEL`. The other
//! flags rcl knows (`-e|--enclave`, `--log-file-name`, `--log-config-file`,
//! `--enable-|--disable-{stdout,rosout,external-lib}-logs`) are accepted and ignored with
//! a warning; any other ROS argument is an error that names it. Before `--ros-args`, the
//! node's own arguments: `--record OUT.mcap` (write everything the node publishes to a
//! rosbag2 MCAP bag) and `-h|--help`; a `from:=to` there is a remapping in rcl's
//! deprecated form (with a warning).

use std::path::PathBuf;

use super::log_level::{LogLevelError, LogLevelRule};

/// The default node name.
pub const DEFAULT_NODE_NAME: &str = "gnss_ins_node";

/// A `--params-file` or a `-p` rule, in command-line order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ParameterSource {
    /// `--params-file FILE`.
    File(PathBuf),
    /// `-p [node:]name:=value`; the value is YAML text. Without a node prefix rcl files
    /// the rule under `/**`.
    Rule {
        node: Option<String>,
        name: String,
        value: String,
    },
}

/// What the command line asks for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeArgs {
    /// Node base name (`-r __node:=NAME`, default [`DEFAULT_NODE_NAME`]).
    pub node_name: String,
    /// Absolute node namespace (`-r __ns:=/NS`, default `/`).
    pub namespace: String,
    /// Parameter files and `-p` rules in command-line order.
    pub parameter_sources: Vec<ParameterSource>,
    /// Topic remappings (`-r from:=to`) in command-line order (those for another node
    /// left out).
    pub remaps: Vec<(String, String)>,
    /// `--log-level` rules in command-line order.
    pub log_levels: Vec<LogLevelRule>,
    /// `--record OUT.mcap`: the bag that receives every message the node publishes.
    pub record: Option<PathBuf>,
    /// `-h` / `--help`: print the usage and exit.
    pub help: bool,
    /// Arguments accepted but not acted on, each with why: for a warning at start.
    pub ignored: Vec<String>,
}

impl Default for NodeArgs {
    fn default() -> Self {
        Self {
            node_name: DEFAULT_NODE_NAME.to_owned(),
            namespace: "/".to_owned(),
            parameter_sources: Vec::new(),
            remaps: Vec::new(),
            log_levels: Vec::new(),
            record: None,
            help: false,
            ignored: Vec::new(),
        }
    }
}

impl NodeArgs {
    /// The node's fully qualified name (`/gnss_ins_node`, `/robot/ins`).
    pub fn fully_qualified_name(&self) -> String {
        if self.namespace == "/" {
            format!("/{}", self.node_name)
        } else {
            format!("{}/{}", self.namespace, self.node_name)
        }
    }
}

/// The usage text of `gnss_ins_node --help`.
pub const USAGE: &str = "\
Usage: gnss_ins_node [--record OUT.mcap] [--ros-args ROS_ARGUMENTS...]

The adaptive GNSS/INS ROS 2 node (speaks DDS itself; honours ROS_DOMAIN_ID and
RMW_IMPLEMENTATION).

Node arguments:
  --record OUT.mcap          also write everything the node publishes to a rosbag2 bag
  -h, --help                 print this text and exit

ROS arguments (after --ros-args, as rcl parses them):
  --params-file FILE         a ROS 2 parameter file; any number, read in order, a later
                             value wins (keys: the node name, its fully qualified name,
                             /**, or wildcards such as /**/gnss_ins_node)
  -p, --param [NODE:]NAME:=VALUE
                             one parameter (YAML value), e.g. -p filter.variant:=ermakf
  -r, --remap [NODE:]FROM:=TO
                             a topic remapping; __node:=NAME and __ns:=/NS rename the node
  --log-level [LOGGER:=]LEVEL
                             debug, info, warn, error or fatal; LOGGER is the node's
                             logger (its name, e.g. gnss_ins_node) or rustdds/ros2_client
  -e, --enclave ENCLAVE      accepted and ignored (no DDS security yet)

Example:
  gnss_ins_node --ros-args --params-file params/defaults.yaml --params-file params/ermakf.yaml \\
      -r __ns:=/vehicle -r imu:=imu/data -p gnss.elevation_mask_deg:=15.0

Every parameter, its unit, range and default: params/defaults.yaml and docs/parameters.md.
";

/// A command line the node does not accept.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ArgsError {
    #[error("unknown argument `{0}` (the node takes `--record OUT.mcap` and `--help`, then ROS arguments: --ros-args --params-file FILE, -p name:=value, -r from:=to, -r __node:=NAME, -r __ns:=/NS, --log-level LEVEL; see --help)")]
    Unknown(String),
    #[error("`{0}` needs a value")]
    MissingValue(String),
    #[error("`{flag} {value}`: expected the form name:=value")]
    NotAssignment { flag: String, value: String },
    #[error("invalid node name `{0}` (letters, digits and `_`, not starting with a digit)")]
    BadNodeName(String),
    #[error("invalid namespace `{0}` (must be absolute, e.g. /robot, with name tokens between the slashes)")]
    BadNamespace(String),
    #[error("invalid topic name `{0}` in a remapping")]
    BadTopicName(String),
    #[error("`{flag} {value}`: invalid parameter name (name tokens joined by `.`, an optional `NODE:` in front)")]
    BadParameterName { flag: String, value: String },
    #[error(transparent)]
    LogLevel(#[from] LogLevelError),
}

fn is_token(s: &str) -> bool {
    s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && s.chars().next().is_some_and(|c| !c.is_ascii_digit())
}

/// True for a ROS node base name.
pub fn is_valid_node_name(name: &str) -> bool {
    is_token(name)
}

/// True for an absolute namespace: `/` or `/a/b` made of name tokens.
pub fn is_valid_namespace(ns: &str) -> bool {
    ns == "/"
        || ns
            .strip_prefix('/')
            .is_some_and(|rest| rest.split('/').all(is_token))
}

/// True for a topic name as a remapping may use: absolute, relative or `~/`-private.
pub fn is_valid_topic_name(name: &str) -> bool {
    let body = name
        .strip_prefix("~/")
        .or_else(|| name.strip_prefix('/'))
        .unwrap_or(name);
    !body.is_empty() && body.split('/').all(is_token)
}

fn split_assignment(flag: &str, value: &str) -> Result<(String, String), ArgsError> {
    match value.split_once(":=") {
        Some((name, v)) if !name.is_empty() => Ok((name.to_owned(), v.to_owned())),
        _ => Err(ArgsError::NotAssignment {
            flag: flag.to_owned(),
            value: value.to_owned(),
        }),
    }
}

/// `NODE:rest` → (Some(NODE), rest) when `rest` follows a single name token and a colon
/// (rcl's node-name prefix of `-p` and `-r` rules); else (None, all).
fn node_prefix(left: &str) -> (Option<String>, &str) {
    match left.split_once(':') {
        Some((node, rest)) if is_token(node) && !rest.is_empty() => (Some(node.to_owned()), rest),
        _ => (None, left),
    }
}

/// A `-p` rule: `[node:]name:=value` with `name` made of name tokens joined by dots.
fn parameter_rule(flag: &str, text: &str) -> Result<ParameterSource, ArgsError> {
    let (left, value) = split_assignment(flag, text)?;
    let (node, name) = node_prefix(&left);
    if !name.split('.').all(is_token) {
        return Err(ArgsError::BadParameterName {
            flag: flag.to_owned(),
            value: text.to_owned(),
        });
    }
    Ok(ParameterSource::Rule {
        node,
        name: name.to_owned(),
        value,
    })
}

/// Flags rcl knows that this node accepts and ignores: (flag, takes a value, why).
const IGNORED_FLAGS: [(&str, bool, &str); 10] = [
    ("--enclave", true, "no DDS security yet"),
    ("-e", true, "no DDS security yet"),
    (
        "--log-file-name",
        true,
        "the node logs to stderr and /rosout only",
    ),
    (
        "--log-config-file",
        true,
        "the node logs to stderr and /rosout only",
    ),
    ("--enable-stdout-logs", false, "stderr logging is always on"),
    (
        "--disable-stdout-logs",
        false,
        "stderr logging is always on",
    ),
    ("--enable-rosout-logs", false, "/rosout is always on"),
    ("--disable-rosout-logs", false, "/rosout is always on"),
    (
        "--enable-external-lib-logs",
        false,
        "there is no external log library",
    ),
    (
        "--disable-external-lib-logs",
        false,
        "there is no external log library",
    ),
];

/// Parses the arguments after the program name, for `gnss_ins_node`.
pub fn parse<I, S>(args: I) -> Result<NodeArgs, ArgsError>
where
    I: IntoIterator<Item = S>,
    S: Into<String>,
{
    parse_as(DEFAULT_NODE_NAME, args)
}

/// Parses the arguments after the program name for a node called `default_node_name`
/// unless renamed (`NODE:` prefixes name the node by it).
pub fn parse_as<I, S>(default_node_name: &str, args: I) -> Result<NodeArgs, ArgsError>
where
    I: IntoIterator<Item = S>,
    S: Into<String>,
{
    let mut out = NodeArgs {
        node_name: default_node_name.to_owned(),
        ..NodeArgs::default()
    };
    // Remappings with their node prefix, filtered once the node name is known.
    let mut remaps: Vec<(Option<String>, String, String)> = Vec::new();
    let mut in_ros_args = false;
    let mut it = args.into_iter().map(Into::into);
    while let Some(arg) = it.next() {
        if arg == "--ros-args" {
            in_ros_args = true;
            continue;
        }
        if !in_ros_args {
            match arg.as_str() {
                "--record" if out.record.is_none() => {
                    let file = it.next().ok_or(ArgsError::MissingValue(arg))?;
                    out.record = Some(PathBuf::from(file));
                }
                "-h" | "--help" => out.help = true,
                // rcl's deprecated form of a remapping, outside --ros-args.
                _ if arg.contains(":=") => {
                    out.ignored.push(format!(
                        "`{arg}`: a remapping outside --ros-args is deprecated; use \
                         --ros-args -r {arg}"
                    ));
                    let (from, to) = split_assignment("-r", &arg)?;
                    let (node, from) = node_prefix(&from);
                    remaps.push((node, from.to_owned(), to));
                }
                _ => return Err(ArgsError::Unknown(arg)),
            }
            continue;
        }
        let mut value_of = |flag: &str| it.next().ok_or(ArgsError::MissingValue(flag.to_owned()));
        match arg.as_str() {
            "--" => in_ros_args = false,
            "--params-file" => {
                let file = value_of(&arg)?;
                out.parameter_sources
                    .push(ParameterSource::File(PathBuf::from(file)));
            }
            "-p" | "--param" => {
                let v = value_of(&arg)?;
                out.parameter_sources.push(parameter_rule(&arg, &v)?);
            }
            "-r" | "--remap" => {
                let v = value_of(&arg)?;
                let (from, to) = split_assignment(&arg, &v)?;
                let (node, from) = node_prefix(&from);
                remaps.push((node, from.to_owned(), to));
            }
            "--log-level" => {
                let v = value_of(&arg)?;
                out.log_levels.push(LogLevelRule::parse(&v)?);
            }
            flag => match IGNORED_FLAGS.iter().find(|(f, _, _)| *f == flag) {
                Some((_, takes_value, why)) => {
                    let shown = if *takes_value {
                        format!("{flag} {}", value_of(flag)?)
                    } else {
                        flag.to_owned()
                    };
                    out.ignored.push(format!("`{shown}` is ignored: {why}"));
                }
                None => return Err(ArgsError::Unknown(arg)),
            },
        }
    }
    resolve_remaps(&mut out, remaps)?;
    Ok(out)
}

/// Applies the remapping rules as rcl does: every rule is checked; the first `__node`
/// (`__name`) and the first `__ns` rule for this node rename it (a `NODE:` prefix must
/// name the node as it is called without renaming); topic rules are kept in order (the
/// first that matches a name wins), those with a prefix only when it is the node's name.
fn resolve_remaps(
    out: &mut NodeArgs,
    rules: Vec<(Option<String>, String, String)>,
) -> Result<(), ArgsError> {
    let original_name = out.node_name.clone();
    let mut renamed = false;
    let mut moved = false;
    let mut topics = Vec::new();
    for (node, from, to) in rules {
        let for_original = node.as_ref().is_none_or(|n| *n == original_name);
        match from.as_str() {
            "__node" | "__name" => {
                if !is_valid_node_name(&to) {
                    return Err(ArgsError::BadNodeName(to));
                }
                if for_original && !renamed {
                    out.node_name = to;
                    renamed = true;
                }
            }
            "__ns" => {
                if !is_valid_namespace(&to) {
                    return Err(ArgsError::BadNamespace(to));
                }
                if for_original && !moved {
                    out.namespace = to;
                    moved = true;
                }
            }
            _ => {
                for name in [&from, &to] {
                    if !is_valid_topic_name(name) {
                        return Err(ArgsError::BadTopicName(name.clone()));
                    }
                }
                topics.push((node, from, to));
            }
        }
    }
    out.remaps = topics
        .into_iter()
        .filter(|(node, _, _)| node.as_ref().is_none_or(|n| *n == out.node_name))
        .map(|(_, from, to)| (from, to))
        .collect();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::log_level::Severity;

    fn p(args: &[&str]) -> Result<NodeArgs, ArgsError> {
        parse(args.iter().copied())
    }

    fn rule(node: Option<&str>, name: &str, value: &str) -> ParameterSource {
        ParameterSource::Rule {
            node: node.map(str::to_owned),
            name: name.to_owned(),
            value: value.to_owned(),
        }
    }

    fn file(path: &str) -> ParameterSource {
        ParameterSource::File(PathBuf::from(path))
    }

    #[test]
    fn empty_command_line_gives_defaults() {
        assert_eq!(p(&[]).unwrap(), NodeArgs::default());
        assert_eq!(p(&["--ros-args"]).unwrap(), NodeArgs::default());
    }

    #[test]
    fn full_ros_command_line() {
        let a = p(&[
            "--ros-args",
            "--params-file",
            "params/defaults.yaml",
            "-p",
            "imu.gyro_bias_deg_per_h:=0.3",
            "--params-file",
            "params/ermakf.yaml",
            "--param",
            "filter.variant:=ermakf",
            "-r",
            "imu:=/sensors/imu",
            "-r",
            "__node:=ins",
            "--ros-args",
            "-r",
            "__ns:=/robot1",
            "--log-level",
            "debug",
            "--log-level",
            "robot1.ins:=WARN",
            "--",
        ])
        .unwrap();
        assert_eq!(
            a.parameter_sources,
            vec![
                file("params/defaults.yaml"),
                rule(None, "imu.gyro_bias_deg_per_h", "0.3"),
                file("params/ermakf.yaml"),
                rule(None, "filter.variant", "ermakf"),
            ]
        );
        assert_eq!(a.remaps, vec![("imu".into(), "/sensors/imu".into())]);
        assert_eq!(a.node_name, "ins");
        assert_eq!(a.namespace, "/robot1");
        assert_eq!(a.fully_qualified_name(), "/robot1/ins");
        assert_eq!(a.log_levels.len(), 2);
        assert_eq!(a.log_levels[1].logger.as_deref(), Some("robot1.ins"));
        assert_eq!(a.log_levels[1].level, Severity::Warn);
    }

    #[test]
    fn node_prefixes_address_one_node() {
        let a = p(&[
            "--ros-args",
            "-p",
            "gnss_ins_node:filter.variant:=iarf",
            "-r",
            "other:imu:=/x",
            "-r",
            "gnss_ins_node:gnss/fix:=/y",
            "-r",
            "other:__node:=z",
        ])
        .unwrap();
        assert_eq!(
            a.parameter_sources,
            vec![rule(Some("gnss_ins_node"), "filter.variant", "iarf")]
        );
        assert_eq!(a.remaps, vec![("gnss/fix".into(), "/y".into())]);
        assert_eq!(a.node_name, DEFAULT_NODE_NAME);
        // As in rcl, the first rename rule wins.
        let a = p(&["--ros-args", "-r", "__node:=a", "-r", "__node:=b"]).unwrap();
        assert_eq!(a.node_name, "a");
    }

    #[test]
    fn record_and_help_come_before_the_ros_args() {
        let a = p(&["--record", "out.mcap", "--ros-args", "-r", "__node:=ins"]).unwrap();
        assert_eq!(a.record, Some(PathBuf::from("out.mcap")));
        assert_eq!(
            p(&["--record"]),
            Err(ArgsError::MissingValue("--record".into()))
        );
        // Once only, and not inside the ROS block.
        assert!(p(&["--record", "a.mcap", "--record", "b.mcap"]).is_err());
        assert!(p(&["--ros-args", "--record", "a.mcap"]).is_err());
        assert!(p(&["--help"]).unwrap().help && p(&["-h"]).unwrap().help);
        assert!(USAGE.contains("--params-file") && USAGE.contains("--log-level"));
    }

    #[test]
    fn value_may_contain_assignment_sign() {
        let a = p(&["--ros-args", "-p", "output.datum_llh_deg_m:=[1, 2, 3]"]).unwrap();
        assert_eq!(
            a.parameter_sources,
            vec![rule(None, "output.datum_llh_deg_m", "[1, 2, 3]")]
        );
        let a = p(&["--ros-args", "-p", "a:=x:=y"]).unwrap();
        assert_eq!(a.parameter_sources, vec![rule(None, "a", "x:=y")]);
    }

    #[test]
    fn unknown_arguments_are_rejected_by_name() {
        assert_eq!(
            p(&["--verbose"]),
            Err(ArgsError::Unknown("--verbose".into()))
        );
        assert_eq!(
            p(&["--ros-args", "--bogus"]),
            Err(ArgsError::Unknown("--bogus".into()))
        );
        // After `--` the ROS block is closed: a plain argument is not ours either.
        assert_eq!(
            p(&["--ros-args", "--", "extra"]),
            Err(ArgsError::Unknown("extra".into()))
        );
        let msg = ArgsError::Unknown("--verbose".into()).to_string();
        assert!(
            msg.contains("--verbose") && msg.contains("--params-file"),
            "{msg}"
        );
    }

    #[test]
    fn flags_rcl_knows_are_accepted_with_a_warning() {
        let a = p(&[
            "--ros-args",
            "--enclave",
            "/secure",
            "-e",
            "/x",
            "--disable-rosout-logs",
            "--log-file-name",
            "f",
        ])
        .unwrap();
        assert_eq!(a.ignored.len(), 4, "{:?}", a.ignored);
        assert!(
            a.ignored[0].contains("--enclave /secure"),
            "{:?}",
            a.ignored
        );
        assert_eq!(
            p(&["--ros-args", "--enclave"]),
            Err(ArgsError::MissingValue("--enclave".into()))
        );
        // rcl's deprecated remapping outside --ros-args.
        let a = p(&["imu:=/sensors/imu"]).unwrap();
        assert_eq!(a.remaps, vec![("imu".into(), "/sensors/imu".into())]);
        assert!(a.ignored[0].contains("deprecated"), "{:?}", a.ignored);
    }

    #[test]
    fn malformed_values_are_rejected() {
        assert_eq!(
            p(&["--ros-args", "-p"]),
            Err(ArgsError::MissingValue("-p".into()))
        );
        assert!(matches!(
            p(&["--ros-args", "-p", "filter.variant=ekf"]),
            Err(ArgsError::NotAssignment { .. })
        ));
        assert!(matches!(
            p(&["--ros-args", "-p", ":=3"]),
            Err(ArgsError::NotAssignment { .. })
        ));
        assert!(matches!(
            p(&["--ros-args", "-p", "filter..variant:=ekf"]),
            Err(ArgsError::BadParameterName { .. })
        ));
        assert_eq!(
            p(&["--ros-args", "-r", "__ns:=robot"]),
            Err(ArgsError::BadNamespace("robot".into()))
        );
        assert_eq!(
            p(&["--ros-args", "-r", "__node:=9lives"]),
            Err(ArgsError::BadNodeName("9lives".into()))
        );
        assert_eq!(
            p(&["--ros-args", "-r", "imu:=a//b"]),
            Err(ArgsError::BadTopicName("a//b".into()))
        );
        assert!(matches!(
            p(&["--ros-args", "--log-level", "loud"]),
            Err(ArgsError::LogLevel(_))
        ));
    }
}
