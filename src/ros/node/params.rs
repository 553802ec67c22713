//! The node's configuration from its command line: the params file (through the core's
//! loader) and the `-p` overrides.

use crate::config::{Config, ConfigError};
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
    #[error("use_sim_time must be true or false, not `{0}`")]
    SimTime(String),
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

/// What the command line configures: the core's configuration and the node's own
/// `use_sim_time`.
#[derive(Debug, Clone)]
pub struct NodeParams {
    /// The engine's configuration.
    pub config: Config,
    /// Whether the node's time follows `/clock`.
    pub use_sim_time: bool,
}

/// The `use_sim_time` of the params file and the `-p` overrides (the last one wins;
/// default false).
fn use_sim_time_from(args: &NodeArgs, params_text: Option<&str>) -> Result<bool, ParamsError> {
    let mut value = false;
    let document = params_text.and_then(|t| serde_yaml::from_str::<serde_yaml::Value>(t).ok());
    if let Some(serde_yaml::Value::Mapping(nodes)) = document {
        for (_, node) in nodes {
            if let Some(v) = node
                .get("ros__parameters")
                .and_then(|p| p.get(USE_SIM_TIME))
            {
                value = v
                    .as_bool()
                    .ok_or_else(|| ParamsError::SimTime(format!("{v:?}")))?;
            }
        }
    }
    for (_, v) in args.parameters.iter().filter(|(n, _)| n == USE_SIM_TIME) {
        value = serde_yaml::from_str::<bool>(v).map_err(|_| ParamsError::SimTime(v.clone()))?;
    }
    Ok(value)
}

/// The node's parameters of `args` where `params_text` is the content of
/// `args.params_file` (None: no file).
pub fn node_params_from(
    args: &NodeArgs,
    params_text: Option<&str>,
) -> Result<NodeParams, ParamsError> {
    Ok(NodeParams {
        config: config_from(args, params_text)?,
        use_sim_time: use_sim_time_from(args, params_text)?,
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
            let text = without_use_sim_time(text);
            Config::from_yaml_str(&text, &origin).map_err(|e| ParamsError::Config(Box::new(e)))?
        }
        None => Config::default(),
    };
    for (name, value) in args.parameters.iter().filter(|(n, _)| n != USE_SIM_TIME) {
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

/// `text` without a `use_sim_time` entry under its node's `ros__parameters` (unchanged,
/// keeping the line numbers of the loader's errors, when there is none).
fn without_use_sim_time(text: &str) -> std::borrow::Cow<'_, str> {
    use serde_yaml::Value;
    let Ok(mut document) = serde_yaml::from_str::<Value>(text) else {
        return text.into();
    };
    let mut removed = false;
    if let Value::Mapping(nodes) = &mut document {
        for (_, node) in nodes.iter_mut() {
            if let Some(Value::Mapping(parameters)) = node.get_mut("ros__parameters") {
                removed |= parameters.remove(USE_SIM_TIME).is_some();
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
        assert!(matches!(e, Err(ParamsError::SimTime(_))));
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
}
