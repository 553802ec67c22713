//! The ROS 2 parameter services of the node without any DDS: requests of
//! `rcl_interfaces/srv/{List,Get,Set,Describe}Parameters`, `GetParameterTypes` and
//! `SetParametersAtomically` in, responses out.
//!
//! The parameters are the core configuration's (`section.key`, human units, the names of
//! the parameter file) plus the node's own `use_sim_time`, `map_frame`, `base_frame`,
//! `odom_frame`, `publish_tf`, `tf_mode`, `queue_depth` and `imu_frame`; their descriptions, ranges and read-only flags come
//! from the parameter table and `NODE_PARAMETERS`. A set request is validated like the
//! parameter file; only the run-time parameters (and `use_sim_time`) are accepted while
//! the node runs, every other parameter is read-only and a set is refused with the reason.
//!
//! Requests are bounded (issue 12): names and values longer than a parameter can be are
//! refused without being echoed, refusals are logged rate-limited, and a reply whose
//! payload would exceed [`MAX_REPLY_BYTES`] is cut down before it is sent.

use std::collections::BTreeSet;

use ros2_client::parameters::raw::{
    FloatingPointRange, IntegerRange, Parameter, ParameterDescriptor, ParameterType,
    ParameterValue, SetParametersResult,
};
use ros2_client::rcl_interfaces::{
    DescribeParametersResponse, GetParameterTypesResponse, GetParametersResponse,
    ListParametersRequest, ListParametersResponse, ListParametersResult,
    SetParametersAtomicallyResponse, SetParametersResponse,
};
use serde_yaml::Value;

use crate::config::{self, Config, ConfigError, Kind};
use crate::ros::cdr;

use super::params::{
    NodeParameter, OutputFrames, BASE_FRAME, DEFAULT_QUEUE_DEPTH, IMU_FRAME, MAP_FRAME, ODOM_FRAME,
    PUBLISH_TF, QUEUE_DEPTH, TF_MODE, USE_SIM_TIME,
};
use crate::ros::adapter::RosAdapter;
use crate::ros::log_limit::LogLimiter;
use crate::ros::msg::{ParameterEvent, Time};

/// An empty `/parameter_events` message of `node`.
fn event(node: &str, stamp: Time) -> ParameterEvent {
    ParameterEvent {
        stamp,
        node: node.to_owned(),
        new_parameters: Vec::new(),
        changed_parameters: Vec::new(),
        deleted_parameters: Vec::new(),
    }
}

/// `ListParameters` depth meaning "no limit".
const DEPTH_RECURSIVE: u64 = 0;
const SEPARATOR: char = '.';

/// Longest parameter name accepted in a request (bytes); a longer one is refused
/// without being echoed.
///
/// Choice: 256, six times the longest name of the table.
pub const MAX_NAME_BYTES: usize = 256;
/// Most names (or parameters) in one request; the rest of a longer request is not
/// answered.
///
/// Choice: 256, about three times as many as the node has parameters.
pub const MAX_NAMES: usize = 256;
/// Longest string, and most elements of a list, in a value to set.
///
/// Choice: 1024; the longest value of the node is a list of six constellation names.
pub const MAX_VALUE_LEN: usize = 1024;
/// Largest reply payload (bytes of CDR).
///
/// Choice: 56 KiB. A reply larger than a UDP datagram (65,507 bytes of payload) never
/// reaches a Cyclone DDS client (issue 12), so 8 KiB are left for the RTPS headers (a
/// few hundred bytes); the describe reply of every parameter takes about two thirds of
/// this budget (38.6 KB with the scale-factor, dual-antenna and slow-error parameters; it
/// outgrew 48 KiB's three quarters, as it had 32 KiB's).
pub const MAX_REPLY_BYTES: usize = 56 * 1024;

/// The parameter services' state: the node-level parameters and the rate limit of the
/// refusals' log lines.
#[derive(Debug)]
pub struct ParameterServer {
    use_sim_time: bool,
    frames: OutputFrames,
    queue_depth: usize,
    imu_frame: Option<String>,
    log: LogLimiter,
    /// The accepted sets since the last [`ParameterServer::take_events`], in order: one
    /// per parameter of `set_parameters`, one per `set_parameters_atomically`.
    accepted: Vec<Vec<Parameter>>,
}

pub fn value(ptype: u8) -> ParameterValue {
    ParameterValue {
        ptype,
        boolean_value: false,
        int_value: 0,
        double_value: 0.0,
        string_value: String::new(),
        byte_array: Vec::new(),
        bool_array: Vec::new(),
        int_array: Vec::new(),
        double_array: Vec::new(),
        string_array: Vec::new(),
    }
}

