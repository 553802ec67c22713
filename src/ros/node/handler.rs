//! The node's message handling without any DDS: decoded messages in, messages to publish
//! out. It converts, feeds the engine, counts and logs; it holds no filter math.

use crate::config::Config;
use crate::earth::Llh;
use crate::engine::{Engine, NotRuntimeTunable, Output, ResetReason, StatusEvent};
use crate::ins::ImuSample;
use crate::ros::convert::{seconds_to_time, time_to_seconds, GnssVelocity};
use crate::ros::fix_velocity::{FixVelocityJoin, FramedFix, Joined, VelocityUse};
use crate::ros::msg::{
    DiagnosticArray, DiagnosticStatus, GnssMeasurements, Header, Imu, KeyValue, NavSatFix,
    NoiseEstimates, Odometry, TFMessage, Time, TwistWithCovarianceStamped,
};
use crate::ros::outbound;
use crate::tools::bag_inputs::fix_of;

use super::log_limit::LogLimiter;
use super::params::OutputFrames;

/// Choice: an IMU stamp more than this much older than the last accepted one is a time
/// jump (a bag played in a loop) and resets the filter; smaller steps back are ordinary
/// out-of-order samples the engine rejects. 1 s is far beyond any transport reordering.
pub const TIME_JUMP_BACK_S: f64 = 1.0;

/// A message the node publishes.
#[derive(Debug, Clone, PartialEq)]
pub enum OutMsg {
    /// On `odometry`.
    Odometry(Box<Odometry>),
    /// On `fix`.
    Fix(NavSatFix),
    /// On `~/noise_estimates`.
    Noise(NoiseEstimates),
    /// On `/tf` (only with `publish_tf`).
    Tf(TFMessage),
}

/// The node's input streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Input {
    Imu,
    Gnss,
    Fix,
    Velocity,
}

impl Input {
    fn name(self) -> &'static str {
        match self {
            Input::Imu => "imu",
            Input::Gnss => "gnss/measurements",
            Input::Fix => "gnss/fix",
            Input::Velocity => "gnss/velocity",
        }
    }
}

/// Counts of what arrived and what was dropped before the engine.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InputCounts {
    /// Imu messages decoded.
    pub imu_received: u64,
    /// GnssMeasurements messages decoded.
    pub gnss_received: u64,
    /// NavSatFix messages decoded.
    pub fix_received: u64,
    /// TwistWithCovarianceStamped messages decoded on `gnss/velocity`.
    pub velocity_received: u64,
    /// Velocities fed to the engine with their fix.
    pub velocity_paired: u64,
    /// Payloads that did not decode, any topic.
    pub undecodable: u64,
    /// IMU messages that decoded but did not convert (bad stamp, NaN).
    pub unconvertible_imu: u64,
    /// GNSS messages that did not convert (bad stamp or time of week, unknown constellation).
    pub unconvertible_gnss: u64,
    /// NavSatFix messages without a solution or with a bad stamp.
    pub unconvertible_fix: u64,
    /// Velocities with a bad stamp or a non-finite value.
    pub unconvertible_velocity: u64,
    /// Resets because the IMU time jumped backwards.
    pub time_jump_resets: u64,
    /// Outputs not published because a value was not finite.
    pub non_finite_outputs: u64,
    /// IMU messages from another frame than the first accepted one (a second publisher).
    pub foreign_frame_imu: u64,
    /// GnssMeasurements messages from another frame than the first accepted one.
    pub foreign_frame_gnss: u64,
    /// NavSatFix messages from another frame than the first accepted one.
    pub foreign_frame_fix: u64,
    /// Velocities neither in the map frame nor in their fix's frame (fix used without).
    pub foreign_frame_velocity: u64,
}

