//! The node's parameters from its command line: the parameter files and `-p` rules,
//! resolved for the node as rclcpp resolves them ([`ParameterOverrides`]), split into the
//! core's configuration and the node's own parameters (declared here). `replay` and
//! `compare` read their `--params` files the same way ([`config_from_files`]).

use std::io::Read;
use std::path::{Path, PathBuf};

use serde_yaml::Value;

use crate::config::{manual::Row, Assignment, Config, ConfigError, Kind, MAX_FILE_BYTES};
pub use crate::ros::adapter::{OutputFrames, TfMode};
use crate::ros::args::{NodeArgs, ParameterSource, DEFAULT_NODE_NAME};
use crate::ros::param_overrides::{node_matches, ParameterOverrides};

/// Why the node's configuration could not be built.
#[derive(Debug, thiserror::Error)]
pub enum ParamsError {
    #[error("cannot read params file {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("params file {path}: top-level key `{key}` does not address node `{fqn}` (use `/**`, the node name, its fully qualified name or a wildcard such as `/**/{name}`)")]
    WrongNode {
        path: String,
        key: String,
        fqn: String,
        name: String,
    },
    #[error(transparent)]
    Config(Box<ConfigError>),
    #[error("{origin}: parameter `{name}` = {value}: {reason}")]
    NodeParameter {
        origin: String,
        name: &'static str,
        value: String,
        reason: &'static str,
    },
}

impl From<ConfigError> for ParamsError {
    fn from(e: ConfigError) -> Self {
        Self::Config(Box::new(e))
    }
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
/// Parent of `base_frame` in the base controller's `/tf` (REP-105 `odom`), for
/// [`TF_MODE`] `map_to_odom`.
pub const ODOM_FRAME: &str = "odom_frame";
/// Whether a TF is published on `/tf` with each Odometry (which one: [`TF_MODE`]).
pub const PUBLISH_TF: &str = "publish_tf";
/// Which TF is published with `publish_tf` ([`TfMode`]).
pub const TF_MODE: &str = "tf_mode";
/// Depth (messages) of the input subscriptions' and the publishers' history.
pub const QUEUE_DEPTH: &str = "queue_depth";
/// The `header.frame_id` of the IMU; empty: learnt from the stream.
pub const IMU_FRAME: &str = "imu_frame";

/// Default of [`QUEUE_DEPTH`].
///
/// Choice: 200 holds one second of a 200 Hz IMU, so a short stall of the node loses
/// nothing; GNSS (1–10 Hz) needs far less but a common depth keeps things simple.
pub const DEFAULT_QUEUE_DEPTH: usize = 200;
/// Largest accepted [`QUEUE_DEPTH`] (a minute of a 1 kHz IMU).
pub const MAX_QUEUE_DEPTH: usize = 60_000;

/// One of the node's own parameters (outside the core configuration): its declaration
/// for the parameter services and the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeParameter {
    pub name: &'static str,
    pub kind: Kind,
    /// Default as YAML text.
    pub default: &'static str,
    /// Valid values, as the manual states them.
    pub range: &'static str,
    /// Whether it can change while the node runs.
    pub runtime: bool,
    pub doc: &'static str,
}

/// [`USE_SIM_TIME`], a parameter of both nodes.
pub const USE_SIM_TIME_PARAMETER: NodeParameter = NodeParameter {
    name: USE_SIM_TIME,
    kind: Kind::Bool,
    default: "false",
    range: "true or false",
    runtime: true,
    doc: "The node's time (diagnostics and rosout stamps, input ages) follows /clock.",
};

/// [`QUEUE_DEPTH`], a parameter of both nodes.
pub const QUEUE_DEPTH_PARAMETER: NodeParameter = NodeParameter {
    name: QUEUE_DEPTH,
    kind: Kind::Integer,
    default: "200",
    range: "an integer in [1, 60000]",
    runtime: false,
    doc: "History depth (messages) of the input subscriptions and the publishers.",
};

