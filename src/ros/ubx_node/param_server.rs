//! The parameter services of `gnss_ins_ubx_node` without any DDS: its parameters (the
//! table [`UBX_NODE_PARAMETERS`]) listed, read and described with the bounds and the
//! rcl rules of `gnss_ins_node`'s; only `use_sim_time` can be set while it runs.

use std::collections::BTreeSet;

use ros2_client::parameters::raw::{Parameter, ParameterDescriptor, ParameterType};
use ros2_client::rcl_interfaces::{
    DescribeParametersResponse, GetParameterTypesResponse, GetParametersResponse,
    ListParametersRequest, ListParametersResponse, ListParametersResult,
    SetParametersAtomicallyResponse, SetParametersResponse,
};

use crate::config::ConfigError;
use crate::ros::log_limit::LogLimiter;
use crate::ros::node::param_server::{
    bounded_names, fit, listed, oversized, parameter_value, result, value as empty_value,
    ParameterServer, MAX_NAMES,
};
use crate::ros::node::params::USE_SIM_TIME;
use crate::ros::node::services::ParameterHandler;

use super::params::{parameter, UbxNodeParams};

/// The parameters as the node started with them, and the current `use_sim_time`.
#[derive(Debug)]
pub struct UbxParameterServer {
    params: UbxNodeParams,
    log: LogLimiter,
}

impl UbxParameterServer {
    pub fn new(params: UbxNodeParams) -> Self {
        Self {
            params,
            log: LogLimiter::default(),
        }
    }

    /// The current `use_sim_time`.
    pub fn use_sim_time(&self) -> bool {
        self.params.use_sim_time
    }

    fn lookup(&self, name: &str) -> Option<ros2_client::parameters::raw::ParameterValue> {
        self.params
            .values()
            .into_iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| parameter_value(&v))
    }

    /// The new `use_sim_time` of `p`, or why `p` is not set.
    fn settable(p: &Parameter) -> Result<bool, String> {
        oversized(p)?;
        let name = ConfigError::shortened(&p.name);
        match parameter(&p.name) {
            None => Err(format!("no parameter `{name}`")),
            Some(d) if d.name == USE_SIM_TIME => ParameterServer::sim_time_value(p),
            Some(_) => Err(format!(
                "`{name}` is read-only while the node runs (the adapter and its topics are \
                 built from it at start): restart the node with -p {name}:=VALUE or a \
                 parameter file"
            )),
        }
    }

    fn log_outcome(&mut self, p: &Parameter, outcome: &Result<(), String>) {
        let name = ConfigError::shortened(&p.name);
        match outcome {
            Ok(()) => log::info!("parameter {name} set"),
            Err(e) => {
                self.log.warn(
                    "parameter set refused",
                    &format!("parameter {name} not set: {e}"),
                );
            }
        }
    }
}

impl ParameterHandler for UbxParameterServer {
    fn list(&mut self, req: &ListParametersRequest) -> ListParametersResponse {
        let prefixes = &req.prefixes[..req.prefixes.len().min(MAX_NAMES)];
        let names: Vec<String> = self
            .params
            .values()
            .into_iter()
            .map(|(n, _)| n.to_owned())
            .filter(|n| listed(n, prefixes, req.depth))
            .collect();
        let prefixes: BTreeSet<String> = names
            .iter()
            .filter_map(|n| n.rsplit_once('.').map(|(p, _)| p.to_owned()))
            .collect();
        ListParametersResponse {
            result: ListParametersResult {
                names,
                prefixes: prefixes.into_iter().collect(),
            },
        }
    }

    fn get(&mut self, names: &[String]) -> GetParametersResponse {
        let names = bounded_names(&mut self.log, names, "get_parameters");
        let mut response = GetParametersResponse {
            values: names
                .iter()
                .map(|n| {
                    self.lookup(n)
                        .unwrap_or_else(|| empty_value(ParameterType::NOT_SET))
                })
                .collect(),
        };
        fit(&mut self.log, "get_parameters", &mut response, |r| {
            r.values.pop().is_some()
        });
        response
    }

    fn types(&mut self, names: &[String]) -> GetParameterTypesResponse {
        GetParameterTypesResponse {
            values: self.get(names).values.iter().map(|v| v.ptype).collect(),
        }
    }

