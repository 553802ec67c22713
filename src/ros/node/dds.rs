//! The DDS plumbing both nodes share (`gnss_ins_node`, `gnss_ins_ubx_node`): the ROS node
//! and its participant, topic names resolved with the command line's namespace and
//! remappings, the QoS of inputs, outputs and `/rosout`, publishers that also record, and
//! the stop signals.

use std::time::Duration;

use futures::stream::{LocalBoxStream, StreamExt};
use ros2_client::{
    qos::{Durability, History},
    Context, ContextOptions, MessageInfo, MessageTypeName, Name, Node, NodeName, NodeOptions,
    Publisher, QosProfile, ReadResult, ServiceMapping, Subscription,
};

use crate::ros::args::NodeArgs;
use crate::ros::msg::{RosMessage, Time};
use crate::ros::names::resolve_remapped;

use super::recorder::Recorder;

/// Period of the /diagnostics report.
pub const DIAGNOSTICS_PERIOD: Duration = Duration::from_secs(1);

/// Why the node could not start or stopped.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    #[error("ROS_DOMAIN_ID `{0}` is not a number in 0..=232")]
    BadDomainId(String),
    #[error("cannot create the DDS participant or node: {0}")]
    Dds(String),
    #[error("invalid topic name `{0}`")]
    TopicName(String),
    #[error("{0}")]
    Record(String),
    #[error("{0}")]
    Parameter(String),
}

/// The DDS domain of `ROS_DOMAIN_ID` (unset or empty: 0).
pub fn domain_id_from(value: Option<&str>) -> Result<u16, NodeError> {
    match value.map(str::trim) {
        None | Some("") => Ok(0),
        Some(v) => v
            .parse::<u16>()
            .ok()
            .filter(|d| *d <= 232)
            .ok_or_else(|| NodeError::BadDomainId(v.to_owned())),
    }
}

pub fn dds_error(e: impl std::fmt::Debug) -> NodeError {
    NodeError::Dds(format!("{e:?}"))
}

/// The `MessageTypeName` of a ROS message type (`pkg/msg/Name`).
pub fn type_name<M: RosMessage>() -> MessageTypeName {
    let package = M::TYPE_NAME.split('/').next().unwrap_or_default();
    let name = M::TYPE_NAME.rsplit('/').next().unwrap_or_default();
    MessageTypeName::new(package, name)
}

/// Best-effort subscription QoS: matches both best-effort and reliable publishers.
fn sensor_qos(depth: usize) -> QosProfile {
    QosProfile::subscription_default()
        .reliability_best_effort()
        .history(History::KeepLast { depth })
}

/// Reliable publisher QoS (matches reliable and best-effort subscribers).
fn output_qos(depth: usize) -> QosProfile {
    QosProfile::publisher_default().history(History::KeepLast { depth })
}

/// `/rosout` QoS as rcl offers it: reliable, transient local, the last 1000 lines (so a
/// late `rqt_console` sees the start-up lines, and volatile readers match too).
pub fn rosout_qos() -> QosProfile {
    QosProfile::publisher_default()
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1000 })
}

/// Topic naming and the history depth of the node's DDS entities.
pub struct Names<'a> {
    pub args: &'a NodeArgs,
    pub queue_depth: usize,
}

impl Names<'_> {
    pub fn topic(&self, relative: &str) -> Result<Name, NodeError> {
        let a = self.args;
        let full = resolve_remapped(relative, &a.namespace, &a.node_name, &a.remaps);
        Name::parse(&full).map_err(|_| NodeError::TopicName(full.clone()))
    }
}

pub fn subscription<M: RosMessage + 'static>(
    node: &mut Node,
    names: &Names,
    relative: &str,
) -> Result<Subscription<M>, NodeError> {
    let name = names.topic(relative)?;
    let topic = node
        .create_topic(&name, type_name::<M>(), &sensor_qos(names.queue_depth))
        .map_err(dds_error)?;
    log::info!("subscribing {name} ({})", M::TYPE_NAME);
    node.create_subscription::<M>(&topic, Some(sensor_qos(names.queue_depth)))
        .map_err(dds_error)
}

/// `/parameter_events` QoS as rclcpp offers it (`rmw_qos_profile_parameter_events`):
/// reliable, volatile, the last 1000 events.
pub fn parameter_events_qos() -> QosProfile {
    QosProfile::publisher_default().history(History::KeepLast { depth: 1000 })
}