/// The `header.frame_id` a stream is locked to.
///
/// Choice: the first message the engine accepts fixes the frame of its stream; messages
/// from any other frame are counted and dropped. Two sensors interleaved on one topic would
/// otherwise be fused as one (duplicate and backward stamps, mixed lever arms and
/// mounting), and the node has one IMU and one antenna. The lock survives filter resets.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
struct FrameLock(Option<String>);

impl FrameLock {
    /// True when no frame is locked yet or `frame_id` is the locked one.
    fn admits(&self, frame_id: &str) -> bool {
        self.0.as_deref().is_none_or(|locked| locked == frame_id)
    }

    /// Locks `frame_id` when no frame is locked yet.
    fn accepted(&mut self, frame_id: &str) {
        if self.0.is_none() {
            self.0 = Some(frame_id.to_owned());
        }
    }
}

/// Engine plus message conversion for one node.
pub struct NodeCore {
    engine: Engine,
    datum: Option<Llh>,
    counts: InputCounts,
    log: LogLimiter,
    imu_frame: FrameLock,
    gnss_frame: FrameLock,
    fix_frame: FrameLock,
    frames: OutputFrames,
    pairing: FixVelocityJoin,
}

impl NodeCore {
    /// A node core running `config`, publishing in `frames`.
    pub fn new(config: Config, frames: OutputFrames) -> Self {
        let datum = config.output.datum;
        Self {
            engine: Engine::new(config),
            datum,
            counts: InputCounts::default(),
            log: LogLimiter::default(),
            imu_frame: FrameLock::default(),
            gnss_frame: FrameLock::default(),
            fix_frame: FrameLock::default(),
            pairing: FixVelocityJoin::new(&frames.map_frame),
            frames,
        }
    }

    /// The input counters.
    pub fn counts(&self) -> &InputCounts {
        &self.counts
    }

    /// The engine (for its counters and phase).
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// Takes over a configuration that differs only in runtime parameters (see
    /// [`Engine::retune`]); the filter keeps running.
    pub fn retune(&mut self, config: Config) -> Result<(), NotRuntimeTunable> {
        self.engine.retune(config)
    }

    /// Records a payload on `topic` that did not decode.
    pub fn on_undecodable(&mut self, topic: &str, error: &str) {
        self.counts.undecodable += 1;
        self.log.warn(
            "undecodable",
            &format!("undecodable message on {topic}: {error}"),
        );
    }

    /// Handles one sensor_msgs/Imu.
    pub fn on_imu(&mut self, msg: &Imu) -> Vec<OutMsg> {
        self.counts.imu_received += 1;
        let sample = match ImuSample::try_from(msg) {
            Ok(s) => s,
            Err(e) => return self.unconvertible(Input::Imu, &e.to_string()),
        };
        if !self.imu_frame.admits(&msg.header.frame_id) {
            return self.foreign_frame(Input::Imu, &msg.header.frame_id);
        }
        let mut outputs = Vec::new();
        if let Some(last_t_s) = self.engine.last_imu_t_s() {
            if sample.t_s < last_t_s - TIME_JUMP_BACK_S {
                self.counts.time_jump_resets += 1;
                log::warn!(
                    "IMU time jumped back from {last_t_s:.3} s to {:.3} s: resetting the filter",
                    sample.t_s
                );
                outputs.push(
                    self.engine
                        .reset(sample.t_s, ResetReason::TimeJumpBackwards),
                );
                self.pairing.clear();
            }
        }
        let released = self.pairing.on_time(sample.t_s);
        outputs.extend(self.push_fixes(released));
        match self.engine.push_imu(&sample) {
            Ok(o) => {
                self.imu_frame.accepted(&msg.header.frame_id);
                outputs.extend(o);
            }
            Err(e) => {
                self.log.warn(e.reason.name(), &format!("imu: {e}"));
            }
        }
        self.publishable(outputs)
    }