/// The ROS parameter value of a configuration value (NOT_SET for `null`, e.g. an unset
/// datum, and for lists of mixed or unknown element types).
pub fn parameter_value(v: &Value) -> ParameterValue {
    match v {
        Value::Bool(b) => ParameterValue {
            boolean_value: *b,
            ..value(ParameterType::BOOL)
        },
        Value::Number(n) => match n.as_i64() {
            Some(i) => ParameterValue {
                int_value: i,
                ..value(ParameterType::INTEGER)
            },
            None => ParameterValue {
                double_value: n.as_f64().unwrap_or(f64::NAN),
                ..value(ParameterType::DOUBLE)
            },
        },
        Value::String(s) => ParameterValue {
            string_value: s.clone(),
            ..value(ParameterType::STRING)
        },
        Value::Sequence(items) => {
            if let Some(d) = items.iter().map(Value::as_f64).collect::<Option<Vec<_>>>() {
                ParameterValue {
                    double_array: d,
                    ..value(ParameterType::DOUBLE_ARRAY)
                }
            } else if let Some(s) = items
                .iter()
                .map(|i| i.as_str().map(str::to_owned))
                .collect::<Option<Vec<_>>>()
            {
                ParameterValue {
                    string_array: s,
                    ..value(ParameterType::STRING_ARRAY)
                }
            } else {
                value(ParameterType::NOT_SET)
            }
        }
        _ => value(ParameterType::NOT_SET),
    }
}

/// The YAML text of a ROS parameter value, for the configuration's loader.
///
/// Choice: an INTEGER is accepted for a DOUBLE parameter (`-p x:=10` style), since the
/// loader reads both; any other type change is refused (ROS's `dynamic_typing` false).
fn yaml_text(new: &ParameterValue, current_type: u8) -> Result<String, String> {
    let t = ParameterType::BOOL..=ParameterType::STRING_ARRAY;
    let compatible = new.ptype == current_type
        || (new.ptype == ParameterType::INTEGER && current_type == ParameterType::DOUBLE)
        || (new.ptype == ParameterType::INTEGER_ARRAY
            && current_type == ParameterType::DOUBLE_ARRAY);
    if !t.contains(&new.ptype) || !compatible {
        return Err(format!(
            "wrong type: the parameter is of type {}, the new value of type {}",
            type_name(current_type),
            type_name(new.ptype)
        ));
    }
    let yaml: Value = match new.ptype {
        ParameterType::BOOL => new.boolean_value.into(),
        ParameterType::INTEGER => new.int_value.into(),
        ParameterType::DOUBLE => new.double_value.into(),
        ParameterType::STRING => new.string_value.clone().into(),
        ParameterType::BYTE_ARRAY => new.byte_array.clone().into(),
        ParameterType::BOOL_ARRAY => new.bool_array.clone().into(),
        ParameterType::INTEGER_ARRAY => new.int_array.clone().into(),
        ParameterType::DOUBLE_ARRAY => new.double_array.clone().into(),
        _ => new.string_array.clone().into(),
    };
    serde_yaml::to_string(&yaml).map_err(|e| e.to_string())
}

fn type_name(ptype: u8) -> &'static str {
    match ptype {
        ParameterType::BOOL => "bool",
        ParameterType::INTEGER => "integer",
        ParameterType::DOUBLE => "double",
        ParameterType::STRING => "string",
        ParameterType::BYTE_ARRAY => "byte array",
        ParameterType::BOOL_ARRAY => "bool array",
        ParameterType::INTEGER_ARRAY => "integer array",
        ParameterType::DOUBLE_ARRAY => "double array",
        ParameterType::STRING_ARRAY => "string array",
        _ => "not set",
    }
}

pub fn result(outcome: Result<(), String>) -> SetParametersResult {
    match outcome {
        Ok(()) => SetParametersResult {
            successful: true,
            reason: String::new(),
        },
        Err(reason) => SetParametersResult {
            successful: false,
            reason,
        },
    }
}

/// Whether `name` is listed for a request with `prefixes` and `depth` (rcl's rule: without
/// prefixes every name with fewer than `depth` separators; with prefixes the names equal to
/// one or below it, less than `depth` separators deeper).
pub fn listed(name: &str, prefixes: &[String], depth: u64) -> bool {
    let separators = |s: &str| s.matches(SEPARATOR).count() as u64;
    let shallow = |rest: &str| depth == DEPTH_RECURSIVE || separators(rest) < depth;
    if prefixes.is_empty() {
        return shallow(name);
    }
    prefixes.iter().any(|p| {
        name == p
            || name
                .strip_prefix(p.as_str())
                .and_then(|rest| rest.strip_prefix(SEPARATOR))
                .is_some_and(shallow)
    })
}

