//! The node's configuration from its command line: the params file (through the core's
//! loader) and the `-p` overrides.

use crate::config::{Config, ConfigError};
pub use crate::ros::adapter::OutputFrames;
use crate::ros::args::{params_key_matches, NodeArgs};

/// Why the node's configuration could not be built.
#[derive(Debug, thiserror::Error)]
pub enum ParamsError {
    #[error("cannot read params file {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("params file {path}: top-level key `{key}` does not address node `{fqn}` (use `/**`, the node name or its fully qualified name)")]
    WrongNode {
        path: String,
        key: String,
        fqn: String,
    },
    #[error(transparent)]
    Config(Box<ConfigError>),
    #[error("{name}: {reason}, not `{value}`")]
    NodeParameter {
        name: &'static str,
        value: String,
        reason: &'static str,
    },
    #[error("-p {name}:={value}: {source}")]
    Override {
        name: String,
        value: String,
        source: Box<ConfigError>,
    },
}

/// The standard ROS parameter every launch file may set: the node's time (the
/// /diagnostics and /rosout stamps, the time since the last input) follows `/clock`.
///
/// It is the node's, not the core's: the filter runs on the stamps of its inputs either
/// way (so a bag replayed with `--clock` is processed on the bag's time) and its outputs
/// carry those stamps.
pub const USE_SIM_TIME: &str = "use_sim_time";

/// Frame of the odometry pose and the TF parent (REP-105 `map`: ENU at the datum).
pub const MAP_FRAME: &str = "map_frame";
/// Frame of the vehicle body (FLU), the odometry's child frame and NavSatFix's frame.
pub const BASE_FRAME: &str = "base_frame";
/// Whether `map_frame` → `base_frame` is published on `/tf` with each Odometry.
pub const PUBLISH_TF: &str = "publish_tf";
/// Depth (messages) of the input subscriptions' and the publishers' history.
pub const QUEUE_DEPTH: &str = "queue_depth";
/// The node's own parameters, outside the core configuration.
pub const NODE_PARAMETERS: [&str; 5] =
    [USE_SIM_TIME, MAP_FRAME, BASE_FRAME, PUBLISH_TF, QUEUE_DEPTH];

/// Default of [`QUEUE_DEPTH`].
///
/// Choice: 200 holds one second of a 200 Hz IMU, so a short stall of the node loses
/// nothing; GNSS (1–10 Hz) needs far less but a common depth keeps things simple.
pub const DEFAULT_QUEUE_DEPTH: usize = 200;
/// Largest accepted [`QUEUE_DEPTH`] (a minute of a 1 kHz IMU).
pub const MAX_QUEUE_DEPTH: usize = 60_000;

/// What the command line configures: the core's configuration and the node's own
/// parameters.
#[derive(Debug, Clone)]
pub struct NodeParams {
    /// The engine's configuration.
    pub config: Config,
    /// Whether the node's time follows `/clock`.
    pub use_sim_time: bool,
    /// Output frames and TF.
    pub frames: OutputFrames,
    /// History depth of the subscriptions and publishers.
    pub queue_depth: usize,
}

/// The value of the node parameter `name` from the params file and the `-p` overrides (the
/// last one wins), as YAML; None when neither sets it.
fn node_value(
    args: &NodeArgs,
    params_text: Option<&str>,
    name: &'static str,
) -> Result<Option<serde_yaml::Value>, ParamsError> {
    let mut value = None;
    let document = params_text.and_then(|t| serde_yaml::from_str::<serde_yaml::Value>(t).ok());
    if let Some(serde_yaml::Value::Mapping(nodes)) = document {
        for (_, node) in nodes {
            if let Some(v) = node.get("ros__parameters").and_then(|p| p.get(name)) {
                value = Some(v.clone());
            }
        }
    }
    for (_, v) in args.parameters.iter().filter(|(n, _)| n == name) {
        let parsed = serde_yaml::from_str::<serde_yaml::Value>(v).map_err(|_| {
            ParamsError::NodeParameter {
                name,
                value: v.clone(),
                reason: "not a YAML value",
            }
        })?;
        value = Some(parsed);
    }
    Ok(value)
}

