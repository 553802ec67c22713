//! The node's command line: the subset of the ROS 2 `--ros-args` syntax it understands,
//! parsed without side effects (no file is read here).
//!
//! Understood after `--ros-args` (which may appear several times; `--` ends a block):
//! `--params-file FILE`, `-p|--param name:=value`, `-r|--remap from:=to` (topic names,
//! plus the special `__node:=NAME` and `__ns:=/NS`), `--log-level LEVEL`.
//! Before `--ros-args`, the node's own argument: `--record OUT.mcap` (write everything the
//! node publishes to a rosbag2 MCAP bag). Anything else is an error that names the
//! argument.

use std::path::PathBuf;

/// The default node name (the params files of `params/` are keyed by it).
pub const DEFAULT_NODE_NAME: &str = "gnss_ins_node";

/// What the command line asks for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeArgs {
    /// Node base name (`-r __node:=NAME`, default [`DEFAULT_NODE_NAME`]).
    pub node_name: String,
    /// Absolute node namespace (`-r __ns:=/NS`, default `/`).
    pub namespace: String,
    /// The parameter file (`--params-file`), if any.
    pub params_file: Option<PathBuf>,
    /// Parameter overrides (`-p name:=value`) in command-line order; values are YAML text.
    pub parameters: Vec<(String, String)>,
    /// Topic remappings (`-r from:=to`) in command-line order.
    pub remaps: Vec<(String, String)>,
    /// `--log-level` value, if given.
    pub log_level: Option<String>,
    /// `--record OUT.mcap`: the bag that receives every message the node publishes.
    pub record: Option<PathBuf>,
}

impl Default for NodeArgs {
    fn default() -> Self {
        Self {
            node_name: DEFAULT_NODE_NAME.to_owned(),
            namespace: "/".to_owned(),
            params_file: None,
            parameters: Vec::new(),
            remaps: Vec::new(),
            log_level: None,
            record: None,
        }
    }
}

/// A command line the node does not accept.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ArgsError {
    #[error("unknown argument `{0}` (the node takes `--record OUT.mcap`, then ROS arguments: --ros-args --params-file FILE, -p name:=value, -r from:=to, -r __node:=NAME, -r __ns:=/NS, --log-level LEVEL)")]
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
    #[error("only one --params-file is supported (got `{first}` and `{second}`)")]
    SecondParamsFile { first: String, second: String },
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

/// Parses the arguments after the program name.
pub fn parse<I, S>(args: I) -> Result<NodeArgs, ArgsError>
where
    I: IntoIterator<Item = S>,
    S: Into<String>,
{
    let mut out = NodeArgs::default();
    let mut in_ros_args = false;
    let mut it = args.into_iter().map(Into::into);
    while let Some(arg) = it.next() {
        if arg == "--ros-args" {
            in_ros_args = true;
            continue;
        }
        if !in_ros_args {
            if arg == "--record" && out.record.is_none() {
                let file = it.next().ok_or(ArgsError::MissingValue(arg))?;
                out.record = Some(PathBuf::from(file));
                continue;
            }
            return Err(ArgsError::Unknown(arg));
        }
        let mut value_of = |flag: &str| it.next().ok_or(ArgsError::MissingValue(flag.to_owned()));
        match arg.as_str() {
            "--" => in_ros_args = false,
            "--params-file" => {
                let file = value_of(&arg)?;
                if let Some(first) = &out.params_file {
                    return Err(ArgsError::SecondParamsFile {
                        first: first.display().to_string(),
                        second: file,
                    });
                }
                out.params_file = Some(PathBuf::from(file));
            }
            "-p" | "--param" => {
                let v = value_of(&arg)?;
                out.parameters.push(split_assignment(&arg, &v)?);
            }
            "-r" | "--remap" => {
                let v = value_of(&arg)?;
                let (from, to) = split_assignment(&arg, &v)?;
                match from.as_str() {
                    "__node" | "__name" => {
                        if !is_valid_node_name(&to) {
                            return Err(ArgsError::BadNodeName(to));
                        }
                        out.node_name = to;
                    }
                    "__ns" => {
                        if !is_valid_namespace(&to) {
                            return Err(ArgsError::BadNamespace(to));
                        }
                        out.namespace = to;
                    }
                    _ => {
                        for name in [&from, &to] {
                            if !is_valid_topic_name(name) {
                                return Err(ArgsError::BadTopicName(name.clone()));
                            }
                        }
                        out.remaps.push((from, to));
                    }
                }
            }
            "--log-level" => out.log_level = Some(value_of(&arg)?),
            _ => return Err(ArgsError::Unknown(arg)),
        }
    }
    Ok(out)
}