/// The node's own parameters.
///
/// Choice: the frames, the TF switch and mode and the queue depth are fixed at start
/// (read-only through the parameter services): a TF tree whose frames change while it
/// runs would break its listeners, and the DDS entities are created with the depth.
///
/// Choice: `publish_tf` keeps its meaning (false, the default, publishes no TF) and
/// `tf_mode` says which TF it publishes, `map_to_base_link` by default as before, so
/// existing files and launch arguments behave as they did; `tf_mode: none` is a second
/// way to switch the TF off, for a launch file that sets the mode alone.
pub const NODE_PARAMETERS: [NodeParameter; 8] = [
    USE_SIM_TIME_PARAMETER,
    NodeParameter {
        name: MAP_FRAME,
        kind: Kind::Text,
        default: "map",
        range: "a frame id (non-empty, no spaces), not base_frame",
        runtime: false,
        doc: "Parent frame of odometry and /tf: ENU at the datum (REP-105 map).",
    },
    NodeParameter {
        name: BASE_FRAME,
        kind: Kind::Text,
        default: "base_link",
        range: "a frame id (non-empty, no spaces), not map_frame",
        runtime: false,
        doc: "Child frame of odometry and /tf, frame of fix: the vehicle body (FLU).",
    },
    NodeParameter {
        name: ODOM_FRAME,
        kind: Kind::Text,
        default: "odom",
        range: "a frame id (non-empty, no spaces), not map_frame or base_frame",
        runtime: false,
        doc: "With tf_mode map_to_odom: the parent of base_frame that the base \
              controller publishes on /tf (REP-105 odom).",
    },
    NodeParameter {
        name: PUBLISH_TF,
        kind: Kind::Bool,
        default: "false",
        range: "true or false",
        runtime: false,
        doc: "Publish the TF of tf_mode on /tf with each odometry.",
    },
    NodeParameter {
        name: TF_MODE,
        kind: Kind::Text,
        default: "map_to_base_link",
        range: "map_to_base_link, map_to_odom or none",
        runtime: false,
        doc: "The TF published with publish_tf. map_to_base_link: map_frame -> \
              base_frame, the fused pose. map_to_odom: map_frame -> odom_frame, so that \
              it chained with the base controller's odom_frame -> base_frame (heard on \
              /tf at the odometry stamp) gives the fused pose; none until that was heard \
              (counted on /diagnostics). none: no TF. See docs/tf.md.",
    },
    QUEUE_DEPTH_PARAMETER,
    NodeParameter {
        name: IMU_FRAME,
        kind: Kind::Text,
        default: "''",
        range: "empty, or a frame id (no spaces)",
        runtime: false,
        doc: "The IMU's header.frame_id: samples from any other frame are dropped and \
              counted. Empty: the first frame is followed, and another one that keeps \
              arriving once it went silent (a stray publisher cannot lock out the IMU).",
    },
];

impl NodeParameter {
    /// The node parameter called `name`.
    pub fn named(name: &str) -> Option<&'static NodeParameter> {
        Self::named_in(&NODE_PARAMETERS, name)
    }

    /// The parameter of `table` called `name`.
    pub fn named_in(table: &'static [NodeParameter], name: &str) -> Option<&'static NodeParameter> {
        table.iter().find(|p| p.name == name)
    }

    /// The description the parameter services give.
    pub fn description(&self) -> String {
        format!(
            "{} Range: {}. Default: {}",
            self.doc, self.range, self.default
        )
    }

    /// The row of the reference (`docs/parameters.md`).
    pub fn row(&self) -> Row {
        Row {
            name: self.name.to_owned(),
            kind: self.kind.name(),
            unit: String::new(),
            default: self.default.to_owned(),
            range: self.range.to_owned(),
            runtime: self.runtime,
            doc: self.doc.to_owned(),
        }
    }
}