    /// Handles one GnssMeasurements (tight coupling).
    pub fn on_gnss(&mut self, msg: &GnssMeasurements) -> Vec<OutMsg> {
        self.counts.gnss_received += 1;
        let epoch = match crate::gnss::GnssEpoch::try_from(msg) {
            Ok(e) => e,
            Err(e) => return self.unconvertible(Input::Gnss, &e.to_string()),
        };
        if !self.gnss_frame.admits(&msg.header.frame_id) {
            return self.foreign_frame(Input::Gnss, &msg.header.frame_id);
        }
        let outputs = match self.engine.push_gnss(epoch) {
            Ok(o) => {
                self.gnss_frame.accepted(&msg.header.frame_id);
                o
            }
            Err(e) => {
                self.log.warn(e.reason.name(), &format!("gnss: {e}"));
                Vec::new()
            }
        };
        self.publishable(outputs)
    }

    /// Handles one NavSatFix (loose coupling); a fix without a solution is ignored.
    pub fn on_fix(&mut self, msg: &NavSatFix) -> Vec<OutMsg> {
        self.counts.fix_received += 1;
        let t_s = match time_to_seconds(&msg.header.stamp) {
            Ok(t) if msg.status.status >= 0 => t,
            _ => return self.unconvertible(Input::Fix, "no solution or invalid stamp"),
        };
        if !self.fix_frame.admits(&msg.header.frame_id) {
            return self.foreign_frame(Input::Fix, &msg.header.frame_id);
        }
        let released = self.pairing.on_fix(FramedFix {
            fix: fix_of(msg, t_s),
            frame_id: msg.header.frame_id.clone(),
        });
        let outputs = self.push_fixes(released);
        self.publishable(outputs)
    }

    /// Handles one velocity on `gnss/velocity` (loose coupling): it joins the fix of its
    /// stamp (see [`crate::engine::fix_pairing`] and [`FixVelocityJoin`]: in the map frame
    /// or the fix's frame). Any other frame is counted and the fix goes on without it.
    pub fn on_velocity(&mut self, msg: &TwistWithCovarianceStamped) -> Vec<OutMsg> {
        self.counts.velocity_received += 1;
        let velocity = match GnssVelocity::try_from(msg) {
            Ok(v) => v,
            Err(e) => return self.unconvertible(Input::Velocity, &e.to_string()),
        };
        let released = self.pairing.on_velocity(velocity);
        let outputs = self.push_fixes(released);
        self.publishable(outputs)
    }

    /// Velocities dropped for want of a fix of their stamp.
    pub fn unpaired_velocities(&self) -> u64 {
        self.pairing.unpaired_velocities()
    }

    /// Feeds joined fixes, counting what became of their velocities.
    fn push_fixes(&mut self, joined: Vec<Joined>) -> Vec<Output> {
        let mut outputs = Vec::new();
        for Joined {
            fix,
            frame_id,
            velocity,
        } in joined
        {
            match velocity {
                VelocityUse::None => {}
                VelocityUse::Paired => self.counts.velocity_paired += 1,
                VelocityUse::ForeignFrame(v_frame) => {
                    self.foreign_frame(Input::Velocity, &v_frame);
                }
            }
            match self.engine.push_fix(fix) {
                Ok(o) => {
                    self.fix_frame.accepted(&frame_id);
                    outputs.extend(o);
                }
                Err(e) => {
                    self.log.warn(e.reason.name(), &format!("fix: {e}"));
                }
            }
        }
        outputs
    }

    fn unconvertible(&mut self, input: Input, error: &str) -> Vec<OutMsg> {
        let counter = match input {
            Input::Imu => &mut self.counts.unconvertible_imu,
            Input::Gnss => &mut self.counts.unconvertible_gnss,
            Input::Fix => &mut self.counts.unconvertible_fix,
            Input::Velocity => &mut self.counts.unconvertible_velocity,
        };
        *counter += 1;
        let name = input.name();
        self.log.warn(
            &format!("unconvertible {name}"),
            &format!("dropped a message on {name}: {error}"),
        );
        Vec::new()
    }

