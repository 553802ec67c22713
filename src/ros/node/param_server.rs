//! The ROS 2 parameter services of the node without any DDS: requests of
//! `rcl_interfaces/srv/{List,Get,Set,Describe}Parameters`, `GetParameterTypes` and
//! `SetParametersAtomically` in, responses out.
//!
//! The parameters are the core configuration's (`section.key`, human units, the names of
//! the parameter file) plus the node's own `use_sim_time`, `map_frame`, `base_frame`,
//! `publish_tf` and `queue_depth`. A set request is validated like the parameter file; only
//! [`RUNTIME_PARAMETERS`] (and `use_sim_time`) are accepted while the node runs, every
//! other parameter is read-only and a set is refused with the reason.

use std::collections::{BTreeSet, HashMap};

use ros2_client::parameters::raw::{
    Parameter, ParameterDescriptor, ParameterType, ParameterValue, SetParametersResult,
};
use ros2_client::rcl_interfaces::{
    DescribeParametersResponse, GetParameterTypesResponse, GetParametersResponse,
    ListParametersRequest, ListParametersResponse, ListParametersResult,
    SetParametersAtomicallyResponse, SetParametersResponse,
};
use serde_yaml::Value;

use crate::config::Config;
use crate::engine::RUNTIME_PARAMETERS;

use super::param_docs;
use super::params::{
    OutputFrames, BASE_FRAME, DEFAULT_QUEUE_DEPTH, MAP_FRAME, PUBLISH_TF, QUEUE_DEPTH, USE_SIM_TIME,
};
use crate::ros::adapter::RosAdapter;

/// `ListParameters` depth meaning "no limit".
const DEPTH_RECURSIVE: u64 = 0;
const SEPARATOR: char = '.';

/// The parameter services' state: the descriptions and the node-level parameters.
#[derive(Debug, Clone)]
pub struct ParameterServer {
    descriptions: HashMap<String, String>,
    use_sim_time: bool,
    frames: OutputFrames,
    queue_depth: usize,
}

/// Descriptions of the node's own parameters (the core's come from the manual).
const NODE_DESCRIPTIONS: [(&str, &str); 5] = [
    (
        USE_SIM_TIME,
        "The node's time (diagnostics and rosout stamps, input ages) follows /clock.",
    ),
    (
        MAP_FRAME,
        "Parent frame of odometry and /tf: ENU at the datum (REP-105 map). Read-only.",
    ),
    (
        BASE_FRAME,
        "Child frame of odometry and /tf, frame of fix: the vehicle body (FLU). Read-only.",
    ),
    (
        PUBLISH_TF,
        "Publish map_frame -> base_frame on /tf with each odometry. Read-only.",
    ),
    (
        QUEUE_DEPTH,
        "History depth (messages) of the input subscriptions and the publishers. Read-only.",
    ),
];