fn node_bool(
    args: &NodeArgs,
    params_text: Option<&str>,
    name: &'static str,
    default: bool,
) -> Result<bool, ParamsError> {
    match node_value(args, params_text, name)? {
        None => Ok(default),
        Some(v) => v.as_bool().ok_or_else(|| ParamsError::NodeParameter {
            name,
            value: shown(&v),
            reason: "must be true or false",
        }),
    }
}

/// A frame id: a non-empty string without spaces.
fn node_frame(
    args: &NodeArgs,
    params_text: Option<&str>,
    name: &'static str,
    default: &str,
) -> Result<String, ParamsError> {
    match node_value(args, params_text, name)? {
        None => Ok(default.to_owned()),
        Some(serde_yaml::Value::String(s)) if !s.is_empty() && !s.contains(char::is_whitespace) => {
            Ok(s)
        }
        Some(v) => Err(ParamsError::NodeParameter {
            name,
            value: shown(&v),
            reason: "must be a frame id (a non-empty string without spaces)",
        }),
    }
}

/// A history depth: an integer in 1..=[`MAX_QUEUE_DEPTH`].
fn node_depth(args: &NodeArgs, params_text: Option<&str>) -> Result<usize, ParamsError> {
    match node_value(args, params_text, QUEUE_DEPTH)? {
        None => Ok(DEFAULT_QUEUE_DEPTH),
        Some(v) => v
            .as_u64()
            .and_then(|d| usize::try_from(d).ok())
            .filter(|d| (1..=MAX_QUEUE_DEPTH).contains(d))
            .ok_or_else(|| ParamsError::NodeParameter {
                name: QUEUE_DEPTH,
                value: shown(&v),
                reason: "must be an integer from 1 to 60000",
            }),
    }
}

fn shown(v: &serde_yaml::Value) -> String {
    serde_yaml::to_string(v)
        .map(|t| t.trim_end().to_owned())
        .unwrap_or_default()
}

fn frames_from(args: &NodeArgs, params_text: Option<&str>) -> Result<OutputFrames, ParamsError> {
    let defaults = OutputFrames::default();
    let frames = OutputFrames {
        map_frame: node_frame(args, params_text, MAP_FRAME, &defaults.map_frame)?,
        base_frame: node_frame(args, params_text, BASE_FRAME, &defaults.base_frame)?,
        publish_tf: node_bool(args, params_text, PUBLISH_TF, defaults.publish_tf)?,
    };
    if frames.map_frame == frames.base_frame {
        return Err(ParamsError::NodeParameter {
            name: BASE_FRAME,
            value: frames.base_frame,
            reason: "must differ from map_frame",
        });
    }
    Ok(frames)
}

/// The node's parameters of `args` where `params_text` is the content of
/// `args.params_file` (None: no file).
pub fn node_params_from(
    args: &NodeArgs,
    params_text: Option<&str>,
) -> Result<NodeParams, ParamsError> {
    Ok(NodeParams {
        config: config_from(args, params_text)?,
        use_sim_time: node_bool(args, params_text, USE_SIM_TIME, false)?,
        frames: frames_from(args, params_text)?,
        queue_depth: node_depth(args, params_text)?,
    })
}

/// The configuration of `args` where `params_text` is the content of `args.params_file`
/// (None: no file; the defaults of `params/ekf.yaml` apply).
pub fn config_from(args: &NodeArgs, params_text: Option<&str>) -> Result<Config, ParamsError> {
    let origin = args
        .params_file
        .as_ref()
        .map_or_else(String::new, |p| p.display().to_string());
    let mut config = match params_text {
        Some(text) => {
            check_node_key(text, &origin, args)?;
            let text = without_node_parameters(text);
            Config::from_yaml_str(&text, &origin).map_err(|e| ParamsError::Config(Box::new(e)))?
        }
        None => Config::default(),
    };
    let core = |n: &String| !NODE_PARAMETERS.contains(&n.as_str());
    for (name, value) in args.parameters.iter().filter(|(n, _)| core(n)) {
        config
            .set_parameter(name, value)
            .map_err(|source| ParamsError::Override {
                name: name.clone(),
                value: value.clone(),
                source: Box::new(source),
            })?;
    }
    Ok(config)
}