    /// Counts and logs a message from another frame than `expected`.
    fn foreign_frame(&mut self, input: Input, frame_id: &str) -> Vec<OutMsg> {
        let lock = |l: &FrameLock| format!("`{}`", l.0.clone().unwrap_or_default());
        let (counter, expected) = match input {
            Input::Imu => (&mut self.counts.foreign_frame_imu, lock(&self.imu_frame)),
            Input::Gnss => (&mut self.counts.foreign_frame_gnss, lock(&self.gnss_frame)),
            Input::Fix => (&mut self.counts.foreign_frame_fix, lock(&self.fix_frame)),
            Input::Velocity => (
                &mut self.counts.foreign_frame_velocity,
                format!("`{}` (ENU) or its fix's frame", self.frames.map_frame),
            ),
        };
        *counter += 1;
        let name = input.name();
        self.log.warn(
            &format!("foreign frame {name}"),
            &format!("dropped a message on {name} from frame `{frame_id}`: the node follows {expected} (a second publisher?)"),
        );
        Vec::new()
    }

    fn publishable(&mut self, outputs: Vec<Output>) -> Vec<OutMsg> {
        let mut msgs = Vec::new();
        for output in outputs {
            match output {
                Output::Solution(sol) => {
                    let Ok(stamp) = seconds_to_time(sol.nav.t_s) else {
                        self.counts.non_finite_outputs += 1;
                        continue;
                    };
                    let datum = *self.datum.get_or_insert(sol.nav.p);
                    let f = &self.frames;
                    let odom = outbound::odometry(&sol, &datum, stamp, &f.map_frame, &f.base_frame);
                    let fix = outbound::nav_sat_fix(&sol, stamp, &f.base_frame);
                    if odometry_is_finite(&odom) && fix_is_finite(&fix) {
                        if f.publish_tf {
                            msgs.push(OutMsg::Tf(outbound::transform(&odom)));
                        }
                        msgs.push(OutMsg::Odometry(Box::new(odom)));
                        msgs.push(OutMsg::Fix(fix));
                    } else {
                        self.counts.non_finite_outputs += 1;
                        self.log.warn(
                            "non_finite_output",
                            "solution with a non-finite value dropped",
                        );
                    }
                }
                Output::Epoch(report) => {
                    if let Ok(stamp) = seconds_to_time(report.t_s) {
                        msgs.push(OutMsg::Noise(outbound::noise_estimates(
                            &report,
                            stamp,
                            &self.frames.base_frame,
                        )));
                    }
                }
                Output::Status(StatusEvent::Initialized {
                    t_s,
                    heading_from_motion,
                }) => log::info!(
                    "filter initialized at {t_s:.3} s (heading from {})",
                    if heading_from_motion {
                        "motion"
                    } else {
                        "the configuration"
                    }
                ),
                Output::Status(StatusEvent::Reset { t_s, reason }) => {
                    log::warn!("filter reset at {t_s:.3} s: {reason:?}")
                }
            }
        }
        msgs
    }