fn value(ptype: u8) -> ParameterValue {
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

fn result(outcome: Result<(), String>) -> SetParametersResult {
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
fn listed(name: &str, prefixes: &[String], depth: u64) -> bool {
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

impl ParameterServer {
    /// Services starting with the node parameters as given on the command line.
    pub fn new(use_sim_time: bool, frames: OutputFrames) -> Self {
        let mut descriptions = param_docs::descriptions();
        for (name, text) in NODE_DESCRIPTIONS {
            descriptions.insert(name.to_owned(), text.to_owned());
        }
        Self {
            descriptions,
            use_sim_time,
            frames,
            queue_depth: DEFAULT_QUEUE_DEPTH,
        }
    }

    /// The server reporting `depth` as the node's `queue_depth`.
    pub fn with_queue_depth(mut self, depth: usize) -> Self {
        self.queue_depth = depth;
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
            (PUBLISH_TF, Value::Bool(f.publish_tf)),
            (QUEUE_DEPTH, Value::Number(self.queue_depth.into())),
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
        self.all(config)
            .into_iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    }

    /// `list_parameters`.
    pub fn list(&self, config: &Config, req: &ListParametersRequest) -> ListParametersResponse {
        let names: Vec<String> = self
            .all(config)
            .into_iter()
            .map(|(n, _)| n)
            .filter(|n| listed(n, &req.prefixes, req.depth))
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
    pub fn get(&self, config: &Config, names: &[String]) -> GetParametersResponse {
        GetParametersResponse {
            values: names
                .iter()
                .map(|n| {
                    self.lookup(config, n)
                        .unwrap_or_else(|| value(ParameterType::NOT_SET))
                })
                .collect(),
        }
    }

    /// `get_parameter_types`: one type per name, NOT_SET for an unknown name.
    pub fn types(&self, config: &Config, names: &[String]) -> GetParameterTypesResponse {
        GetParameterTypesResponse {
            values: self
                .get(config, names)
                .values
                .iter()
                .map(|v| v.ptype)
                .collect(),
        }
    }

    /// `describe_parameters`: type, description from the manual, and read-only for every
    /// parameter that cannot change while the node runs.
    pub fn describe(&self, config: &Config, names: &[String]) -> DescribeParametersResponse {
        let values = names
            .iter()
            .map(|name| {
                let known = self.lookup(config, name);
                let runtime = name == USE_SIM_TIME || RUNTIME_PARAMETERS.contains(&name.as_str());
                ParameterDescriptor {
                    name: name.clone(),
                    r#type: known.as_ref().map_or(ParameterType::NOT_SET, |v| v.ptype),
                    description: self.descriptions.get(name).cloned().unwrap_or_default(),
                    additional_constraints: if known.is_none() || runtime {
                        String::new()
                    } else {
                        "read-only while the node runs: set it in the parameter file or with -p"
                            .to_owned()
                    },
                    read_only: known.is_some() && !runtime,
                    dynamic_typing: false,
                    floating_point_range: Vec::new(),
                    integer_range: Vec::new(),
                }
            })
            .collect();
        DescribeParametersResponse { values }
    }

    /// The configuration after setting `param` on `config` (validated as the file is);
    /// `use_sim_time` is handled by the caller.
    fn changed(&self, config: &Config, param: &Parameter) -> Result<Config, String> {
        let name = &param.name;
        let current = self
            .lookup(config, name)
            .ok_or_else(|| format!("no parameter `{name}`"))?;
        if name == QUEUE_DEPTH {
            return Err(format!(
                "`{name}` is read-only while the node runs (the DDS entities are created \
                 with it): restart the node with -p {name}:=VALUE or a parameter file"
            ));
        }
        if [MAP_FRAME, BASE_FRAME, PUBLISH_TF].contains(&name.as_str()) {
            return Err(format!(
                "`{name}` is read-only while the node runs (the TF tree's listeners expect \
                 fixed frames): restart the node with -p {name}:=VALUE or a parameter file"
            ));
        }
        if !RUNTIME_PARAMETERS.contains(&name.as_str()) {
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

    fn sim_time_value(param: &Parameter) -> Result<bool, String> {
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
        if param.name == USE_SIM_TIME {
            self.use_sim_time = Self::sim_time_value(param)?;
            return Ok(());
        }
        let next = self.changed(core.engine().config(), param)?;
        core.retune(next).map_err(|e| e.to_string())
    }

    /// `set_parameters`: each parameter on its own, one result each.
    pub fn set(&mut self, core: &mut RosAdapter, params: &[Parameter]) -> SetParametersResponse {
        let results = params
            .iter()
            .map(|p| {
                let outcome = self.set_one(core, p);
                log_outcome(p, &outcome);
                result(outcome)
            })
            .collect();
        SetParametersResponse { results }
    }

    /// `set_parameters_atomically`: all or none.
    pub fn set_atomically(
        &mut self,
        core: &mut RosAdapter,
        params: &[Parameter],
    ) -> SetParametersAtomicallyResponse {
        let mut config = core.engine().config().clone();
        let mut sim_time = self.use_sim_time;
        let mut outcome = Ok(());
        for p in params {
            let step = if p.name == USE_SIM_TIME {
                Self::sim_time_value(p).map(|b| sim_time = b)
            } else {
                self.changed(&config, p).map(|next| config = next)
            };
            if let Err(e) = step {
                outcome = Err(format!("{}: {e}", p.name));
                break;
            }
        }
        let outcome = outcome.and_then(|()| core.retune(config).map_err(|e| e.to_string()));
        if outcome.is_ok() {
            self.use_sim_time = sim_time;
        }
        for p in params {
            log_outcome(p, &outcome);
        }
        SetParametersAtomicallyResponse {
            result: result(outcome),
        }
    }
}

fn log_outcome(p: &Parameter, outcome: &Result<(), String>) {
    match outcome {
        Ok(()) => log::info!("parameter {} set to {:?}", p.name, shown(&p.value)),
        Err(e) => log::warn!("parameter {} not set: {e}", p.name),
    }
}

fn shown(v: &ParameterValue) -> String {
    yaml_text(v, v.ptype)
        .map(|t| t.trim_end().to_owned())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

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
            c.parameters().len() + NODE_DESCRIPTIONS.len()
        );
        assert!(all.names.contains(&"use_sim_time".to_owned()));
        assert!(all.prefixes.contains(&"gnss".to_owned()));
        assert_eq!(
            list(&[], 1).names,
            vec![
                "use_sim_time",
                "map_frame",
                "base_frame",
                "publish_tf",
                "queue_depth"
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
        let s = ParameterServer::new(true, OutputFrames::default());
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
    fn frames_are_served_read_only() {
        let frames = OutputFrames {
            map_frame: "world_enu".to_owned(),
            base_frame: "imu_link".to_owned(),
            publish_tf: true,
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
}