/// A publisher on `relative` resolved by `names` (not recorded: see [`Output`]).
pub fn publisher_with<M: RosMessage>(
    node: &mut Node,
    names: &Names,
    relative: &str,
    qos: QosProfile,
) -> Result<Publisher<M>, NodeError> {
    let name = names.topic(relative)?;
    let topic = node
        .create_topic(&name, type_name::<M>(), &qos)
        .map_err(dds_error)?;
    log::info!("publishing {name} ({})", M::TYPE_NAME);
    node.create_publisher::<M>(&topic, Some(qos))
        .map_err(dds_error)
}

/// How the node meets the DDS world: the domain and the service request/reply mapping.
#[derive(Debug, Clone, Copy)]
pub struct DdsOptions {
    /// `ROS_DOMAIN_ID`.
    pub domain_id: u16,
    /// From `RMW_IMPLEMENTATION`, see [`service_mapping_from`].
    pub service_mapping: ServiceMapping,
}

/// A publisher with its resolved topic name (what a recording names the topic).
pub struct Output<M: RosMessage> {
    publisher: Publisher<M>,
    topic: String,
}

impl<M: RosMessage + std::fmt::Debug> Output<M> {
    pub fn new(node: &mut Node, names: &Names, relative: &str) -> Result<Self, NodeError> {
        Self::with_qos(node, names, relative, output_qos(names.queue_depth))
    }

    pub fn with_qos(
        node: &mut Node,
        names: &Names,
        relative: &str,
        qos: QosProfile,
    ) -> Result<Self, NodeError> {
        Ok(Self {
            publisher: publisher_with(node, names, relative, qos)?,
            topic: names.topic(relative)?.to_string(),
        })
    }

    /// Publishes `message`, recording it first when a recording is open.
    pub fn send(
        &self,
        message: M,
        recorder: &mut Option<Recorder>,
        now: Time,
    ) -> Result<(), String> {
        if let Some(r) = recorder.as_mut() {
            r.record(&self.topic, &message, now);
        }
        self.publisher
            .publish(message)
            .map_err(|e| format!("{}: {e:?}", self.topic))
    }
}

/// The participant on `dds`'s domain and the node named by `args`. ros2-client's own
/// rosout, parameter services and sim time stay off: the nodes serve their parameters
/// themselves and their /clock has the wrong type.
pub fn create_node(args: &NodeArgs, dds: DdsOptions) -> Result<Node, NodeError> {
    let context =
        Context::with_options(ContextOptions::new().domain_id(dds.domain_id)).map_err(dds_error)?;
    let node_name = NodeName::new(&args.namespace, &args.node_name).map_err(dds_error)?;
    context
        .new_node(
            node_name,
            NodeOptions::new()
                .enable_rosout(false)
                .start_parameter_services(false),
        )
        .map_err(dds_error)
}

/// The message of a read, or why it did not decode.
pub fn decoded<M>(r: ReadResult<(M, MessageInfo)>) -> Result<M, String> {
    r.map(|(m, _)| m).map_err(|e| format!("{e:?}"))
}

/// The decoded messages of `subscription`, each wrapped by `event`.
pub fn events<'a, M: RosMessage + 'static, E: 'a>(
    subscription: &'a Subscription<M>,
    event: fn(Result<M, String>) -> E,
) -> LocalBoxStream<'a, E> {
    subscription
        .async_stream()
        .map(move |r| event(decoded(r)))
        .boxed_local()
}

/// The recording of `args.record`, if asked for.
pub fn recorder(args: &NodeArgs) -> Result<Option<Recorder>, NodeError> {
    args.record
        .as_ref()
        .map(|path| Recorder::create(path).map_err(NodeError::Record))
        .transpose()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::msg::{DiagnosticArray, GnssMeasurements, Imu};

    #[test]
    fn domain_id_parsing() {
        assert_eq!(domain_id_from(None).unwrap(), 0);
        assert_eq!(domain_id_from(Some("")).unwrap(), 0);
        assert_eq!(domain_id_from(Some("42")).unwrap(), 42);
        assert!(domain_id_from(Some("233")).is_err());
        assert!(domain_id_from(Some("x")).is_err());
    }

    #[test]
    fn dds_type_names_match_the_messages() {
        assert_eq!(type_name::<Imu>().dds_msg_type(), Imu::DDS_TYPE_NAME);
        assert_eq!(
            type_name::<GnssMeasurements>().dds_msg_type(),
            GnssMeasurements::DDS_TYPE_NAME
        );
        assert_eq!(
            type_name::<DiagnosticArray>().dds_msg_type(),
            DiagnosticArray::DDS_TYPE_NAME
        );
    }
}