    /// The /diagnostics report at `stamp`: input counts, rejections by reason, phase and,
    /// once running, the filter's 3D position sigma (level ERROR when it is not finite).
    pub fn diagnostics(&self, node_name: &str, stamp: Time) -> DiagnosticArray {
        let phase = match self.engine.init_phase() {
            Some(p) => format!("initializing ({p:?})"),
            None => "running".to_owned(),
        };
        let c = &self.counts;
        let mut values: Vec<KeyValue> = [
            ("variant", self.engine.variant_name().to_owned()),
            ("phase", phase.clone()),
            ("imu_received", c.imu_received.to_string()),
            ("gnss_received", c.gnss_received.to_string()),
            ("fix_received", c.fix_received.to_string()),
            ("velocity_received", c.velocity_received.to_string()),
            ("velocity_paired", c.velocity_paired.to_string()),
            ("unpaired_velocity", self.unpaired_velocities().to_string()),
            ("undecodable", c.undecodable.to_string()),
            ("unconvertible_imu", c.unconvertible_imu.to_string()),
            ("unconvertible_gnss", c.unconvertible_gnss.to_string()),
            ("unconvertible_fix", c.unconvertible_fix.to_string()),
            (
                "unconvertible_velocity",
                c.unconvertible_velocity.to_string(),
            ),
            ("time_jump_resets", c.time_jump_resets.to_string()),
            ("non_finite_outputs", c.non_finite_outputs.to_string()),
            ("foreign_frame_imu", c.foreign_frame_imu.to_string()),
            ("foreign_frame_gnss", c.foreign_frame_gnss.to_string()),
            ("foreign_frame_fix", c.foreign_frame_fix.to_string()),
            (
                "foreign_frame_velocity",
                c.foreign_frame_velocity.to_string(),
            ),
        ]
        .into_iter()
        .map(|(key, value)| KeyValue {
            key: key.to_owned(),
            value,
        })
        .collect();
        values.extend(self.engine.counters().iter().map(|(reason, n)| KeyValue {
            key: format!("rejected_{}", reason.name()),
            value: n.to_string(),
        }));
        let (level, message) = match self.engine.state() {
            None => (DiagnosticStatus::WARN, phase),
            Some(state) => {
                // Filter health: the 3D position sigma the filter claims.
                let sigma_m = state
                    .solution()
                    .position_covariance_enu_m2()
                    .trace()
                    .max(0.0)
                    .sqrt();
                values.push(KeyValue {
                    key: "position_sigma_3d_m".to_owned(),
                    value: format!("{sigma_m:.3}"),
                });
                if sigma_m.is_finite() {
                    (DiagnosticStatus::OK, phase)
                } else {
                    (
                        DiagnosticStatus::ERROR,
                        "filter covariance is not finite".to_owned(),
                    )
                }
            }
        };
        DiagnosticArray {
            header: Header {
                stamp,
                frame_id: String::new(),
            },
            status: vec![DiagnosticStatus {
                level,
                name: format!("{node_name}: filter"),
                message,
                hardware_id: String::new(),
                values,
            }],
        }
    }
}

fn odometry_is_finite(o: &Odometry) -> bool {
    let p = &o.pose.pose;
    let t = &o.twist.twist;
    [
        p.position.x,
        p.position.y,
        p.position.z,
        p.orientation.x,
        p.orientation.y,
        p.orientation.z,
        p.orientation.w,
        t.linear.x,
        t.linear.y,
        t.linear.z,
        t.angular.x,
        t.angular.y,
        t.angular.z,
    ]
    .iter()
    .chain(o.pose.covariance.iter())
    .chain(o.twist.covariance.iter())
    .all(|v| v.is_finite())
}

