//! The node's parameter services over DDS (`~/list_parameters`, `~/get_parameters`,
//! `~/get_parameter_types`, `~/set_parameters`, `~/set_parameters_atomically`,
//! `~/describe_parameters`); the answers come from [`ParameterServer`].

use futures::stream::{LocalBoxStream, StreamExt};
use ros2_client::rcl_interfaces::{
    DescribeParametersRequest, DescribeParametersResponse, GetParameterTypesRequest,
    GetParameterTypesResponse, GetParametersRequest, GetParametersResponse, ListParametersRequest,
    ListParametersResponse, SetParametersAtomicallyResponse, SetParametersRequest,
    SetParametersResponse,
};
use ros2_client::{
    qos::History, Message, Name, Node, QosProfile, RmwRequestId, Server, ServiceMapping,
    ServiceTypeName,
};

use ros2_client::parameters::raw::Parameter;

use super::dds::{dds_error, NodeError};
use super::param_server::ParameterServer;
use crate::ros::adapter::RosAdapter;

/// The request/reply mapping of the ROS 2 middleware named by `RMW_IMPLEMENTATION`.
///
/// Choice: `rmw_cyclonedds_cpp` puts a request header in the payload (ros2-client's
/// `Cyclone` mapping); Fast DDS, ROS 2 Jazzy's default (unset variable), and Connext in
/// its extended mode carry the request identity in inline QoS (`Enhanced`). Service
/// clients of other middlewares cannot be served at the same time, as in ROS 2 itself.
pub fn service_mapping_from(rmw_implementation: Option<&str>) -> ServiceMapping {
    match rmw_implementation.map(str::trim) {
        Some("rmw_cyclonedds_cpp") => ServiceMapping::Cyclone,
        _ => ServiceMapping::Enhanced,
    }
}

/// A parameter service request with the identity its reply must carry.
pub enum ParamRequest {
    List(RmwRequestId, ListParametersRequest),
    Get(RmwRequestId, GetParametersRequest),
    Types(RmwRequestId, GetParameterTypesRequest),
    Set(RmwRequestId, SetParametersRequest),
    SetAtomically(RmwRequestId, SetParametersRequest),
    Describe(RmwRequestId, DescribeParametersRequest),
}

/// The six servers of the node.
pub struct ParameterServices {
    list: Server<ListParametersRequest, ListParametersResponse>,
    get: Server<GetParametersRequest, GetParametersResponse>,
    types: Server<GetParameterTypesRequest, GetParameterTypesResponse>,
    set: Server<SetParametersRequest, SetParametersResponse>,
    set_atomically: Server<SetParametersRequest, SetParametersAtomicallyResponse>,
    describe: Server<DescribeParametersRequest, DescribeParametersResponse>,
}

/// ROS 2's default service QoS: reliable, volatile, keep last 10.
fn service_qos() -> QosProfile {
    QosProfile::publisher_default().history(History::KeepLast { depth: 10 })
}

fn server<Req, Resp>(
    node: &mut Node,
    mapping: ServiceMapping,
    service: &str,
    type_name: &str,
) -> Result<Server<Req, Resp>, NodeError>
where
    Req: Message + Clone + 'static,
    Resp: Message + 'static,
{
    let fqn = node.fully_qualified_name();
    let name = Name::new(&fqn, service).map_err(|_| NodeError::TopicName(service.to_owned()))?;
    log::info!("serving {name} (rcl_interfaces/srv/{type_name})");
    node.create_server(
        mapping,
        &name,
        &ServiceTypeName::new("rcl_interfaces", type_name),
        service_qos(),
        service_qos(),
    )
    .map_err(dds_error)
}

/// The requests of one server as a stream of `ParamRequest`s (a request that does not
/// decode is logged and skipped).
fn requests<'a, Req, Resp>(
    s: &'a Server<Req, Resp>,
    wrap: fn(RmwRequestId, Req) -> ParamRequest,
) -> LocalBoxStream<'a, ParamRequest>
where
    Req: Message + Clone + Send + 'static,
    Resp: Message + 'static,
{
    s.receive_request_stream()
        .filter_map(move |r| async move {
            match r {
                Ok((id, req)) => Some(wrap(id, req)),
                Err(e) => {
                    log::warn!("undecodable parameter service request: {e:?}");
                    None
                }
            }
        })
        .boxed_local()
}

fn sent<E: std::fmt::Debug>(service: &str, r: Result<(), E>) {
    if let Err(e) = r {
        log::warn!("{service}: sending the reply failed: {e:?}");
    }
}

