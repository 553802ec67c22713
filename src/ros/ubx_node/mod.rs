//! The `gnss_ins_ubx_node` ROS 2 node: the u-blox drivers' raw GNSS in, GnssMeasurements
//! out, through the DDS-free [`UbxAdapter`]; the command line, /diagnostics, /rosout and
//! the parameter services as `gnss_ins_node` has them (the shared plumbing of
//! [`crate::ros::node`]).
//!
//! Topics (relative, so `__ns` and remappings apply; the names are parameters, see
//! [`params`]): subscribes `ubx_rxm_rawx` (ublox_ubx_msgs/UBXRxmRawx), `ubx_rxm_sfrbx`
//! (UBXRxmSfrbx), `ubx_raw` (std_msgs/UInt8MultiArray), `imu` (sensor_msgs/Imu, for the
//! clock check) and `/clock`; publishes `gnss/measurements`, `/diagnostics` (1 Hz) and
//! `/rosout`.

pub mod param_server;
pub mod params;

use futures::stream::{self, LocalBoxStream, StreamExt};

use crate::ros::args::NodeArgs;
use crate::ros::log_limit::LogLimiter;
use crate::ros::msg::{
    Clock, DiagnosticArray, GnssMeasurements, Header, Imu, Log, UInt8MultiArray, UbxRxmRawx,
    UbxRxmSfrbx,
};
use crate::ros::node::clock::NodeClock;
use crate::ros::node::dds::{self, events, subscription, DdsOptions, Names, NodeError, Output};
use crate::ros::node::housekeeping;
use crate::ros::node::input_stats::{InputStats, StreamSet};
use crate::ros::node::rosout::{self, LogLine, LogLines};
use crate::ros::node::services::{ParamRequest, ParameterServices};
use crate::ros::ubx_adapter::UbxAdapter;

use param_server::UbxParameterServer;
use params::UbxNodeParams;

/// The default node name.
pub const DEFAULT_NODE_NAME: &str = "gnss_ins_ubx_node";

/// The usage text of `gnss_ins_ubx_node --help`.
pub const USAGE: &str = "\
Usage: gnss_ins_ubx_node [--record OUT.mcap] [--ros-args ROS_ARGUMENTS...]

Raw GNSS of a u-blox receiver (ublox_dgnss UBXRxmRawx/UBXRxmSfrbx, or the ublox_gps byte
stream) -> GnssMeasurements for gnss_ins_node (speaks DDS itself; honours ROS_DOMAIN_ID and
RMW_IMPLEMENTATION).

Node arguments:
  --record OUT.mcap          also write everything the node publishes to a rosbag2 bag
  -h, --help                 print this text and exit

ROS arguments (after --ros-args, as rcl parses them): --params-file FILE, -p NAME:=VALUE,
-r FROM:=TO (__node:=NAME, __ns:=/NS), --log-level [LOGGER:=]LEVEL, as gnss_ins_node.

Parameters: time_base (gnss|host), leap_seconds, host_latency_s, max_imu_gnss_skew_s,
ionosphere (iono_free|broadcast|none), frame_id, offset_window_epochs, the topics
rawx_topic, sfrbx_topic, stream_topic, imu_topic, measurements_topic, and use_sim_time,
queue_depth: docs/parameters.md.

Example (ublox_dgnss at the root namespace, this node in /vehicle):
  gnss_ins_ubx_node --ros-args -r __ns:=/vehicle -r ubx_rxm_rawx:=/ubx_rxm_rawx \\
      -r ubx_rxm_sfrbx:=/ubx_rxm_sfrbx -r imu:=imu/data -p time_base:=host
";

enum Event {
    Rawx(Result<UbxRxmRawx, String>),
    Sfrbx(Result<UbxRxmSfrbx, String>),
    Stream(Result<UInt8MultiArray, String>),
    Imu(Result<Box<Imu>, String>),
    Clock(Result<Clock, String>),
    Param(ParamRequest),
    LogLine(LogLine),
    Tick,
    Shutdown,
}

impl Event {
    /// The index in [`UBX_NODE_STREAMS`] of an input message (decodable or not).
    fn stream(&self) -> Option<usize> {
        match self {
            Self::Rawx(_) => Some(0),
            Self::Sfrbx(_) => Some(1),
            Self::Stream(_) => Some(2),
            Self::Imu(_) => Some(3),
            _ => None,
        }
    }
}

/// Choice: a receiver outputs RAWX at 1–20 Hz; three silent seconds (three missed epochs
/// at 1 Hz) while it was heard before means it stopped, and /diagnostics says so.
const RECEIVER_STALE_S: f64 = 3.0;

/// The node's input streams on /diagnostics; the receiver's (RAWX, or the UBX byte stream
/// of ublox_gps) are watched.
const UBX_NODE_STREAMS: StreamSet = StreamSet {
    keys: &["rawx", "sfrbx", "ubx_stream", "imu"],
    watched: &[(0, RECEIVER_STALE_S), (2, RECEIVER_STALE_S)],
};