/// `docs/parameters.md` up to `gnss_ins_ubx_node`'s section: the core's parameters and
/// the node's.
pub fn reference() -> String {
    let rows: Vec<Row> = NODE_PARAMETERS.iter().map(NodeParameter::row).collect();
    crate::config::manual::reference(&rows)
}

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
    /// The IMU's frame when configured (else learnt from the stream).
    pub imu_frame: Option<String>,
}

/// The node's parameters from the values resolved for it.
pub fn node_params_from(values: &[Assignment]) -> Result<NodeParams, ParamsError> {
    let (own, core): (Vec<&Assignment>, Vec<&Assignment>) = values
        .iter()
        .partition(|a| NodeParameter::named(&a.name).is_some());
    let config = Config::default().with(core.into_iter().cloned())?;
    let value = |name: &str| own.iter().find(|a| a.name == name).copied();
    let defaults = OutputFrames::default();
    let frames = OutputFrames {
        map_frame: frame(value(MAP_FRAME), MAP_FRAME, &defaults.map_frame)?,
        base_frame: frame(value(BASE_FRAME), BASE_FRAME, &defaults.base_frame)?,
        odom_frame: frame(value(ODOM_FRAME), ODOM_FRAME, &defaults.odom_frame)?,
        publish_tf: boolean(value(PUBLISH_TF), PUBLISH_TF, defaults.publish_tf)?,
        tf_mode: tf_mode(value(TF_MODE))?,
    };
    let clash =
        |name: &'static str, frame: &str, reason: &'static str| ParamsError::NodeParameter {
            origin: value(name)
                .or(value(MAP_FRAME))
                .map_or_else(String::new, |a| a.origin.clone()),
            name,
            value: frame.to_owned(),
            reason,
        };
    if frames.map_frame == frames.base_frame {
        return Err(clash(
            BASE_FRAME,
            &frames.base_frame,
            "must differ from map_frame",
        ));
    }
    // The odom frame is used only in map_to_odom: a robot without a map that names its
    // fused frame `odom` (map_frame: odom) is not refused for the unused default.
    let odom_used = frames.published_tf() == TfMode::MapToOdom;
    if odom_used
        && (frames.odom_frame == frames.map_frame || frames.odom_frame == frames.base_frame)
    {
        return Err(clash(
            ODOM_FRAME,
            &frames.odom_frame,
            "must differ from map_frame and base_frame",
        ));
    }
    Ok(NodeParams {
        config,
        use_sim_time: boolean(value(USE_SIM_TIME), USE_SIM_TIME, false)?,
        frames,
        queue_depth: depth(value(QUEUE_DEPTH))?,
        imu_frame: optional_frame(value(IMU_FRAME), IMU_FRAME)?,
    })
}

pub(crate) fn refused(a: &Assignment, name: &'static str, reason: &'static str) -> ParamsError {
    ParamsError::NodeParameter {
        origin: a.origin.clone(),
        name,
        value: ConfigError::shortened(&crate::config::yaml_text(&a.value)),
        reason,
    }
}

pub(crate) fn boolean(
    a: Option<&Assignment>,
    name: &'static str,
    default: bool,
) -> Result<bool, ParamsError> {
    match a {
        None => Ok(default),
        Some(a) => a
            .value
            .as_bool()
            .ok_or_else(|| refused(a, name, "must be true or false")),
    }
}

/// A frame id: a non-empty string without spaces.
pub(crate) fn frame(
    a: Option<&Assignment>,
    name: &'static str,
    default: &str,
) -> Result<String, ParamsError> {
    match a {
        None => Ok(default.to_owned()),
        Some(Assignment {
            value: Value::String(s),
            ..
        }) if !s.is_empty() && !s.contains(char::is_whitespace) => Ok(s.clone()),
        Some(a) => Err(refused(
            a,
            name,
            "must be a frame id (a non-empty string without spaces)",
        )),
    }
}

/// A [`TfMode`] by its name; unset: `map_to_base_link`.
fn tf_mode(a: Option<&Assignment>) -> Result<TfMode, ParamsError> {
    match a {
        None => Ok(TfMode::MapToBaseLink),
        Some(a) => a
            .value
            .as_str()
            .and_then(TfMode::from_name)
            .ok_or_else(|| refused(a, TF_MODE, "must be map_to_base_link, map_to_odom or none")),
    }
}

