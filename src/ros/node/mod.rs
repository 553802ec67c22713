//! The `gnss_ins_node` ROS 2 node: DDS subscriptions and publishers around the
//! [`RosAdapter`] (which `gnss_ins replay` drives from a bag).
//!
//! Topics (relative, so `__ns` and remappings apply): subscribes `imu`
//! (sensor_msgs/Imu), `gnss/measurements` (GnssMeasurements), `gnss/fix` (NavSatFix),
//! `gnss/velocity` (TwistWithCovarianceStamped), `/clock` (rosgraph_msgs/Clock, for
//! `use_sim_time`); publishes `odometry` (nav_msgs/Odometry, `map_frame` → `base_frame`),
//! `fix` (NavSatFix), `~/noise_estimates` (NoiseEstimates), `/diagnostics`
//! (DiagnosticArray, 1 Hz), `/rosout` (rcl_interfaces/Log) and, with `publish_tf`, `/tf`
//! (tf2_msgs/TFMessage). Serves the parameter services ([`services`]).

pub mod clock;
pub mod input_stats;
pub mod param_server;
pub mod params;
pub mod recorder;
pub mod rosout;
pub mod services;

use std::time::Duration;

use futures::stream::{self, LocalBoxStream, StreamExt};
use ros2_client::{
    qos::{Durability, History},
    Context, ContextOptions, MessageInfo, MessageTypeName, Name, Node, NodeName, NodeOptions,
    Publisher, QosProfile, ReadResult, ServiceMapping, Subscription,
};

use crate::ros::adapter::{Published, PublishedSolution, RosAdapter, SolutionMessages};
use crate::ros::args::NodeArgs;
use crate::ros::log_limit::LogLimiter;
use crate::ros::msg::{
    Clock, DiagnosticArray, GnssMeasurements, Imu, Log, NavSatFix, NoiseEstimates, Odometry,
    RosMessage, TFMessage, Time, TwistWithCovarianceStamped,
};
use crate::ros::names::resolve_remapped;

use clock::NodeClock;
use input_stats::{InputStats, Stream};
use param_server::ParameterServer;
use params::NodeParams;
use recorder::Recorder;
use rosout::{LogLine, LogLines};
pub use services::service_mapping_from;
use services::{ParamRequest, ParameterServices};

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

fn dds_error(e: impl std::fmt::Debug) -> NodeError {
    NodeError::Dds(format!("{e:?}"))
}

/// The `MessageTypeName` of a ROS message type (`pkg/msg/Name`).
fn type_name<M: RosMessage>() -> MessageTypeName {
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
fn rosout_qos() -> QosProfile {
    QosProfile::publisher_default()
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1000 })
}

/// Topic naming and the history depth of the node's DDS entities.
struct Names<'a> {
    args: &'a NodeArgs,
    queue_depth: usize,
}

impl Names<'_> {
    fn topic(&self, relative: &str) -> Result<Name, NodeError> {
        let a = self.args;
        let full = resolve_remapped(relative, &a.namespace, &a.node_name, &a.remaps);
        Name::parse(&full).map_err(|_| NodeError::TopicName(full.clone()))
    }
}

fn subscription<M: RosMessage + 'static>(
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