/// The first [`MAX_NAMES`] of `names` (a longer request is logged on `log`).
pub fn bounded_names<'a>(log: &mut LogLimiter, names: &'a [String], service: &str) -> &'a [String] {
    if names.len() > MAX_NAMES {
        log.warn(
            service,
            &format!(
                "{service}: a request for {} names, only the first {MAX_NAMES} answered",
                names.len()
            ),
        );
    }
    &names[..names.len().min(MAX_NAMES)]
}

/// Drops entries from the end of `response` (with `pop`) until its payload fits
/// [`MAX_REPLY_BYTES`] (logged on `log` when it did not).
pub fn fit<R: serde::Serialize>(
    log: &mut LogLimiter,
    service: &str,
    response: &mut R,
    pop: impl Fn(&mut R) -> bool,
) {
    let size = |r: &R| cdr::encode(r).map_or(usize::MAX, |b| b.len());
    if size(response) <= MAX_REPLY_BYTES {
        return;
    }
    while size(response) > MAX_REPLY_BYTES && pop(response) {}
    log.warn(
        service,
        &format!("{service}: reply cut to {MAX_REPLY_BYTES} bytes"),
    );
}

impl ParameterServer {
    /// Services starting with the node parameters as given on the command line.
    pub fn new(use_sim_time: bool, frames: OutputFrames) -> Self {
        Self {
            use_sim_time,
            frames,
            queue_depth: DEFAULT_QUEUE_DEPTH,
            imu_frame: None,
            log: LogLimiter::default(),
            accepted: Vec::new(),
        }
    }

    /// The `/parameter_events` messages of the sets accepted since the last call: one per
    /// set with its parameters and the values set in `changed_parameters`, as rclcpp
    /// announces them (its `set_parameters` sets each parameter atomically on its own).
    pub fn take_events(&mut self, node: &str, stamp: Time) -> Vec<ParameterEvent> {
        std::mem::take(&mut self.accepted)
            .into_iter()
            .map(|changed_parameters| ParameterEvent {
                changed_parameters,
                ..event(node, stamp)
            })
            .collect()
    }

    /// The declaration burst of the node's start: rclcpp publishes one event per declared
    /// parameter with it (and its initial value) in `new_parameters`.
    pub fn declaration_events(
        &self,
        config: &Config,
        node: &str,
        stamp: Time,
    ) -> Vec<ParameterEvent> {
        self.all(config)
            .into_iter()
            .map(|(name, value)| ParameterEvent {
                new_parameters: vec![Parameter { name, value }],
                ..event(node, stamp)
            })
            .collect()
    }

    /// The server reporting `depth` as the node's `queue_depth`.
    pub fn with_queue_depth(mut self, depth: usize) -> Self {
        self.queue_depth = depth;
        self
    }

    /// The server reporting `frame_id` as the node's `imu_frame` (None: empty).
    pub fn with_imu_frame(mut self, frame_id: Option<String>) -> Self {
        self.imu_frame = frame_id;
        self
    }

    /// The current `use_sim_time`.
    pub fn use_sim_time(&self) -> bool {
        self.use_sim_time
    }

    /// Every parameter with its value: the node's, then the configuration's in file
    /// order.
    fn all(&self, config: &Config) -> Vec<(String, ParameterValue)> {
        let f = &self.frames;
        let node = [
            (USE_SIM_TIME, Value::Bool(self.use_sim_time)),
            (MAP_FRAME, Value::String(f.map_frame.clone())),
            (BASE_FRAME, Value::String(f.base_frame.clone())),
            (ODOM_FRAME, Value::String(f.odom_frame.clone())),
            (PUBLISH_TF, Value::Bool(f.publish_tf)),
            (TF_MODE, Value::String(f.tf_mode.name().to_owned())),
            (QUEUE_DEPTH, Value::Number(self.queue_depth.into())),
            (
                IMU_FRAME,
                Value::String(self.imu_frame.clone().unwrap_or_default()),
            ),
        ];
        node.into_iter()
            .map(|(name, v)| (name.to_owned(), parameter_value(&v)))
            .chain(
                config
                    .parameters()
                    .into_iter()
                    .map(|(name, v)| (name, parameter_value(&v))),
            )
            .collect()
    }

    fn lookup(&self, config: &Config, name: &str) -> Option<ParameterValue> {
        if name.len() > MAX_NAME_BYTES {
            return None;
        }
        self.all(config)
            .into_iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    }

    /// `list_parameters` (the answer holds only the node's own names, so it is bounded).
    pub fn list(&self, config: &Config, req: &ListParametersRequest) -> ListParametersResponse {
        let prefixes = &req.prefixes[..req.prefixes.len().min(MAX_NAMES)];
        let names: Vec<String> = self
            .all(config)
            .into_iter()
            .map(|(n, _)| n)
            .filter(|n| listed(n, prefixes, req.depth))
            .collect();
        let prefixes: BTreeSet<String> = names
            .iter()
            .filter_map(|n| n.rsplit_once(SEPARATOR).map(|(p, _)| p.to_owned()))
            .collect();
        ListParametersResponse {
            result: ListParametersResult {
                names,
                prefixes: prefixes.into_iter().collect(),
            },
        }
    }