    fn describe(&mut self, names: &[String]) -> DescribeParametersResponse {
        let names = bounded_names(&mut self.log, names, "describe_parameters");
        let values = names
            .iter()
            .map(|name| {
                let declared = parameter(name);
                let read_only = declared.is_some_and(|d| !d.runtime);
                ParameterDescriptor {
                    name: ConfigError::shortened(name),
                    r#type: self
                        .lookup(name)
                        .map_or(ParameterType::NOT_SET, |v| v.ptype),
                    description: declared.map(|d| d.description()).unwrap_or_default(),
                    additional_constraints: if read_only {
                        "read-only while the node runs: set it in the parameter file or with -p"
                            .to_owned()
                    } else {
                        String::new()
                    },
                    read_only,
                    dynamic_typing: false,
                    floating_point_range: Vec::new(),
                    integer_range: Vec::new(),
                }
            })
            .collect();
        let mut response = DescribeParametersResponse { values };
        fit(&mut self.log, "describe_parameters", &mut response, |r| {
            r.values.pop().is_some()
        });
        response
    }

    fn set(&mut self, params: &[Parameter]) -> SetParametersResponse {
        let results = params
            .iter()
            .take(MAX_NAMES)
            .map(|p| {
                let outcome = Self::settable(p).map(|sim| self.params.use_sim_time = sim);
                self.log_outcome(p, &outcome);
                result(outcome)
            })
            .collect();
        SetParametersResponse { results }
    }

    fn set_atomically(&mut self, params: &[Parameter]) -> SetParametersAtomicallyResponse {
        let mut sim_time = self.params.use_sim_time;
        let mut outcome = if params.len() > MAX_NAMES {
            Err(format!(
                "{} parameters, at most {MAX_NAMES} at once",
                params.len()
            ))
        } else {
            Ok(())
        };
        for p in params.iter().take(MAX_NAMES) {
            if outcome.is_ok() {
                outcome = Self::settable(p)
                    .map(|sim| sim_time = sim)
                    .map_err(|e| format!("{}: {e}", ConfigError::shortened(&p.name)));
            }
        }
        if outcome.is_ok() {
            self.params.use_sim_time = sim_time;
        }
        for p in params.iter().take(MAX_NAMES) {
            self.log_outcome(p, &outcome);
        }
        SetParametersAtomicallyResponse {
            result: result(outcome.map_err(|e| ConfigError::shortened(&e))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::node::param_server::parameter_value;
    use crate::ros::ubx_node::params::{ubx_node_params_from, UBX_NODE_PARAMETERS};

    fn server() -> UbxParameterServer {
        UbxParameterServer::new(ubx_node_params_from(&[]).unwrap())
    }

    fn param(name: &str, value: serde_yaml::Value) -> Parameter {
        Parameter {
            name: name.to_owned(),
            value: parameter_value(&value),
        }
    }

    #[test]
    fn lists_gets_and_describes_the_table() {
        let mut s = server();
        let all = s.list(&ListParametersRequest {
            prefixes: Vec::new(),
            depth: 0,
        });
        let declared: Vec<&str> = UBX_NODE_PARAMETERS.iter().map(|p| p.name).collect();
        assert_eq!(all.result.names, declared);
        let got = s.get(&["time_base".to_owned(), "nope".to_owned()]);
        assert_eq!(got.values[0].string_value, "gnss");
        assert_eq!(got.values[1].ptype, ParameterType::NOT_SET);
        let d = s.describe(&["leap_seconds".to_owned(), "use_sim_time".to_owned()]);
        assert!(d.values[0].read_only && d.values[0].description.contains("GPS - UTC"));
        assert_eq!(d.values[0].r#type, ParameterType::INTEGER);
        assert!(!d.values[1].read_only);
    }

    #[test]
    fn only_use_sim_time_is_set_at_run_time() {
        let mut s = server();
        let r = s.set(&[
            param("use_sim_time", true.into()),
            param("time_base", "host".into()),
            param("use_sim_time", 1.into()),
        ]);
        let ok: Vec<bool> = r.results.iter().map(|r| r.successful).collect();
        assert_eq!(ok, [true, false, false]);
        assert!(r.results[1].reason.contains("read-only"));
        assert!(s.use_sim_time());
        let r = s.set_atomically(&[
            param("use_sim_time", false.into()),
            param("frame_id", "x".into()),
        ]);
        assert!(!r.result.successful);
        assert!(s.use_sim_time(), "all or nothing");
    }
}