/// `text` without the [`NODE_PARAMETERS`] under its node's `ros__parameters` (unchanged,
/// keeping the line numbers of the loader's errors, when there is none).
fn without_node_parameters(text: &str) -> std::borrow::Cow<'_, str> {
    use serde_yaml::Value;
    let Ok(mut document) = serde_yaml::from_str::<Value>(text) else {
        return text.into();
    };
    let mut removed = false;
    if let Value::Mapping(nodes) = &mut document {
        for (_, node) in nodes.iter_mut() {
            if let Some(Value::Mapping(parameters)) = node.get_mut("ros__parameters") {
                for name in NODE_PARAMETERS {
                    removed |= parameters.remove(name).is_some();
                }
            }
        }
    }
    match (removed, serde_yaml::to_string(&document)) {
        (true, Ok(stripped)) => stripped.into(),
        _ => text.into(),
    }
}

/// Rejects a file whose single top-level key names another node. Files of any other shape
/// are left to the core's loader, whose errors describe the expected layout.
fn check_node_key(text: &str, origin: &str, args: &NodeArgs) -> Result<(), ParamsError> {
    let Ok(serde_yaml::Value::Mapping(top)) = serde_yaml::from_str(text) else {
        return Ok(());
    };
    for key in top.keys().filter_map(|k| k.as_str()) {
        if !params_key_matches(key, &args.namespace, &args.node_name) {
            let fqn = if args.namespace == "/" {
                format!("/{}", args.node_name)
            } else {
                format!("{}/{}", args.namespace, args.node_name)
            };
            return Err(ParamsError::WrongNode {
                path: origin.to_owned(),
                key: key.to_owned(),
                fqn,
            });
        }
    }
    Ok(())
}