    /// `get_parameters`: one value per name, NOT_SET for an unknown name.
    pub fn get(&mut self, config: &Config, names: &[String]) -> GetParametersResponse {
        let names = bounded_names(&mut self.log, names, "get_parameters");
        let mut response = GetParametersResponse {
            values: names
                .iter()
                .map(|n| {
                    self.lookup(config, n)
                        .unwrap_or_else(|| value(ParameterType::NOT_SET))
                })
                .collect(),
        };
        fit(&mut self.log, "get_parameters", &mut response, |r| {
            r.values.pop().is_some()
        });
        response
    }

    /// `get_parameter_types`: one type per name, NOT_SET for an unknown name.
    pub fn types(&mut self, config: &Config, names: &[String]) -> GetParameterTypesResponse {
        GetParameterTypesResponse {
            values: self
                .get(config, names)
                .values
                .iter()
                .map(|v| v.ptype)
                .collect(),
        }
    }

    /// `describe_parameters`: type, description, range and read-only flag from the
    /// parameter table (or the node's own declarations).
    pub fn describe(&mut self, config: &Config, names: &[String]) -> DescribeParametersResponse {
        let names = bounded_names(&mut self.log, names, "describe_parameters");
        let values = names
            .iter()
            .map(|name| self.descriptor(config, name))
            .collect();
        let mut response = DescribeParametersResponse { values };
        fit(&mut self.log, "describe_parameters", &mut response, |r| {
            r.values.pop().is_some()
        });
        response
    }

    fn descriptor(&self, config: &Config, name: &str) -> ParameterDescriptor {
        let known = self.lookup(config, name);
        let core = config::parameter(name);
        let node = NodeParameter::named(name);
        let runtime = core.map(|p| p.runtime).or(node.map(|p| p.runtime));
        let range = core.and_then(|p| p.range.closed_bounds());
        let (floating_point_range, integer_range) = match (range, core.map(|p| p.kind)) {
            (Some((from_value, to_value)), Some(Kind::Double)) => (
                vec![FloatingPointRange {
                    from_value,
                    to_value,
                    step: 0.0,
                }],
                Vec::new(),
            ),
            (Some((from, to)), Some(Kind::Integer)) => (
                Vec::new(),
                vec![IntegerRange {
                    from_value: from as i64,
                    to_value: to as i64,
                    step: 0,
                }],
            ),
            _ => (Vec::new(), Vec::new()),
        };
        ParameterDescriptor {
            // An over-long unknown name is not echoed.
            name: ConfigError::shortened(name),
            r#type: known.as_ref().map_or(ParameterType::NOT_SET, |v| v.ptype),
            description: core
                .map(|p| p.description())
                .or(node.map(|p| p.description()))
                .unwrap_or_default(),
            additional_constraints: match runtime {
                Some(false) => {
                    "read-only while the node runs: set it in the parameter file or with -p"
                        .to_owned()
                }
                _ => String::new(),
            },
            read_only: runtime == Some(false),
            dynamic_typing: false,
            floating_point_range,
            integer_range,
        }
    }

    /// Logs a refusal, rate-limited per kind (issue 12: a flood of bad requests must not
    /// flood stderr and /rosout).
    fn refused(&mut self, kind: &str, message: &str) {
        self.log.warn(kind, message);
    }

    /// The configuration after setting `param` on `config` (validated as the file is);
    /// `use_sim_time` is handled by the caller.
    fn changed(&self, config: &Config, param: &Parameter) -> Result<Config, String> {
        let name = &param.name;
        let current = self
            .lookup(config, name)
            .ok_or_else(|| format!("no parameter `{}`", ConfigError::shortened(name)))?;
        if name == QUEUE_DEPTH {
            return Err(format!(
                "`{name}` is read-only while the node runs (the DDS entities are created \
                 with it): restart the node with -p {name}:=VALUE or a parameter file"
            ));
        }
        if name == IMU_FRAME {
            return Err(format!(
                "`{name}` is read-only while the node runs (the filter follows one IMU): \
                 restart the node with -p {name}:=VALUE or a parameter file"
            ));
        }
        if [MAP_FRAME, BASE_FRAME, PUBLISH_TF].contains(&name.as_str()) {
            return Err(format!(
                "`{name}` is read-only while the node runs (the TF tree's listeners expect \
                 fixed frames): restart the node with -p {name}:=VALUE or a parameter file"
            ));
        }
        if !config::parameter(name).is_some_and(|p| p.runtime) {
            return Err(format!(
                "`{name}` is read-only while the node runs (the filter is built from it at \
                 start): restart the node with -p {name}:=VALUE or a parameter file"
            ));
        }
        let text = yaml_text(&param.value, current.ptype)?;
        let mut next = config.clone();
        next.set_parameter(name, text.trim_end())
            .map_err(|e| e.to_string())?;
        Ok(next)
    }