/// Runs the node until the process is stopped (or the DDS streams end). `log_lines`
/// (from [`rosout::init_logging`]) are published on `/rosout`.
pub fn run(
    args: &NodeArgs,
    params: UbxNodeParams,
    dds: DdsOptions,
    log_lines: Option<LogLines>,
) -> Result<(), NodeError> {
    let mut adapter =
        UbxAdapter::new(params.adapter.clone()).map_err(|e| NodeError::Parameter(e.to_string()))?;
    let mut node = dds::create_node(args, dds)?;
    let names = Names {
        args,
        queue_depth: params.queue_depth,
    };
    let topics = params.topics.clone();
    let rawx_sub = subscription::<UbxRxmRawx>(&mut node, &names, &topics.rawx)?;
    let sfrbx_sub = subscription::<UbxRxmSfrbx>(&mut node, &names, &topics.sfrbx)?;
    let stream_sub = subscription::<UInt8MultiArray>(&mut node, &names, &topics.stream)?;
    let imu_sub = subscription::<Imu>(&mut node, &names, &topics.imu)?;
    let clock_sub = subscription::<Clock>(&mut node, &names, "/clock")?;
    let measurements = Output::<GnssMeasurements>::new(&mut node, &names, &topics.measurements)?;
    let diagnostics = Output::<DiagnosticArray>::new(&mut node, &names, "/diagnostics")?;
    let rosout = Output::<Log>::with_qos(&mut node, &names, "/rosout", dds::rosout_qos())?;
    let services = ParameterServices::new(&mut node, dds.service_mapping)?;
    let mut recorder = dds::recorder(args)?;
    let fqn = node.fully_qualified_name();
    let logger = rosout::logger_name(&fqn);
    let mut parameters = UbxParameterServer::new(params);
    let mut clock = NodeClock::default();
    let mut log = LogLimiter::default();
    let mut stats = InputStats::new(UBX_NODE_STREAMS);

    let mut sources: Vec<LocalBoxStream<'_, Event>> = vec![
        events(&rawx_sub, Event::Rawx),
        events(&sfrbx_sub, Event::Sfrbx),
        events(&stream_sub, Event::Stream),
        events(&imu_sub, |r| Event::Imu(r.map(Box::new))),
        events(&clock_sub, Event::Clock),
    ];
    sources.extend(housekeeping::housekeeping(
        &services,
        log_lines,
        housekeeping::Housekeeping {
            tick: || Event::Tick,
            param: Event::Param,
            log_line: Event::LogLine,
            stop: || Event::Shutdown,
        },
    ));
    let mut events = stream::select_all(sources);
    log::info!("{fqn} running on DDS domain {}", dds.domain_id);

    smol::block_on(async {
        while let Some(event) = events.next().await {
            let use_sim_time = parameters.use_sim_time();
            let arrival_s = clock.now_s(use_sim_time);
            if let Some(stream) = event.stream() {
                stats.record(stream, arrival_s);
            }
            let out: Vec<GnssMeasurements> = match event {
                Event::Rawx(Ok(m)) => adapter.on_rawx(&m, arrival_s).into_iter().collect(),
                Event::Sfrbx(Ok(m)) => {
                    adapter.on_sfrbx(&m);
                    Vec::new()
                }
                Event::Stream(Ok(m)) => adapter.on_stream_chunk(&m, arrival_s),
                Event::Imu(Ok(m)) => {
                    adapter.on_imu(&m, arrival_s);
                    Vec::new()
                }
                Event::Clock(Ok(m)) => {
                    clock.on_clock(&m);
                    Vec::new()
                }
                Event::Rawx(Err(e)) => undecodable(&mut adapter, &topics.rawx, &e),
                Event::Sfrbx(Err(e)) => undecodable(&mut adapter, &topics.sfrbx, &e),
                Event::Stream(Err(e)) => undecodable(&mut adapter, &topics.stream, &e),
                Event::Imu(Err(e)) => undecodable(&mut adapter, &topics.imu, &e),
                Event::Clock(Err(e)) => undecodable(&mut adapter, "/clock", &e),
                Event::Param(request) => {
                    services.answer(request, &mut parameters);
                    Vec::new()
                }
                Event::LogLine(line) => {
                    let stamp = clock.now(use_sim_time);
                    let message = rosout::rosout_message(line, &logger, stamp);
                    // Not logged again: a failure here would feed itself.
                    let _ = rosout.send(message, &mut recorder, stamp);
                    Vec::new()
                }
                Event::Tick => {
                    let stamp = clock.now(use_sim_time);
                    let report = DiagnosticArray {
                        header: Header {
                            stamp,
                            frame_id: String::new(),
                        },
                        status: vec![{
                            let mut status = adapter.diagnostics(&fqn);
                            stats.report(&mut status, arrival_s);
                            status
                        }],
                    };
                    if let Err(e) = diagnostics.send(report, &mut recorder, stamp) {
                        log::warn!("publishing diagnostics failed: {e}");
                    }
                    Vec::new()
                }
                Event::Shutdown => {
                    log::info!("{fqn}: stopping on a signal");
                    break;
                }
            };
            let stamp = clock.now(use_sim_time);
            for m in out {
                if let Err(e) = measurements.send(m, &mut recorder, stamp) {
                    log.warn("publish", &format!("publish failed: {e}"));
                }
            }
        }
    });
    if let Some(recorder) = recorder.take() {
        recorder.finish();
    }
    Ok(())
}

fn undecodable(adapter: &mut UbxAdapter, topic: &str, error: &str) -> Vec<GnssMeasurements> {
    adapter.on_undecodable(topic, error);
    Vec::new()
}
