//! The `gnss_ins_node` ROS 2 node: DDS subscriptions and publishers around the
//! [`RosAdapter`] (which `gnss_ins replay` drives from a bag).
//!
//! Topics (relative, so `__ns` and remappings apply): subscribes `imu`
//! (sensor_msgs/Imu), `gnss/measurements` (GnssMeasurements), `gnss/fix` (NavSatFix),
//! `gnss/velocity` (TwistWithCovarianceStamped), with `wheel_odometry.enabled`
//! `wheel/odometry` (nav_msgs/Odometry of the base controller), with
//! `dual_antenna.enabled` `ubx_nav_rel_pos_ned` (ublox_ubx_msgs/UBXNavRelPosNED of a
//! moving-base pair, as ublox_dgnss names it), `/clock`
//! (rosgraph_msgs/Clock, for `use_sim_time`); publishes `odometry` (nav_msgs/Odometry,
//! `map_frame` → `base_frame`), `fix/filtered` (NavSatFix), `~/noise_estimates`
//! (NoiseEstimates), `/diagnostics` (DiagnosticArray, 1 Hz and at shutdown), `/rosout`
//! (rcl_interfaces/Log), `/parameter_events` (rcl_interfaces/ParameterEvent: each
//! parameter declared at the start, then each accepted set, as rclcpp announces them)
//! and, with `publish_tf`, `/tf`
//! (tf2_msgs/TFMessage: `map_frame → base_frame`, or in `tf_mode` `map_to_odom`
//! `map_frame → odom_frame`, for which it also subscribes `/tf` to hear the base
//! controller's `odom_frame → base_frame`). Serves the parameter services ([`services`]).

pub mod clock;
pub mod dds;
pub mod housekeeping;
pub mod input_stats;
pub mod param_server;
pub mod params;
pub mod recorder;
pub mod rosout;
pub mod services;
pub mod startup;

use futures::stream::{self, LocalBoxStream, StreamExt};

use crate::ros::adapter::{Published, PublishedSolution, RosAdapter, SolutionMessages, TfMode};
use crate::ros::args::NodeArgs;
use crate::ros::log_limit::LogLimiter;
use crate::ros::msg::{
    Clock, DiagnosticArray, GnssMeasurements, Imu, Log, NavSatFix, NoiseEstimates, Odometry,
    ParameterEvent, TFMessage, Time, TwistWithCovarianceStamped, UbxNavRelPosNed,
};

use clock::NodeClock;
pub use dds::{domain_id_from, DdsOptions, NodeError, DIAGNOSTICS_PERIOD};
use dds::{events, subscription, Names, Output};
use input_stats::{InputStats, Stream, FILTER_NODE_STREAMS};
use param_server::ParameterServer;
use params::NodeParams;
use recorder::Recorder;
use rosout::{LogLine, LogLines};
pub use services::service_mapping_from;
use services::{CoreParameters, ParamRequest, ParameterServices};

enum Event {
    Imu(Result<Imu, String>),
    Gnss(Result<GnssMeasurements, String>),
    Fix(Result<NavSatFix, String>),
    Velocity(Result<TwistWithCovarianceStamped, String>),
    WheelOdometry(Result<Box<Odometry>, String>),
    RelPosNed(Result<Box<UbxNavRelPosNed>, String>),
    Clock(Result<Clock, String>),
    Tf(Result<TFMessage, String>),
    Param(ParamRequest),
    LogLine(LogLine),
    Tick,
    Shutdown,
}