impl ParameterServices {
    /// Creates the servers under the node's name.
    pub fn new(node: &mut Node, mapping: ServiceMapping) -> Result<Self, NodeError> {
        Ok(Self {
            list: server(node, mapping, "list_parameters", "ListParameters")?,
            get: server(node, mapping, "get_parameters", "GetParameters")?,
            types: server(node, mapping, "get_parameter_types", "GetParameterTypes")?,
            set: server(node, mapping, "set_parameters", "SetParameters")?,
            set_atomically: server(
                node,
                mapping,
                "set_parameters_atomically",
                "SetParametersAtomically",
            )?,
            describe: server(node, mapping, "describe_parameters", "DescribeParameters")?,
        })
    }

    /// Every request of every server.
    pub fn streams(&self) -> Vec<LocalBoxStream<'_, ParamRequest>> {
        vec![
            requests(&self.list, ParamRequest::List),
            requests(&self.get, ParamRequest::Get),
            requests(&self.types, ParamRequest::Types),
            requests(&self.set, ParamRequest::Set),
            requests(&self.set_atomically, ParamRequest::SetAtomically),
            requests(&self.describe, ParamRequest::Describe),
        ]
    }

    /// Answers `request` with `handler`.
    pub fn answer(&self, request: ParamRequest, handler: &mut impl ParameterHandler) {
        match request {
            ParamRequest::List(id, r) => sent(
                "list_parameters",
                self.list.send_response(id, handler.list(&r)),
            ),
            ParamRequest::Get(id, r) => sent(
                "get_parameters",
                self.get.send_response(id, handler.get(&r.names)),
            ),
            ParamRequest::Types(id, r) => sent(
                "get_parameter_types",
                self.types.send_response(id, handler.types(&r.names)),
            ),
            ParamRequest::Set(id, r) => sent(
                "set_parameters",
                self.set.send_response(id, handler.set(&r.parameter)),
            ),
            ParamRequest::SetAtomically(id, r) => sent(
                "set_parameters_atomically",
                self.set_atomically
                    .send_response(id, handler.set_atomically(&r.parameter)),
            ),
            ParamRequest::Describe(id, r) => sent(
                "describe_parameters",
                self.describe.send_response(id, handler.describe(&r.names)),
            ),
        }
    }
}

/// What answers the parameter services of a node: one method per service.
pub trait ParameterHandler {
    fn list(&mut self, request: &ListParametersRequest) -> ListParametersResponse;
    fn get(&mut self, names: &[String]) -> GetParametersResponse;
    fn types(&mut self, names: &[String]) -> GetParameterTypesResponse;
    fn describe(&mut self, names: &[String]) -> DescribeParametersResponse;
    fn set(&mut self, params: &[Parameter]) -> SetParametersResponse;
    fn set_atomically(&mut self, params: &[Parameter]) -> SetParametersAtomicallyResponse;
}

/// `gnss_ins_node`'s parameters: the node's own in `server`, the configuration of
/// `core`'s engine (run-time parameters are set on it).
pub struct CoreParameters<'a> {
    pub server: &'a mut ParameterServer,
    pub core: &'a mut RosAdapter,
}

impl ParameterHandler for CoreParameters<'_> {
    fn list(&mut self, request: &ListParametersRequest) -> ListParametersResponse {
        self.server.list(self.core.engine().config(), request)
    }
    fn get(&mut self, names: &[String]) -> GetParametersResponse {
        self.server.get(self.core.engine().config(), names)
    }
    fn types(&mut self, names: &[String]) -> GetParameterTypesResponse {
        self.server.types(self.core.engine().config(), names)
    }
    fn describe(&mut self, names: &[String]) -> DescribeParametersResponse {
        self.server.describe(self.core.engine().config(), names)
    }
    fn set(&mut self, params: &[Parameter]) -> SetParametersResponse {
        self.server.set(self.core, params)
    }
    fn set_atomically(&mut self, params: &[Parameter]) -> SetParametersAtomicallyResponse {
        self.server.set_atomically(self.core, params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_follows_the_rmw_implementation() {
        let m = |v| service_mapping_from(v);
        assert_eq!(m(Some("rmw_cyclonedds_cpp")), ServiceMapping::Cyclone);
        assert_eq!(m(Some("rmw_fastrtps_cpp")), ServiceMapping::Enhanced);
        assert_eq!(m(None), ServiceMapping::Enhanced);
    }
}