fn fix_is_finite(f: &NavSatFix) -> bool {
    [f.latitude, f.longitude, f.altitude]
        .iter()
        .chain(f.position_covariance.iter())
        .all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::RejectionReason;
    use nalgebra::Matrix3;

    fn imu_at(t_s: f64) -> Imu {
        let sample = ImuSample {
            t_s,
            w_ib_b_rad_s: nalgebra::Vector3::zeros(),
            f_ib_b_m_s2: nalgebra::Vector3::new(0.0, 0.0, 9.8),
        };
        outbound::imu(&sample, seconds_to_time(t_s).unwrap(), "imu")
    }

    fn feed(core: &mut NodeCore, t0_s: f64, t1_s: f64) {
        let n = ((t1_s - t0_s) * 100.0).round() as usize;
        for k in 0..n {
            core.on_imu(&imu_at(t0_s + k as f64 * 0.01));
        }
    }

    fn diagnostic(core: &NodeCore, key: &str) -> Option<String> {
        let d = core.diagnostics("/n", Time::default());
        d.status[0]
            .values
            .iter()
            .find(|kv| kv.key == key)
            .map(|kv| kv.value.clone())
    }

    #[test]
    fn time_jump_backwards_resets_small_steps_are_rejected() {
        let mut core = NodeCore::new(Config::default(), OutputFrames::default());
        feed(&mut core, 100.0, 102.0);
        core.on_imu(&imu_at(101.5));
        assert_eq!(core.counts().time_jump_resets, 0);
        assert_eq!(
            core.engine()
                .counters()
                .count(RejectionReason::ImuOutOfOrder),
            1
        );
        feed(&mut core, 50.0, 51.0);
        assert_eq!(core.counts().time_jump_resets, 1);
        assert_eq!(core.engine().last_imu_t_s(), Some(50.99));
        assert_eq!(
            core.engine()
                .counters()
                .count(RejectionReason::ImuOutOfOrder),
            1,
            "the samples after the jump are accepted"
        );
        assert_eq!(diagnostic(&core, "time_jump_resets").as_deref(), Some("1"));
        assert_eq!(diagnostic(&core, "imu_received").as_deref(), Some("301"));
    }

    #[test]
    fn bad_inputs_are_counted_and_dropped() {
        let mut core = NodeCore::new(Config::default(), OutputFrames::default());
        feed(&mut core, 10.0, 10.5);
        let mut nan = imu_at(10.5);
        nan.linear_acceleration.y = f64::NAN;
        assert!(core.on_imu(&nan).is_empty());
        let mut bad_stamp = imu_at(10.6);
        bad_stamp.header.stamp.nanosec = 1_500_000_000;
        assert!(core.on_imu(&bad_stamp).is_empty());
        core.on_undecodable("imu", "truncated payload");
        let mut no_fix = NavSatFix::default();
        no_fix.status.status = -1;
        assert!(core.on_fix(&no_fix).is_empty());
        assert_eq!(core.counts().unconvertible_imu, 2, "NaN and a bad stamp");
        assert_eq!(core.counts().unconvertible_fix, 1);
        assert_eq!(core.counts().undecodable, 1);
        assert_eq!(diagnostic(&core, "unconvertible_imu").as_deref(), Some("2"));
        assert_eq!(
            diagnostic(&core, "phase").as_deref(),
            Some("initializing (Leveling)")
        );
        // The node goes on with good data.
        feed(&mut core, 10.7, 11.0);
        assert_eq!(core.engine().last_imu_t_s(), Some(10.99));
    }

    #[test]
    fn a_second_imu_frame_is_counted_and_dropped() {
        let mut core = NodeCore::new(Config::default(), OutputFrames::default());
        feed(&mut core, 10.0, 10.5);
        let mut other = imu_at(10.505);
        other.header.frame_id = "other_imu".to_owned();
        assert!(core.on_imu(&other).is_empty());
        assert_eq!(core.counts().foreign_frame_imu, 1);
        assert_eq!(
            core.engine().last_imu_t_s(),
            Some(10.49),
            "not fed to the engine"
        );
        assert_eq!(diagnostic(&core, "foreign_frame_imu").as_deref(), Some("1"));
        feed(&mut core, 10.5, 10.6);
        assert_eq!(
            core.engine().last_imu_t_s(),
            Some(10.59),
            "the first frame goes on"
        );
    }

    #[test]
    fn loose_coupling_runs_on_fixes_and_counts_raw_epochs_as_wrong_coupling() {
        use crate::sim::SimEvent;
        let mut core = loose_core(OutputFrames::default());
        let (mut odometry, mut epochs) = (0, 0);
        let mut out_had_tf = false;
        for_each_static_event_30_s(|event, stamp| {
            let out = match event {
                SimEvent::Imu(s) => core.on_imu(&outbound::imu(&s, stamp, "imu")),
                SimEvent::Fix(f) => core.on_fix(&outbound::receiver_fix(&f, stamp, "gnss")),
                SimEvent::Gnss { epoch, .. } => {
                    epochs += 1;
                    core.on_gnss(&outbound::gnss_measurements(&epoch, 0, stamp, "gnss"))
                }
                _ => Vec::new(),
            };
            odometry += out
                .iter()
                .filter(|m| matches!(m, OutMsg::Odometry(_)))
                .count();
            out_had_tf |= out.iter().any(|m| matches!(m, OutMsg::Tf(_)));
        });
        assert!(odometry > 2000, "{odometry} odometry messages in 30 s");
        assert_eq!(core.counts().velocity_received, 0);
        assert!(!out_had_tf, "no /tf without publish_tf");
        assert_eq!(core.engine().init_phase(), None, "running");
        assert_eq!(core.counts().unconvertible_fix, 0);
        assert_eq!(
            core.engine()
                .counters()
                .count(RejectionReason::WrongCoupling),
            epochs
        );
    }

    fn loose_core(frames: OutputFrames) -> NodeCore {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/params/ekf_loose.yaml");
        let text = std::fs::read_to_string(path).unwrap();
        let mut config = Config::from_yaml_str(&text, path).unwrap();
        // The static scenario faces north; heading is not observable at rest.
        config.set_parameter("init.heading_deg", "0.0").unwrap();
        NodeCore::new(config, frames)
    }

    /// Calls `on_event` with the static scenario's events of its first 30 s, each with its
    /// stamp.
    fn for_each_static_event_30_s(mut on_event: impl FnMut(crate::sim::SimEvent, Time)) {
        let scenario = crate::sim::Scenario::builtin("static", 5).unwrap();
        for event in scenario.events() {
            let event = event.unwrap();
            if event.t_s() > 30.0 {
                break;
            }
            let stamp = seconds_to_time(event.t_s()).unwrap();
            on_event(event, stamp);
        }
    }

    /// The velocity message of a simulated fix (ENU twist, the linear covariance block).
    fn velocity_of(fix: &crate::engine::GnssFix, frame_id: &str) -> TwistWithCovarianceStamped {
        let stamp = seconds_to_time(fix.t_s).unwrap();
        outbound::receiver_velocity(fix, stamp, frame_id).unwrap()
    }

    #[test]
    fn velocities_pair_with_their_fixes_bad_ones_are_counted_and_tf_follows_odometry() {
        use crate::sim::SimEvent;
        let frames = OutputFrames {
            map_frame: "map".to_owned(),
            base_frame: "imu_link".to_owned(),
            publish_tf: true,
        };
        let mut core = loose_core(frames);
        let mut out = Vec::new();
        let (mut fixes, mut paired) = (0, 0);
        for_each_static_event_30_s(|event, stamp| {
            match event {
                SimEvent::Imu(s) => out.extend(core.on_imu(&outbound::imu(&s, stamp, "imu"))),
                SimEvent::Fix(f) => {
                    fixes += 1;
                    let fix = outbound::receiver_fix(&f, stamp, "gnss");
                    // Velocity in the map frame or in the fix's frame, after or before
                    // (after for the first: it pairs as well).
                    let mut velocity = velocity_of(&f, ["map", "gnss"][fixes % 2]);
                    match fixes {
                        3 => velocity.twist.twist.linear.x = f64::NAN,
                        5 => velocity.header.frame_id = "base_link".to_owned(),
                        _ => paired += 1,
                    }
                    if fixes % 2 == 0 {
                        out.extend(core.on_velocity(&velocity));
                        out.extend(core.on_fix(&fix));
                    } else {
                        out.extend(core.on_fix(&fix));
                        out.extend(core.on_velocity(&velocity));
                    }
                    if fixes == 7 {
                        // A velocity whose fix never comes, and one repeated after its fix.
                        let mut late = velocity.clone();
                        late.header.stamp = seconds_to_time(f.t_s + 0.5).unwrap();
                        out.extend(core.on_velocity(&velocity));
                        out.extend(core.on_velocity(&late));
                    }
                }
                _ => {}
            }
        });
        let c = core.counts();
        assert!(fixes > 25, "{fixes} fixes");
        assert_eq!(c.velocity_received, fixes as u64 + 2);
        assert_eq!(c.velocity_paired, paired);
        assert_eq!(c.unconvertible_velocity, 1, "NaN");
        assert_eq!(c.foreign_frame_velocity, 1);
        assert_eq!(core.unpaired_velocities(), 2, "repeated and fix-less");
        assert_eq!(diagnostic(&core, "unpaired_velocity").as_deref(), Some("2"));
        assert_eq!(
            diagnostic(&core, "velocity_paired"),
            Some(paired.to_string())
        );
        let counters = core.engine().counters();
        for reason in [
            RejectionReason::MeasurementDuplicate,
            RejectionReason::FixNotFinite,
            RejectionReason::MeasurementTooOld,
        ] {
            assert_eq!(counters.count(reason), 0, "{reason:?}");
        }
        assert_eq!(core.engine().init_phase(), None, "running");
        // Every Odometry comes with its TF: same stamp, frames, translation and rotation.
        let mut tf_count = 0;
        for pair in out.windows(2) {
            if let [OutMsg::Tf(tf), OutMsg::Odometry(o)] = pair {
                tf_count += 1;
                let t = &tf.transforms[0];
                assert_eq!(t.header, o.header);
                assert_eq!(
                    (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
                    ("map", "imu_link")
                );
                let p = &o.pose.pose.position;
                let tr = &t.transform.translation;
                assert_eq!([tr.x, tr.y, tr.z], [p.x, p.y, p.z]);
                assert_eq!(t.transform.rotation, o.pose.pose.orientation);
            }
        }
        let odometry = out
            .iter()
            .filter(|m| matches!(m, OutMsg::Odometry(_)))
            .count();
        assert!(
            odometry > 2000 && tf_count == odometry,
            "{tf_count} TF, {odometry} odometry"
        );
    }

    #[test]
    fn a_paired_velocity_reaches_the_filter() {
        use crate::sim::SimEvent;
        // The receiver at rest claims 1 m/s east with σ 0.05 m/s: the filter must follow it.
        let speed_after = |bias_mps: f64| {
            let mut core = loose_core(OutputFrames::default());
            let mut last = None;
            for_each_static_event_30_s(|event, stamp| {
                let out = match event {
                    SimEvent::Imu(s) => core.on_imu(&outbound::imu(&s, stamp, "imu")),
                    SimEvent::Fix(mut f) => {
                        let mut out = core.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
                        f.velocity_enu_mps = Some(nalgebra::Vector3::new(bias_mps, 0.0, 0.0));
                        f.velocity_covariance_enu_m2_s2 =
                            Some(Matrix3::identity() * 0.05f64.powi(2));
                        out.extend(core.on_velocity(&velocity_of(&f, "map")));
                        out
                    }
                    _ => Vec::new(),
                };
                for m in out {
                    if let OutMsg::Odometry(o) = m {
                        let v = &o.twist.twist.linear;
                        last = Some(nalgebra::Vector3::new(v.x, v.y, v.z).norm());
                    }
                }
            });
            assert!(core.counts().velocity_paired > 25);
            last.unwrap()
        };
        let honest = speed_after(0.0);
        let biased = speed_after(1.0);
        eprintln!(
            "speed after 30 s: {honest:.3} m/s at rest, {biased:.3} m/s with the 1 m/s claim"
        );
        assert!(honest < 0.1, "at rest: {honest} m/s");
        assert!(biased > 0.5, "following the claimed 1 m/s: {biased} m/s");
    }
}