/// A frame id or, empty or unset, none.
fn optional_frame(
    a: Option<&Assignment>,
    name: &'static str,
) -> Result<Option<String>, ParamsError> {
    match a {
        Some(Assignment {
            value: Value::String(s),
            ..
        }) if s.is_empty() => Ok(None),
        Some(_) => frame(a, name, "").map(Some),
        None => Ok(None),
    }
}

/// A history depth: an integer in 1..=[`MAX_QUEUE_DEPTH`].
pub(crate) fn depth(a: Option<&Assignment>) -> Result<usize, ParamsError> {
    match a {
        None => Ok(DEFAULT_QUEUE_DEPTH),
        Some(a) => a
            .value
            .as_u64()
            .and_then(|d| usize::try_from(d).ok())
            .filter(|d| (1..=MAX_QUEUE_DEPTH).contains(d))
            .ok_or_else(|| refused(a, QUEUE_DEPTH, "must be an integer from 1 to 60000")),
    }
}

/// Reads a parameter file of at most [`MAX_FILE_BYTES`] (a larger one is refused without
/// being read whole).
pub fn read_params_file(path: &Path) -> Result<String, ParamsError> {
    let read_error = |source| ParamsError::Read {
        path: path.display().to_string(),
        source,
    };
    let file = std::fs::File::open(path).map_err(read_error)?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(read_error)?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(ConfigError::TooLarge {
            origin: path.display().to_string(),
            limit: MAX_FILE_BYTES,
        }
        .into());
    }
    String::from_utf8(bytes)
        .map_err(|e| read_error(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))
}

/// The overrides of `sources` for the node `fqn`: each file read and parsed, each rule
/// parsed; a file none of whose entries addresses the node is an error.
fn overrides(
    sources: &[ParameterSource],
    fqn: &str,
    name: &str,
) -> Result<ParameterOverrides, ParamsError> {
    let mut overrides = ParameterOverrides::default();
    for source in sources {
        match source {
            ParameterSource::File(path) => {
                let text = read_params_file(path)?;
                let origin = path.display().to_string();
                let nodes = overrides.add_file(&text, &origin)?;
                // Choice: rcl silently ignores entries for other nodes; a file none of
                // whose entries is for this node is almost certainly a mistake.
                if !nodes.iter().any(|n| node_matches(n, fqn)) {
                    return Err(ParamsError::WrongNode {
                        path: origin,
                        key: ConfigError::shortened(&nodes.join(", ")),
                        fqn: fqn.to_owned(),
                        name: name.to_owned(),
                    });
                }
            }
            ParameterSource::Rule { node, name, value } => {
                overrides.add_rule(node.as_deref(), name, value)?
            }
        }
    }
    Ok(overrides)
}

/// Reads the parameter files of `args` and builds the node's parameters.
pub fn load(args: &NodeArgs) -> Result<NodeParams, ParamsError> {
    node_params_from(&resolved(args)?)
}

/// The parameter values the files and rules of `args` give the node it names, as rclcpp
/// resolves them.
pub fn resolved(args: &NodeArgs) -> Result<Vec<Assignment>, ParamsError> {
    let fqn = args.fully_qualified_name();
    Ok(overrides(&args.parameter_sources, &fqn, &args.node_name)?.for_node(&fqn))
}

/// The values that parameter files read in order (a later value wins) give the node
/// `/gnss_ins_node` (as the node started with its default name reads them).
fn values_from_files(paths: &[PathBuf]) -> Result<Vec<Assignment>, ParamsError> {
    let sources: Vec<ParameterSource> = paths.iter().cloned().map(ParameterSource::File).collect();
    let fqn = format!("/{DEFAULT_NODE_NAME}");
    Ok(overrides(&sources, &fqn, DEFAULT_NODE_NAME)?.for_node(&fqn))
}