    pub fn sim_time_value(param: &Parameter) -> Result<bool, String> {
        if param.value.ptype == ParameterType::BOOL {
            Ok(param.value.boolean_value)
        } else {
            Err(format!(
                "wrong type: {USE_SIM_TIME} is a bool, the new value is of type {}",
                type_name(param.value.ptype)
            ))
        }
    }

    fn set_one(&mut self, core: &mut RosAdapter, param: &Parameter) -> Result<(), String> {
        oversized(param)?;
        if param.name == USE_SIM_TIME {
            self.use_sim_time = Self::sim_time_value(param)?;
            return Ok(());
        }
        let next = self.changed(core.engine().config(), param)?;
        core.retune(next).map_err(|e| e.to_string())
    }

    /// `set_parameters`: each parameter on its own, one result each.
    pub fn set(&mut self, core: &mut RosAdapter, params: &[Parameter]) -> SetParametersResponse {
        if params.len() > MAX_NAMES {
            self.refused(
                "set_parameters",
                &format!(
                    "set_parameters: {} parameters, only the first {MAX_NAMES} set",
                    params.len()
                ),
            );
        }
        let params = &params[..params.len().min(MAX_NAMES)];
        let results = params
            .iter()
            .map(|p| {
                let outcome = self.set_one(core, p);
                self.log_outcome(p, &outcome);
                if outcome.is_ok() {
                    self.accepted.push(vec![p.clone()]);
                }
                result(outcome)
            })
            .collect();
        let mut response = SetParametersResponse { results };
        fit(&mut self.log, "set_parameters", &mut response, |r| {
            r.results.pop().is_some()
        });
        response
    }

    /// `set_parameters_atomically`: all or none.
    pub fn set_atomically(
        &mut self,
        core: &mut RosAdapter,
        params: &[Parameter],
    ) -> SetParametersAtomicallyResponse {
        let mut config = core.engine().config().clone();
        let mut sim_time = self.use_sim_time;
        let mut outcome = if params.len() > MAX_NAMES {
            Err(format!(
                "{} parameters, at most {MAX_NAMES} at once",
                params.len()
            ))
        } else {
            Ok(())
        };
        for p in params {
            if outcome.is_err() {
                break;
            }
            let step = oversized(p).and_then(|()| {
                if p.name == USE_SIM_TIME {
                    Self::sim_time_value(p).map(|b| sim_time = b)
                } else {
                    self.changed(&config, p).map(|next| config = next)
                }
            });
            if let Err(e) = step {
                outcome = Err(format!("{}: {e}", ConfigError::shortened(&p.name)));
            }
        }
        let outcome = outcome.and_then(|()| core.retune(config).map_err(|e| e.to_string()));
        if outcome.is_ok() {
            self.use_sim_time = sim_time;
            self.accepted.push(params.to_vec());
        }
        for p in params.iter().take(MAX_NAMES) {
            self.log_outcome(p, &outcome);
        }
        SetParametersAtomicallyResponse {
            result: result(outcome.map_err(|e| ConfigError::shortened(&e))),
        }
    }

    /// Logs an accepted set (each one: they are bounded by what can change) or a refusal
    /// (rate-limited).
    fn log_outcome(&mut self, p: &Parameter, outcome: &Result<(), String>) {
        let name = ConfigError::shortened(&p.name);
        match outcome {
            Ok(()) => log::info!("parameter {name} set to {:?}", shown(&p.value)),
            Err(e) => self.refused(
                "parameter set refused",
                &format!("parameter {name} not set: {e}"),
            ),
        }
    }
}

/// Refuses a name or a value longer than any parameter's, without quoting it.
pub fn oversized(p: &Parameter) -> Result<(), String> {
    if p.name.len() > MAX_NAME_BYTES {
        return Err(format!(
            "a parameter name of {} bytes (the longest is {MAX_NAME_BYTES})",
            p.name.len()
        ));
    }
    let v = &p.value;
    let longest_text = v
        .string_array
        .iter()
        .map(String::len)
        .chain([v.string_value.len()])
        .max()
        .unwrap_or(0);
    let longest_list = [
        v.byte_array.len(),
        v.bool_array.len(),
        v.int_array.len(),
        v.double_array.len(),
        v.string_array.len(),
    ]
    .into_iter()
    .max()
    .unwrap_or(0);
    if longest_text > MAX_VALUE_LEN || longest_list > MAX_VALUE_LEN {
        return Err(format!(
            "a value with a text of {longest_text} bytes or a list of {longest_list} \
             elements (at most {MAX_VALUE_LEN} each)"
        ));
    }
    Ok(())
}