struct Outputs {
    odometry: Output<Odometry>,
    fix: Output<NavSatFix>,
    noise: Output<NoiseEstimates>,
    /// Only with `publish_tf` and a `tf_mode` other than `none`.
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
                Published::NoFix(fix) => {
                    log_failure(log, self.fix.send(*fix, recorder, now));
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
    let mut node = dds::create_node(args, dds)?;
    let names = Names {
        args,
        queue_depth: params.queue_depth,
    };
    let imu_sub = subscription::<Imu>(&mut node, &names, "imu")?;
    let gnss_sub = subscription::<GnssMeasurements>(&mut node, &names, "gnss/measurements")?;
    let fix_sub = subscription::<NavSatFix>(&mut node, &names, "gnss/fix")?;
    let velocity_sub =
        subscription::<TwistWithCovarianceStamped>(&mut node, &names, "gnss/velocity")?;
    let wheel_sub = if params.config.wheel_odometry.enabled {
        Some(subscription::<Odometry>(
            &mut node,
            &names,
            "wheel/odometry",
        )?)
    } else {
        None
    };
    let rel_pos_sub = if params.config.dual_antenna.enabled {
        Some(subscription::<UbxNavRelPosNed>(
            &mut node,
            &names,
            "ubx_nav_rel_pos_ned",
        )?)
    } else {
        None
    };
    let clock_sub = subscription::<Clock>(&mut node, &names, "/clock")?;
    let tf_sub = if params.frames.published_tf() == TfMode::MapToOdom {
        Some(subscription::<TFMessage>(&mut node, &names, "/tf")?)
    } else {
        None
    };
    let mut outputs = Outputs {
        odometry: Output::new(&mut node, &names, "odometry")?,
        fix: Output::new(&mut node, &names, "fix/filtered")?,
        noise: Output::new(&mut node, &names, "~/noise_estimates")?,
        tf: if params.frames.published_tf() != TfMode::None {
            Some(Output::new(&mut node, &names, "/tf")?)
        } else {
            None
        },
        recorder: dds::recorder(args)?,
        log: LogLimiter::default(),
    };
    let diagnostics = Output::<DiagnosticArray>::new(&mut node, &names, "/diagnostics")?;
    let rosout = Output::<Log>::with_qos(&mut node, &names, "/rosout", dds::rosout_qos())?;
    let services = ParameterServices::new(&mut node, dds.service_mapping)?;
    // Not recorded: the bag writer has no definition of rcl_interfaces' parameter types.
    let parameter_events = dds::publisher_with::<ParameterEvent>(
        &mut node,
        &names,
        "/parameter_events",
        dds::parameter_events_qos(),
    )?;
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
    let stamp = clock.now(parameters.use_sim_time());
    for event in parameters.declaration_events(core.engine().config(), &fqn, stamp) {
        publish_parameter_event(&parameter_events, event);
    }
    let mut stats = InputStats::new(FILTER_NODE_STREAMS);

    let mut sources: Vec<LocalBoxStream<'_, Event>> = vec![
        events(&imu_sub, Event::Imu),
        events(&gnss_sub, Event::Gnss),
        events(&fix_sub, Event::Fix),
        events(&velocity_sub, Event::Velocity),
        events(&clock_sub, Event::Clock),
    ];
    sources.extend(
        wheel_sub
            .as_ref()
            .map(|sub| events(sub, |m| Event::WheelOdometry(m.map(Box::new)))),
    );
    sources.extend(
        rel_pos_sub
            .as_ref()
            .map(|sub| events(sub, |m| Event::RelPosNed(m.map(Box::new)))),
    );
    sources.extend(tf_sub.as_ref().map(|sub| events(sub, Event::Tf)));
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
    log::info!(
        "{fqn} running filter variant {} on DDS domain {}{}",
        core.engine().variant_name(),
        dds.domain_id,
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
                    stats.record(Stream::Imu.index(), now_s());
                    match m {
                        Ok(m) => core.on_imu(&m),
                        Err(e) => undecodable(&mut core, "imu", &e),
                    }
                }
                Event::Gnss(m) => {
                    stats.record(Stream::Gnss.index(), now_s());
                    match m {
                        Ok(m) => core.on_gnss(&m),
                        Err(e) => undecodable(&mut core, "gnss/measurements", &e),
                    }
                }
                Event::Fix(m) => {
                    stats.record(Stream::Fix.index(), now_s());
                    match m {
                        Ok(m) => core.on_fix(&m),
                        Err(e) => undecodable(&mut core, "gnss/fix", &e),
                    }
                }
                Event::Velocity(m) => {
                    stats.record(Stream::Velocity.index(), now_s());
                    match m {
                        Ok(m) => core.on_velocity(&m),
                        Err(e) => undecodable(&mut core, "gnss/velocity", &e),
                    }
                }
                Event::WheelOdometry(m) => {
                    stats.record(Stream::WheelOdometry.index(), now_s());
                    match m {
                        Ok(m) => core.on_wheel_odometry(&m),
                        Err(e) => undecodable(&mut core, "wheel/odometry", &e),
                    }
                }
                Event::RelPosNed(m) => {
                    stats.record(Stream::RelPosNed.index(), now_s());
                    match m {
                        Ok(m) => core.on_rel_pos_ned(&m),
                        Err(e) => undecodable(&mut core, "ubx_nav_rel_pos_ned", &e),
                    }
                }
                Event::Clock(Ok(m)) => {
                    clock.on_clock(&m);
                    Vec::new()
                }
                Event::Clock(Err(e)) => undecodable(&mut core, "/clock", &e),
                Event::Tf(Ok(m)) => {
                    core.on_tf(&m);
                    Vec::new()
                }
                Event::Tf(Err(e)) => undecodable(&mut core, "/tf", &e),
                Event::Param(request) => {
                    let mut handler = CoreParameters {
                        server: &mut parameters,
                        core: &mut core,
                    };
                    services.answer(request, &mut handler);
                    let stamp = clock.now(parameters.use_sim_time());
                    for event in parameters.take_events(&fqn, stamp) {
                        publish_parameter_event(&parameter_events, event);
                    }
                    Vec::new()
                }
                Event::LogLine(line) => {
                    let stamp = clock.now(parameters.use_sim_time());
                    let message = rosout::rosout_message(line, &logger, stamp);
                    // Not logged again: a failure here would feed itself.
                    let _ = rosout.send(message, &mut outputs.recorder, stamp);
                    Vec::new()
                }
                // Choice: a last report on the way out, so that the counts of the whole
                // run are on /diagnostics (and in a recording), not those of the last tick.
                event @ (Event::Tick | Event::Shutdown) => {
                    let stamp = clock.now(parameters.use_sim_time());
                    let mut report = core.diagnostics(&fqn, stamp);
                    if let Some(status) = report.status.first_mut() {
                        stats.report(status, now_s());
                    }
                    if let Err(e) = diagnostics.send(report, &mut outputs.recorder, stamp) {
                        log::warn!("publishing diagnostics failed: {e}");
                    }
                    if matches!(event, Event::Shutdown) {
                        log::info!("{fqn}: stopping on a signal");
                        break;
                    }
                    Vec::new()
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

fn publish_parameter_event(
    publisher: &ros2_client::Publisher<ParameterEvent>,
    event: ParameterEvent,
) {
    if let Err(e) = publisher.publish(event) {
        log::warn!("publishing /parameter_events failed: {e:?}");
    }
}

fn undecodable(core: &mut RosAdapter, topic: &str, error: &str) -> Vec<Published> {
    core.on_undecodable(topic, error);
    Vec::new()
}