/// The configuration of `compare` and `spp` from their `--params` files (see
/// [`values_from_files`]). The node's own parameters are accepted and ignored.
pub fn config_from_files(paths: &[PathBuf]) -> Result<Config, ParamsError> {
    let core = values_from_files(paths)?
        .into_iter()
        .filter(|a| NodeParameter::named(&a.name).is_none());
    Ok(Config::default().with(core)?)
}

/// What `replay`'s `--params` files give the node (see [`values_from_files`]): the
/// configuration and the node's own parameters, checked as the node checks them, so that
/// `replay` frames its outputs and publishes the TF as the node started with these files.
pub fn node_params_from_files(paths: &[PathBuf]) -> Result<NodeParams, ParamsError> {
    node_params_from(&values_from_files(paths)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::args::parse;

    const FILE: &str = "gnss_ins_node:\n  ros__parameters:\n    filter:\n      variant: ermakf\n";

    /// Loads with parameter files holding `files` (each written to a temporary file and
    /// given with --params-file, in order) followed by the ROS arguments `extra`.
    fn load_with(files: &[&str], extra: &[&str]) -> Result<NodeParams, ParamsError> {
        let dir = tempfile::tempdir().unwrap();
        let mut all = vec!["--ros-args".to_owned()];
        for (i, text) in files.iter().enumerate() {
            let path = dir.path().join(format!("p{i}.yaml"));
            std::fs::write(&path, text).unwrap();
            all.extend(["--params-file".to_owned(), path.display().to_string()]);
        }
        all.extend(extra.iter().map(|s| s.to_string()));
        load(&parse(all).unwrap())
    }

    fn variant(p: &NodeParams) -> &'static str {
        p.config.filter.variant.as_str()
    }

    #[test]
    fn file_then_overrides() {
        assert_eq!(variant(&load_with(&[FILE], &[]).unwrap()), "ermakf");
        let p = load_with(&[FILE], &["-p", "filter.variant:=ekf"]).unwrap();
        assert_eq!(variant(&p), "ekf");
    }

    #[test]
    fn any_number_of_files_apply_in_order() {
        let base = FILE.replace("ermakf", "ekf") + "    gnss:\n      pseudorange_sigma_m: 4.0\n";
        let p = load_with(&[&base, FILE], &[]).unwrap();
        assert_eq!(variant(&p), "ermakf", "the later file wins");
        assert_eq!(
            p.config.gnss.pseudorange_sigma_m, 4.0,
            "the earlier file's other keys stay"
        );
        let p = load_with(&[FILE, &base], &[]).unwrap();
        assert_eq!(variant(&p), "ekf");
    }

    #[test]
    fn wildcard_qualified_and_dotted_keys_are_accepted() {
        let any = FILE.replace("gnss_ins_node:", "/**:");
        assert_eq!(variant(&load_with(&[&any], &[]).unwrap()), "ermakf");
        let fq = FILE.replace("gnss_ins_node:", "/r1/ins:");
        let p = load_with(&[&fq], &["-r", "__ns:=/r1", "-r", "__node:=ins"]).unwrap();
        assert_eq!(variant(&p), "ermakf");
        let pattern = FILE.replace("gnss_ins_node:", "/**/ins:");
        let p = load_with(&[&pattern], &["-r", "__ns:=/r1", "-r", "__node:=ins"]).unwrap();
        assert_eq!(variant(&p), "ermakf");
        let dotted = "/**:\n  ros__parameters:\n    filter.variant: ermakf\n    publish_tf: true\n";
        let p = load_with(&[dotted], &[]).unwrap();
        assert_eq!(variant(&p), "ermakf");
        assert!(p.frames.publish_tf);
        let p = load_with(&[], &["-p", "gnss_ins_node:filter.variant:=iarf"]).unwrap();
        assert_eq!(variant(&p), "iarf");
        let p = load_with(&[], &["-p", "other:filter.variant:=iarf"]).unwrap();
        assert_eq!(variant(&p), "ekf", "a rule for another node");
    }

    #[test]
    fn file_for_another_node_is_rejected() {
        let e = load_with(&[FILE], &["-r", "__node:=ins"]).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, ParamsError::WrongNode { .. }), "{text}");
        assert!(
            text.contains("gnss_ins_node") && text.contains("`/ins`"),
            "{text}"
        );
        // A file with an entry for this node and one for another is fine (rcl).
        let two = format!("{FILE}other_node:\n  ros__parameters:\n    x: 1\n");
        assert_eq!(variant(&load_with(&[&two], &[]).unwrap()), "ermakf");
    }

    #[test]
    fn bad_override_names_the_parameter() {
        let e = load_with(&[FILE], &["-p", "filter.no_such_key:=1"]).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("filter.no_such_key") && text.starts_with("-p "),
            "{text}"
        );
        let e = load_with(&[FILE], &["-p", "filter.variant:=ukf"]).unwrap_err();
        assert!(e.to_string().starts_with("-p filter.variant:=ukf: "), "{e}");
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
        let p = load_with(&[&file], &[]).unwrap();
        assert!(p.use_sim_time, "from the file");
        assert_eq!(variant(&p), "ermakf");
        let p = load_with(&[&file], &["-p", "use_sim_time:=false"]).unwrap();
        assert!(!p.use_sim_time, "-p wins over the file");
        assert!(!load_with(&[FILE], &[]).unwrap().use_sim_time);
        let e = load_with(&[FILE], &["-p", "use_sim_time:=maybe"]);
        assert!(matches!(e, Err(ParamsError::NodeParameter { .. })), "{e:?}");
        let bad = FILE.replace("ermakf", "no_such_variant");
        let e = load_with(&[&bad], &[]).unwrap_err().to_string();
        assert!(e.contains("p0.yaml") && e.contains("filter.variant"), "{e}");
    }

    #[test]
    fn every_shipped_preset_loads_over_the_manual() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("params");
        let manual = dir.join("defaults.yaml");
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            config_from_files(&[manual.clone(), path.clone()])
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
    }

    #[test]
    fn tools_ignore_the_nodes_own_parameters() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.yaml");
        let text = "/**:\n  ros__parameters:\n    use_sim_time: true\n    map_frame: odom\n    filter.variant: iarf\n";
        std::fs::write(&path, text).unwrap();
        let config = config_from_files(&[path]).unwrap();
        assert_eq!(config.filter.variant.as_str(), "iarf");
    }

    #[test]
    fn a_file_over_the_size_limit_is_refused_unread() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.yaml");
        let file = std::fs::File::create(&path).unwrap();
        // Sparse: 1 GB on disk costs nothing, and is not read.
        file.set_len(1 << 30).unwrap();
        let e = config_from_files(&[path]).unwrap_err();
        assert!(
            matches!(&e, ParamsError::Config(c) if matches!(**c, ConfigError::TooLarge { .. })),
            "{e}"
        );
    }

    #[test]
    fn declared_defaults_are_the_loaded_ones() {
        let p = load_with(&[], &[]).unwrap();
        let loaded = [
            (USE_SIM_TIME, Value::Bool(p.use_sim_time)),
            (MAP_FRAME, p.frames.map_frame.into()),
            (BASE_FRAME, p.frames.base_frame.into()),
            (ODOM_FRAME, p.frames.odom_frame.into()),
            (PUBLISH_TF, Value::Bool(p.frames.publish_tf)),
            (TF_MODE, p.frames.tf_mode.name().into()),
            (QUEUE_DEPTH, Value::from(p.queue_depth)),
            (IMU_FRAME, p.imu_frame.unwrap_or_default().into()),
        ];
        for (name, value) in loaded {
            let declared = NodeParameter::named(name).unwrap().default;
            assert_eq!(
                serde_yaml::from_str::<Value>(declared).unwrap(),
                value,
                "{name}"
            );
        }
    }

    #[test]
    fn queue_depth_is_the_nodes_and_checked() {
        let p = load_with(&[], &[]).unwrap();
        assert_eq!(p.queue_depth, DEFAULT_QUEUE_DEPTH);
        let p = load_with(&[], &["-p", "queue_depth:=1000"]).unwrap();
        assert_eq!(p.queue_depth, 1000);
        for bad in ["0", "-3", "2.5", "deep", "60001"] {
            let set = format!("queue_depth:={bad}");
            assert!(load_with(&[], &["-p", &set]).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn imu_frame_is_the_nodes_and_optional() {
        assert_eq!(load_with(&[FILE], &[]).unwrap().imu_frame, None);
        let p = load_with(&[FILE], &["-p", "imu_frame:=imu_link"]).unwrap();
        assert_eq!(p.imu_frame.as_deref(), Some("imu_link"));
        assert_eq!(variant(&p), "ermakf");
        let p = load_with(&[FILE], &["-p", "imu_frame:=''"]).unwrap();
        assert_eq!(p.imu_frame, None, "empty: learnt");
        for bad in ["imu_frame:=12", "imu_frame:='a b'"] {
            let e = load_with(&[FILE], &["-p", bad]);
            assert!(
                matches!(e, Err(ParamsError::NodeParameter { .. })),
                "{bad}: {e:?}"
            );
        }
    }

    #[test]
    fn frames_and_publish_tf_are_the_nodes() {
        let p = load_with(&[FILE], &[]).unwrap();
        assert_eq!(p.frames, OutputFrames::default());
        assert_eq!(p.frames.map_frame, "map");
        assert_eq!(p.frames.base_frame, "base_link");
        assert!(!p.frames.publish_tf);
        let file = FILE.replace(
            "ros__parameters:\n",
            "ros__parameters:\n    map_frame: odom_enu\n    publish_tf: true\n",
        );
        let p = load_with(&[&file], &["-p", "base_frame:=imu_link"]).unwrap();
        assert_eq!(variant(&p), "ermakf");
        assert_eq!(p.frames.map_frame, "odom_enu");
        assert_eq!(p.frames.base_frame, "imu_link");
        assert!(p.frames.publish_tf);
        let p = load_with(&[&file], &["-p", "publish_tf:=false"]).unwrap();
        assert!(!p.frames.publish_tf, "-p wins over the file");
        assert_eq!(
            p.frames.published_tf(),
            TfMode::None,
            "publish_tf false: none"
        );
        let p = load_with(&[&file], &["-p", "tf_mode:=map_to_odom"]).unwrap();
        assert_eq!(p.frames.published_tf(), TfMode::MapToOdom);
        assert_eq!(p.frames.odom_frame, "odom");
        let p = load_with(
            &[&file],
            &["-p", "tf_mode:=none", "-p", "odom_frame:=wheel_odom"],
        )
        .unwrap();
        assert_eq!(p.frames.published_tf(), TfMode::None);
        assert_eq!(p.frames.odom_frame, "wheel_odom");
        for bad in [
            "publish_tf:=yes please",
            "base_frame:=''",
            "map_frame:=12",
            "base_frame:=map",
            "tf_mode:=map_to_odometry",
            "tf_mode:=1",
        ] {
            let e = load_with(&[FILE], &["-p", bad]);
            assert!(
                matches!(e, Err(ParamsError::NodeParameter { .. })),
                "{bad}: {e:?}"
            );
        }
        // The odom frame must differ from the others where it is used.
        for bad in ["odom_frame:=base_link", "odom_frame:=odom_enu"] {
            let e = load_with(&[&file], &["-p", "tf_mode:=map_to_odom", "-p", bad]);
            assert!(
                matches!(e, Err(ParamsError::NodeParameter { .. })),
                "{bad}: {e:?}"
            );
        }
        // Elsewhere it is unused: a map frame named `odom` is fine.
        let p = load_with(&[&file], &["-p", "map_frame:=odom"]).unwrap();
        assert_eq!(p.frames.map_frame, "odom");
    }
}