/// True when a params file's top-level key `key` addresses the node `name` in namespace
/// `ns`: `/**`, the base name, or the fully qualified name (with or without leading `/`).
pub fn params_key_matches(key: &str, ns: &str, name: &str) -> bool {
    let fully_qualified = if ns == "/" {
        format!("/{name}")
    } else {
        format!("{ns}/{name}")
    };
    key == "/**" || key == name || key == fully_qualified || Some(key) == fully_qualified.get(1..)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(args: &[&str]) -> Result<NodeArgs, ArgsError> {
        parse(args.iter().copied())
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
            "params/ekf.yaml",
            "-p",
            "imu.gyro_bias_deg_per_h:=0.3",
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
            "--",
        ])
        .unwrap();
        assert_eq!(a.params_file, Some(PathBuf::from("params/ekf.yaml")));
        assert_eq!(
            a.parameters,
            vec![
                ("imu.gyro_bias_deg_per_h".into(), "0.3".into()),
                ("filter.variant".into(), "ermakf".into())
            ]
        );
        assert_eq!(a.remaps, vec![("imu".into(), "/sensors/imu".into())]);
        assert_eq!(a.node_name, "ins");
        assert_eq!(a.namespace, "/robot1");
        assert_eq!(a.log_level.as_deref(), Some("debug"));
    }

    #[test]
    fn record_comes_before_the_ros_args() {
        let a = p(&["--record", "out.mcap", "--ros-args", "-r", "__node:=ins"]).unwrap();
        assert_eq!(a.record, Some(PathBuf::from("out.mcap")));
        assert_eq!(
            p(&["--record"]),
            Err(ArgsError::MissingValue("--record".into()))
        );
        // Once only, and not inside the ROS block.
        assert!(p(&["--record", "a.mcap", "--record", "b.mcap"]).is_err());
        assert!(p(&["--ros-args", "--record", "a.mcap"]).is_err());
    }

    #[test]
    fn value_may_contain_assignment_sign() {
        let a = p(&["--ros-args", "-p", "output.datum_llh_deg_m:=[1, 2, 3]"]).unwrap();
        assert_eq!(a.parameters[0].1, "[1, 2, 3]");
    }

    #[test]
    fn unknown_arguments_are_rejected_by_name() {
        assert_eq!(
            p(&["--verbose"]),
            Err(ArgsError::Unknown("--verbose".into()))
        );
        assert_eq!(
            p(&["--ros-args", "--enclave", "x"]),
            Err(ArgsError::Unknown("--enclave".into()))
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
            p(&["--ros-args", "--params-file", "a", "--params-file", "b"]),
            Err(ArgsError::SecondParamsFile { .. })
        ));
    }

    #[test]
    fn params_file_keys() {
        assert!(params_key_matches("/**", "/", "gnss_ins_node"));
        assert!(params_key_matches("gnss_ins_node", "/", "gnss_ins_node"));
        assert!(params_key_matches("/gnss_ins_node", "/", "gnss_ins_node"));
        assert!(params_key_matches("/r1/ins", "/r1", "ins"));
        assert!(params_key_matches("r1/ins", "/r1", "ins"));
        assert!(!params_key_matches("gnss_ins_node", "/", "ins"));
        assert!(!params_key_matches("/r2/ins", "/r1", "ins"));
        assert!(!params_key_matches("/*", "/", "ins"));
    }
}