fn publisher_with<M: RosMessage>(
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

enum Event {
    Imu(Result<Imu, String>),
    Gnss(Result<GnssMeasurements, String>),
    Fix(Result<NavSatFix, String>),
    Velocity(Result<TwistWithCovarianceStamped, String>),
    Clock(Result<Clock, String>),
    Param(ParamRequest),
    LogLine(LogLine),
    Tick,
    Shutdown,
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
struct Output<M: RosMessage> {
    publisher: Publisher<M>,
    topic: String,
}

impl<M: RosMessage + std::fmt::Debug> Output<M> {
    fn new(node: &mut Node, names: &Names, relative: &str) -> Result<Self, NodeError> {
        Self::with_qos(node, names, relative, output_qos(names.queue_depth))
    }

    fn with_qos(
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
    fn send(&self, message: M, recorder: &mut Option<Recorder>, now: Time) -> Result<(), String> {
        if let Some(r) = recorder.as_mut() {
            r.record(&self.topic, &message, now);
        }
        self.publisher
            .publish(message)
            .map_err(|e| format!("{}: {e:?}", self.topic))
    }
}

struct Outputs {
    odometry: Output<Odometry>,
    fix: Output<NavSatFix>,
    noise: Output<NoiseEstimates>,
    /// Only with `publish_tf`.
    tf: Option<Output<TFMessage>>,
    recorder: Option<Recorder>,
    log: LogLimiter,
}

impl Outputs {
    /// Publishes each output's messages: the TF (with `publish_tf`) before its Odometry.
    fn publish(&mut self, published: Vec<Published>, now: Time) {
        for p in published {
            let recorder = &mut self.recorder;
            let log = &mut self.log;
            match p {
                Published::Solution(PublishedSolution { messages, .. }) => {
                    // The node's adapter frames every solution.
                    let Some(m) = messages else { continue };
                    let SolutionMessages { odometry, fix, tf } = *m;
                    if let (Some(t), Some(out)) = (tf, &self.tf) {
                        log_failure(log, out.send(t, recorder, now));
                    }
                    log_failure(log, self.odometry.send(odometry, recorder, now));
                    log_failure(log, self.fix.send(fix, recorder, now));
                }
                Published::Epoch(epoch) => {
                    log_failure(log, self.noise.send(epoch.noise, recorder, now));
                }
            }
        }
    }
}

fn log_failure(log: &mut LogLimiter, sent: Result<(), String>) {
    if let Err(e) = sent {
        log.warn("publish", &format!("publish failed: {e}"));
    }
}

/// Runs the node until the process is stopped (or the DDS streams end). `log_lines`
/// (from [`rosout::init_logging`]) are published on `/rosout`.
pub fn run(
    args: &NodeArgs,
    params: NodeParams,
    dds: DdsOptions,
    log_lines: Option<LogLines>,
) -> Result<(), NodeError> {
    let domain_id = dds.domain_id;
    let context =
        Context::with_options(ContextOptions::new().domain_id(domain_id)).map_err(dds_error)?;
    let node_name = NodeName::new(&args.namespace, &args.node_name).map_err(dds_error)?;
    // ros2-client's own rosout, parameter services and sim time stay off: the node
    // serves its configuration itself and its /clock has the wrong type.
    let mut node = context
        .new_node(
            node_name,
            NodeOptions::new()
                .enable_rosout(false)
                .start_parameter_services(false),
        )
        .map_err(dds_error)?;
    let names = Names {
        args,
        queue_depth: params.queue_depth,
    };
    let imu_sub = subscription::<Imu>(&mut node, &names, "imu")?;
    let gnss_sub = subscription::<GnssMeasurements>(&mut node, &names, "gnss/measurements")?;
    let fix_sub = subscription::<NavSatFix>(&mut node, &names, "gnss/fix")?;
    let velocity_sub =
        subscription::<TwistWithCovarianceStamped>(&mut node, &names, "gnss/velocity")?;
    let clock_sub = subscription::<Clock>(&mut node, &names, "/clock")?;
    let recorder = match &args.record {
        Some(path) => Some(Recorder::create(path).map_err(NodeError::Record)?),
        None => None,
    };
    let mut outputs = Outputs {
        odometry: Output::new(&mut node, &names, "odometry")?,
        fix: Output::new(&mut node, &names, "fix")?,
        noise: Output::new(&mut node, &names, "~/noise_estimates")?,
        tf: if params.frames.publish_tf {
            Some(Output::new(&mut node, &names, "/tf")?)
        } else {
            None
        },
        recorder,
        log: LogLimiter::default(),
    };
    let diagnostics = Output::<DiagnosticArray>::new(&mut node, &names, "/diagnostics")?;
    let rosout = Output::<Log>::with_qos(&mut node, &names, "/rosout", rosout_qos())?;
    let services = ParameterServices::new(&mut node, dds.service_mapping)?;
    let config = params.config;
    let fqn = node.fully_qualified_name();
    let logger = rosout::logger_name(&fqn);
    let mut core = RosAdapter::new(config, params.frames.clone());
    if let Some(imu_frame) = &params.imu_frame {
        core = core.with_imu_frame(imu_frame);
    }
    let mut parameters = ParameterServer::new(params.use_sim_time, params.frames)
        .with_queue_depth(params.queue_depth)
        .with_imu_frame(params.imu_frame);
    let mut clock = NodeClock::default();
    let mut stats = InputStats::default();

    let mut sources: Vec<LocalBoxStream<'_, Event>> = vec![
        imu_sub
            .async_stream()
            .map(|r| Event::Imu(decoded(r)))
            .boxed_local(),
        gnss_sub
            .async_stream()
            .map(|r| Event::Gnss(decoded(r)))
            .boxed_local(),
        fix_sub
            .async_stream()
            .map(|r| Event::Fix(decoded(r)))
            .boxed_local(),
        velocity_sub
            .async_stream()
            .map(|r| Event::Velocity(decoded(r)))
            .boxed_local(),
        clock_sub
            .async_stream()
            .map(|r| Event::Clock(decoded(r)))
            .boxed_local(),
        smol::Timer::interval(DIAGNOSTICS_PERIOD)
            .map(|_| Event::Tick)
            .boxed_local(),
    ];
    sources.extend(
        services
            .streams()
            .into_iter()
            .map(|s| s.map(Event::Param).boxed_local()),
    );
    if let Some(lines) = log_lines {
        sources.push(lines.map(Event::LogLine).boxed_local());
    }
    // SIGINT / SIGTERM end the loop so that a recording is completed; without a handler
    // the process would die with the bag unfinished.
    match async_signal::Signals::new([async_signal::Signal::Int, async_signal::Signal::Term]) {
        Ok(signals) => sources.push(signals.map(|_| Event::Shutdown).boxed_local()),
        Err(e) => log::warn!("cannot handle SIGINT/SIGTERM ({e}); stopping kills the node"),
    }
    let mut events = stream::select_all(sources);
    log::info!(
        "{fqn} running filter variant {} on DDS domain {domain_id}{}",
        core.engine().variant_name(),
        if parameters.use_sim_time() {
            " (use_sim_time: node time follows /clock)"
        } else {
            ""
        }
    );

    smol::block_on(async {
        while let Some(event) = events.next().await {
            let now_s = || clock.now_s(parameters.use_sim_time());
            let msgs = match event {
                Event::Imu(m) => {
                    stats.record(Stream::Imu, now_s());
                    match m {
                        Ok(m) => core.on_imu(&m),
                        Err(e) => undecodable(&mut core, "imu", &e),
                    }
                }
                Event::Gnss(m) => {
                    stats.record(Stream::Gnss, now_s());
                    match m {
                        Ok(m) => core.on_gnss(&m),
                        Err(e) => undecodable(&mut core, "gnss/measurements", &e),
                    }
                }
                Event::Fix(m) => {
                    stats.record(Stream::Fix, now_s());
                    match m {
                        Ok(m) => core.on_fix(&m),
                        Err(e) => undecodable(&mut core, "gnss/fix", &e),
                    }
                }
                Event::Velocity(m) => {
                    stats.record(Stream::Velocity, now_s());
                    match m {
                        Ok(m) => core.on_velocity(&m),
                        Err(e) => undecodable(&mut core, "gnss/velocity", &e),
                    }
                }
                Event::Clock(Ok(m)) => {
                    clock.on_clock(&m);
                    Vec::new()
                }
                Event::Clock(Err(e)) => undecodable(&mut core, "/clock", &e),
                Event::Param(request) => {
                    services.answer(request, &mut parameters, &mut core);
                    Vec::new()
                }
                Event::LogLine(line) => {
                    let stamp = clock.now(parameters.use_sim_time());
                    let message = rosout::rosout_message(line, &logger, stamp);
                    // Not logged again: a failure here would feed itself.
                    let _ = rosout.send(message, &mut outputs.recorder, stamp);
                    Vec::new()
                }
                Event::Tick => {
                    let stamp = clock.now(parameters.use_sim_time());
                    let mut report = core.diagnostics(&fqn, stamp);
                    if let Some(status) = report.status.first_mut() {
                        stats.report(status, now_s());
                    }
                    if let Err(e) = diagnostics.send(report, &mut outputs.recorder, stamp) {
                        log::warn!("publishing diagnostics failed: {e}");
                    }
                    Vec::new()
                }
                Event::Shutdown => {
                    log::info!("{fqn}: stopping on a signal");
                    break;
                }
            };
            outputs.publish(msgs, clock.now(parameters.use_sim_time()));
        }
    });
    if let Some(recorder) = outputs.recorder.take() {
        recorder.finish();
    }
    Ok(())
}

fn decoded<M>(r: ReadResult<(M, MessageInfo)>) -> Result<M, String> {
    r.map(|(m, _)| m).map_err(|e| format!("{e:?}"))
}

fn undecodable(core: &mut RosAdapter, topic: &str, error: &str) -> Vec<Published> {
    core.on_undecodable(topic, error);
    Vec::new()
}

#[cfg(test)]
mod tests {
    use super::*;

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