/// Reads `args.params_file` (if any) and builds the node's parameters.
pub fn load(args: &NodeArgs) -> Result<NodeParams, ParamsError> {
    let text = match &args.params_file {
        Some(path) => Some(
            std::fs::read_to_string(path).map_err(|source| ParamsError::Read {
                path: path.display().to_string(),
                source,
            })?,
        ),
        None => None,
    };
    node_params_from(args, text.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::args::parse;

    const FILE: &str = "gnss_ins_node:\n  ros__parameters:\n    filter:\n      variant: ermakf\n";

    fn args(extra: &[&str]) -> NodeArgs {
        let mut all = vec!["--ros-args", "--params-file", "p.yaml"];
        all.extend_from_slice(extra);
        parse(all.iter().copied()).unwrap()
    }

    #[test]
    fn file_then_overrides() {
        let c = config_from(&args(&[]), Some(FILE)).unwrap();
        assert_eq!(c.filter.variant.as_str(), "ermakf");
        let c = config_from(&args(&["-p", "filter.variant:=ekf"]), Some(FILE)).unwrap();
        assert_eq!(c.filter.variant.as_str(), "ekf");
    }

    #[test]
    fn wildcard_and_qualified_keys_are_accepted() {
        let any = FILE.replace("gnss_ins_node:", "/**:");
        assert!(config_from(&args(&[]), Some(&any)).is_ok());
        let fq = FILE.replace("gnss_ins_node:", "/r1/ins:");
        assert!(config_from(&args(&["-r", "__ns:=/r1", "-r", "__node:=ins"]), Some(&fq)).is_ok());
    }

    #[test]
    fn file_for_another_node_is_rejected() {
        let e = config_from(&args(&["-r", "__node:=ins"]), Some(FILE)).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, ParamsError::WrongNode { .. }), "{text}");
        assert!(
            text.contains("gnss_ins_node") && text.contains("/ins"),
            "{text}"
        );
    }

    #[test]
    fn bad_override_names_the_parameter() {
        let e = config_from(&args(&["-p", "filter.no_such_key:=1"]), Some(FILE)).unwrap_err();
        assert!(matches!(e, ParamsError::Override { .. }), "{e}");
        assert!(e.to_string().contains("filter.no_such_key"), "{e}");
    }

    #[test]
    fn use_sim_time_is_the_nodes_not_the_cores() {
        let file = FILE.replace(
            "ros__parameters:\n",
            "ros__parameters:\n    use_sim_time: true\n",
        );
        assert!(
            Config::from_yaml_str(&file, "p.yaml").is_err(),
            "the core's loader alone refuses the key"
        );
        let c = config_from(&args(&["-p", "use_sim_time:=true"]), Some(&file)).unwrap();
        assert_eq!(c.filter.variant.as_str(), "ermakf");
        let p = node_params_from(&args(&[]), Some(&file)).unwrap();
        assert!(p.use_sim_time, "from the file");
        let p = node_params_from(&args(&["-p", "use_sim_time:=false"]), Some(&file)).unwrap();
        assert!(!p.use_sim_time, "-p wins over the file");
        assert!(
            !node_params_from(&args(&[]), Some(FILE))
                .unwrap()
                .use_sim_time
        );
        let e = node_params_from(&args(&["-p", "use_sim_time:=maybe"]), Some(FILE));
        assert!(matches!(e, Err(ParamsError::NodeParameter { .. })));
        // Files without it keep the loader's line numbers in errors.
        let bad = FILE.replace("ermakf", "no_such_variant");
        let e = config_from(&args(&[]), Some(&bad)).unwrap_err().to_string();
        assert!(e.contains("p.yaml"), "{e}");
    }

    #[test]
    fn every_shipped_preset_loads() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("params");
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let a = parse(["--ros-args", "--params-file", path.to_str().unwrap()]).unwrap();
            config_from(&a, Some(&text)).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
    }

    #[test]
    fn queue_depth_is_the_nodes_and_checked() {
        let p = node_params_from(&args(&[]), None).unwrap();
        assert_eq!(p.queue_depth, DEFAULT_QUEUE_DEPTH);
        let p = node_params_from(&args(&["-p", "queue_depth:=1000"]), None).unwrap();
        assert_eq!(p.queue_depth, 1000);
        for bad in ["0", "-3", "2.5", "deep", "60001"] {
            let set = format!("queue_depth:={bad}");
            assert!(
                node_params_from(&args(&["-p", &set]), None).is_err(),
                "{bad} accepted"
            );
        }
    }

    #[test]
    fn frames_and_publish_tf_are_the_nodes() {
        let p = node_params_from(&args(&[]), Some(FILE)).unwrap();
        assert_eq!(p.frames, OutputFrames::default());
        assert_eq!(p.frames.map_frame, "map");
        assert_eq!(p.frames.base_frame, "base_link");
        assert!(!p.frames.publish_tf);
        let file = FILE.replace(
            "ros__parameters:\n",
            "ros__parameters:\n    map_frame: odom_enu\n    publish_tf: true\n",
        );
        let p = node_params_from(&args(&["-p", "base_frame:=imu_link"]), Some(&file)).unwrap();
        assert_eq!(p.config.filter.variant.as_str(), "ermakf");
        assert_eq!(p.frames.map_frame, "odom_enu");
        assert_eq!(p.frames.base_frame, "imu_link");
        assert!(p.frames.publish_tf);
        let p = node_params_from(&args(&["-p", "publish_tf:=false"]), Some(&file)).unwrap();
        assert!(!p.frames.publish_tf, "-p wins over the file");
        for bad in [
            "publish_tf:=yes please",
            "base_frame:=''",
            "map_frame:=12",
            "base_frame:=map",
        ] {
            let e = node_params_from(&args(&["-p", bad]), Some(FILE));
            assert!(
                matches!(e, Err(ParamsError::NodeParameter { .. })),
                "{bad}: {e:?}"
            );
        }
    }
}