fn shown(v: &ParameterValue) -> String {
    ConfigError::shortened(
        yaml_text(v, v.ptype)
            .map(|t| t.trim_end().to_owned())
            .unwrap_or_default()
            .as_str(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::node::params::NODE_PARAMETERS;

    fn double(v: f64) -> ParameterValue {
        ParameterValue {
            double_value: v,
            ..value(ParameterType::DOUBLE)
        }
    }

    fn param(name: &str, value: ParameterValue) -> Parameter {
        Parameter {
            name: name.to_owned(),
            value,
        }
    }

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn list_follows_prefixes_and_depth() {
        let s = ParameterServer::new(false, OutputFrames::default());
        let c = Config::default();
        let list = |prefixes: &[&str], depth| {
            let req = ListParametersRequest {
                prefixes: names(prefixes),
                depth,
            };
            s.list(&c, &req).result
        };
        let all = list(&[], DEPTH_RECURSIVE);
        assert_eq!(
            all.names.len(),
            c.parameters().len() + NODE_PARAMETERS.len()
        );
        assert!(all.names.contains(&"use_sim_time".to_owned()));
        assert!(all.prefixes.contains(&"gnss".to_owned()));
        assert_eq!(
            list(&[], 1).names,
            vec![
                "use_sim_time",
                "map_frame",
                "base_frame",
                "odom_frame",
                "publish_tf",
                "tf_mode",
                "queue_depth",
                "imu_frame"
            ],
            "no separator"
        );
        let gnss = list(&["gnss"], DEPTH_RECURSIVE);
        assert!(gnss.names.iter().all(|n| n.starts_with("gnss.")));
        assert!(gnss.names.contains(&"gnss.elevation_mask_deg".to_owned()));
        assert_eq!(gnss.prefixes, vec!["gnss"]);
        assert!(list(&["gns"], DEPTH_RECURSIVE).names.is_empty());
    }

    #[test]
    fn get_types_and_describe() {
        let mut s = ParameterServer::new(true, OutputFrames::default());
        let c = Config::default();
        let n = names(&[
            "gnss.elevation_mask_deg",
            "filter.variant",
            "gnss.constellations",
            "use_sim_time",
            "nope",
        ]);
        let v = s.get(&c, &n).values;
        assert_eq!(v[0].ptype, ParameterType::DOUBLE);
        assert_eq!(v[0].double_value, 10.0);
        assert_eq!(v[1].string_value, "ekf");
        assert_eq!(v[2].string_array, vec!["gps", "galileo", "beidou"]);
        assert!(v[3].boolean_value);
        assert_eq!(v[4].ptype, ParameterType::NOT_SET);
        let types = s.types(&c, &n).values;
        assert_eq!(
            types,
            vec![
                ParameterType::DOUBLE,
                ParameterType::STRING,
                ParameterType::STRING_ARRAY,
                ParameterType::BOOL,
                ParameterType::NOT_SET
            ]
        );
        let d = s.describe(&c, &n).values;
        assert!(!d[0].read_only && d[1].read_only && !d[3].read_only);
        assert!(
            d[0].description.contains("Unit: deg"),
            "{}",
            d[0].description
        );
        assert_eq!(d[4].r#type, ParameterType::NOT_SET);
    }

    #[test]
    fn set_applies_runtime_parameters_and_refuses_the_rest_with_a_reason() {
        let mut s = ParameterServer::new(false, OutputFrames::default());
        let mut core = RosAdapter::new(Config::default(), OutputFrames::default());
        let r = s.set(
            &mut core,
            &[
                param("gnss.elevation_mask_deg", double(15.0)),
                param("gnss.elevation_mask_deg", double(95.0)),
                param("imu.gyro_bias_deg_per_h", double(0.3)),
                param(
                    "gnss.innovation_gate_sigma",
                    ParameterValue {
                        string_value: "x".into(),
                        ..value(ParameterType::STRING)
                    },
                ),
                param(
                    "output.rate_hz",
                    ParameterValue {
                        int_value: 10,
                        ..value(ParameterType::INTEGER)
                    },
                ),
                param(
                    "use_sim_time",
                    ParameterValue {
                        boolean_value: true,
                        ..value(ParameterType::BOOL)
                    },
                ),
                param("nope", double(1.0)),
            ],
        );
        let ok: Vec<bool> = r.results.iter().map(|r| r.successful).collect();
        assert_eq!(ok, vec![true, false, false, false, true, true, false]);
        for (i, needle) in [
            (1, "elevation_mask_deg"),
            (2, "read-only"),
            (3, "wrong type"),
            (6, "no parameter"),
        ] {
            assert!(
                r.results[i].reason.contains(needle),
                "{i}: {}",
                r.results[i].reason
            );
        }
        let config = core.engine().config();
        assert!((config.gnss.elevation_mask_rad - 15f64.to_radians()).abs() < 1e-15);
        assert_eq!(config.output.rate_hz, 10.0);
        assert!(s.use_sim_time());
        let v = s.get(config, &names(&["gnss.elevation_mask_deg"])).values;
        assert_eq!(v[0].double_value, 15.0, "read back in human units");
    }

    #[test]
    fn set_atomically_is_all_or_nothing() {
        let mut s = ParameterServer::new(false, OutputFrames::default());
        let mut core = RosAdapter::new(Config::default(), OutputFrames::default());
        let r = s.set_atomically(
            &mut core,
            &[
                param("gnss.elevation_mask_deg", double(15.0)),
                param("filter.joseph_form", value(ParameterType::BOOL)),
            ],
        );
        assert!(!r.result.successful);
        assert!(r.result.reason.starts_with("filter.joseph_form"));
        assert_eq!(core.engine().config(), &Config::default());
        let r = s.set_atomically(
            &mut core,
            &[
                param("gnss.elevation_mask_deg", double(15.0)),
                param("gnss.cn0_mask_dbhz", double(20.0)),
            ],
        );
        assert!(r.result.successful, "{}", r.result.reason);
        assert_eq!(core.engine().config().gnss.cn0_mask_dbhz, 20.0);
    }

    #[test]
    fn accepted_sets_and_declarations_become_parameter_events() {
        let mut s = ParameterServer::new(false, OutputFrames::default());
        let mut core = RosAdapter::new(Config::default(), OutputFrames::default());
        let stamp = Time {
            sec: 1_764_000_000,
            nanosec: 2_500_001,
        };
        let declared = s.declaration_events(core.engine().config(), "/ns/n", stamp);
        assert_eq!(
            declared.len(),
            Config::default().parameters().len() + NODE_PARAMETERS.len()
        );
        assert!(declared.iter().all(|e| e.new_parameters.len() == 1
            && e.changed_parameters.is_empty()
            && e.node == "/ns/n"
            && e.stamp == stamp));
        assert!(s.take_events("/ns/n", stamp).is_empty(), "nothing set yet");
        // One accepted, one refused (read-only): only the accepted one is announced.
        let mask = param("gnss.elevation_mask_deg", double(12.5));
        let variant = param("filter.variant", value(ParameterType::STRING));
        let r = s.set(&mut core, &[mask, variant]);
        assert!(r.results[0].successful && !r.results[1].successful);
        let events = s.take_events("/ns/n", stamp);
        assert_eq!(events.len(), 1);
        let e = &events[0];
        assert!(e.new_parameters.is_empty() && e.deleted_parameters.is_empty());
        assert_eq!(e.changed_parameters.len(), 1);
        assert_eq!(e.changed_parameters[0].name, "gnss.elevation_mask_deg");
        assert_eq!(e.changed_parameters[0].value.double_value, 12.5);
        assert!(s.take_events("/ns/n", stamp).is_empty(), "announced once");
        // Two accepted in one set_parameters: two events, as rclcpp.
        let two = [
            param("gnss.elevation_mask_deg", double(11.0)),
            param("gnss.cn0_mask_dbhz", double(22.0)),
        ];
        assert!(s.set(&mut core, &two).results.iter().all(|r| r.successful));
        let events = s.take_events("/ns/n", stamp);
        assert_eq!(events.len(), 2);
        assert_eq!(events[1].changed_parameters[0].value.double_value, 22.0);
        // An atomic set: all of it or, refused, nothing.
        let both = [
            param("gnss.elevation_mask_deg", double(15.0)),
            param("gnss.cn0_mask_dbhz", double(20.0)),
        ];
        assert!(s.set_atomically(&mut core, &both).result.successful);
        let events = s.take_events("/ns/n", stamp);
        assert_eq!(events.len(), 1, "one event for the atomic set");
        assert_eq!(events[0].changed_parameters.len(), 2);
        let refused = [
            both[0].clone(),
            param("filter.joseph_form", value(ParameterType::BOOL)),
        ];
        assert!(!s.set_atomically(&mut core, &refused).result.successful);
        assert!(s.take_events("/ns/n", stamp).is_empty());
    }

    #[test]
    fn frames_are_served_read_only() {
        let frames = OutputFrames {
            map_frame: "world_enu".to_owned(),
            base_frame: "imu_link".to_owned(),
            publish_tf: true,
            ..OutputFrames::default()
        };
        let mut s = ParameterServer::new(false, frames);
        let mut core = RosAdapter::new(Config::default(), OutputFrames::default());
        let c = Config::default();
        let n = names(&["map_frame", "base_frame", "publish_tf"]);
        let v = s.get(&c, &n).values;
        assert_eq!(v[0].string_value, "world_enu");
        assert_eq!(v[1].string_value, "imu_link");
        assert!(v[2].boolean_value && v[2].ptype == ParameterType::BOOL);
        let d = s.describe(&c, &n).values;
        assert!(d.iter().all(|d| d.read_only), "{d:?}");
        assert!(d[2].description.contains("/tf"), "{}", d[2].description);
        let r = s.set(
            &mut core,
            &[param(
                "base_frame",
                ParameterValue {
                    string_value: "other".into(),
                    ..value(ParameterType::STRING)
                },
            )],
        );
        assert!(!r.results[0].successful);
        assert!(
            r.results[0].reason.contains("read-only"),
            "{}",
            r.results[0].reason
        );
        assert_eq!(s.get(&c, &n).values[1].string_value, "imu_link");
    }

    #[test]
    fn descriptions_ranges_and_read_only_flags_come_from_the_table() {
        let mut s = ParameterServer::new(false, OutputFrames::default());
        let c = Config::default();
        let every: Vec<String> = s.all(&c).into_iter().map(|(n, _)| n).collect();
        let d = s.describe(&c, &every).values;
        assert_eq!(d.len(), every.len());
        for (name, d) in every.iter().zip(&d) {
            assert!(!d.description.is_empty(), "{name} undocumented");
            let runtime = config::parameter(name)
                .map(|p| p.runtime)
                .or(NodeParameter::named(name).map(|p| p.runtime))
                .unwrap();
            assert_eq!(d.read_only, !runtime, "{name}");
        }
        let mask = &d[every
            .iter()
            .position(|n| n == "gnss.elevation_mask_deg")
            .unwrap()];
        assert!(
            mask.description.contains("Unit: deg"),
            "{}",
            mask.description
        );
        let gap = &d[every
            .iter()
            .position(|n| n == "engine.imu_buffer_s")
            .unwrap()];
        assert_eq!(gap.floating_point_range[0].to_value, 60.0);
        let window = &d[every
            .iter()
            .position(|n| n == "adaptive.window_size_m")
            .unwrap()];
        assert_eq!(window.integer_range[0].to_value, 10_000);
        // Describing every parameter fits in a reply with room to spare.
        let size = cdr::encode(&DescribeParametersResponse { values: d })
            .unwrap()
            .len();
        assert!(size < MAX_REPLY_BYTES * 3 / 4, "{size} bytes");
    }

    /// Issue 12 item 13: 100 requests with 200 KB names added 74 MB and 40 MB of stderr;
    /// each rejected name was logged and echoed, and a reply over ~64 KB never reaches a
    /// Cyclone client.
    #[test]
    fn huge_names_and_values_get_bounded_replies_and_rate_limited_logs() {
        let mut s = ParameterServer::new(false, OutputFrames::default());
        let mut core = RosAdapter::new(Config::default(), OutputFrames::default());
        let c = Config::default();
        let huge = "n".repeat(200_000);
        let names: Vec<String> = (0..100).map(|i| format!("{huge}{i}")).collect();
        let described = s.describe(&c, &names);
        assert!(
            reply_size(&described) <= MAX_REPLY_BYTES,
            "{}",
            reply_size(&described)
        );
        let got = s.get(&c, &names);
        assert!(reply_size(&got) <= MAX_REPLY_BYTES);
        let params: Vec<Parameter> = names.iter().map(|n| param(n, double(1.0))).collect();
        let set = s.set(&mut core, &params);
        assert!(reply_size(&set) <= MAX_REPLY_BYTES, "{}", reply_size(&set));
        assert!(set
            .results
            .iter()
            .all(|r| !r.successful && r.reason.len() < 200));
        let atomic = s.set_atomically(&mut core, &params);
        assert!(!atomic.result.successful && atomic.result.reason.len() < 300);
        // A huge value for a real parameter is refused without being quoted.
        let value = ParameterValue {
            string_value: huge.clone(),
            ..value(ParameterType::STRING)
        };
        let r = s.set(&mut core, &[param("filter.variant", value)]);
        assert!(
            !r.results[0].successful && r.results[0].reason.len() < 200,
            "{}",
            r.results[0].reason
        );
        // Every refusal was counted, only the 1st, 10th, 100th... of a kind logged.
        assert_eq!(s.log.count("parameter set refused"), 201);
        assert_eq!(s.log.logged("parameter set refused"), 3);
        // Too many names: only the first MAX_NAMES are answered.
        let many = vec!["gnss.elevation_mask_deg".to_owned(); 5 * MAX_NAMES];
        let described = s.describe(&c, &many);
        assert!(described.values.len() <= MAX_NAMES);
        assert!(
            reply_size(&described) <= MAX_REPLY_BYTES,
            "{}",
            reply_size(&described)
        );
    }

    fn reply_size<T: serde::Serialize>(reply: &T) -> usize {
        cdr::encode(reply).unwrap().len()
    }
}
