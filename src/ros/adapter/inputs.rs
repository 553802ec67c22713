//! Decoded input messages into the engine: conversion, frame locks, the IMU time line and
//! the fix / velocity join; what is dropped is counted and logged (rate-limited).

use crate::engine::{BaselineHeadingReading, GnssFix, Output, ResetReason};
use crate::gnss::GnssEpoch;
use crate::ins::ImuSample;
use crate::ros::convert::{GnssVelocity, WheelOdometrySpeed};
use crate::ros::fix_velocity::{FramedFix, Joined, VelocityUse};
use crate::ros::msg::{
    GnssMeasurements, Imu, NavSatFix, Odometry, TFMessage, Time, TwistWithCovarianceStamped,
    UbxNavRelPosNed,
};

use super::frame_lock::Admission;
use super::time_line::Verdict;
use super::{Input, Published, RosAdapter};

/// A decoded message on one of the adapter's input streams.
#[derive(Debug, Clone, PartialEq)]
pub enum InputMessage {
    Imu(Imu),
    Gnss(GnssMeasurements),
    Fix(NavSatFix),
    Velocity(TwistWithCovarianceStamped),
    WheelOdometry(Box<Odometry>),
    RelPosNed(Box<UbxNavRelPosNed>),
}

impl RosAdapter {
    /// Handles one decoded message of any input stream.
    pub fn on_message(&mut self, msg: &InputMessage) -> Vec<Published> {
        match msg {
            InputMessage::Imu(m) => self.on_imu(m),
            InputMessage::Gnss(m) => self.on_gnss(m),
            InputMessage::Fix(m) => self.on_fix(m),
            InputMessage::Velocity(m) => self.on_velocity(m),
            InputMessage::WheelOdometry(m) => self.on_wheel_odometry(m),
            InputMessage::RelPosNed(m) => self.on_rel_pos_ned(m),
        }
    }

    /// Records a payload on `topic` that did not decode.
    pub fn on_undecodable(&mut self, topic: &str, error: &str) {
        self.counts.undecodable += 1;
        self.log.warn(
            "undecodable",
            &format!("undecodable message on {topic}: {error}"),
        );
    }

    /// Takes the base controller's `odom_frame → base_frame` transforms of a `/tf` message
    /// (used in `tf_mode` `map_to_odom`; other transforms are ignored).
    pub fn on_tf(&mut self, msg: &TFMessage) {
        self.outputs.odom.on_tf(msg);
    }

    /// Handles one sensor_msgs/Imu.
    pub fn on_imu(&mut self, msg: &Imu) -> Vec<Published> {
        self.counts.stream_mut(Input::Imu).received += 1;
        let sample = match ImuSample::try_from(msg) {
            Ok(s) => s,
            Err(e) => return self.unconvertible(Input::Imu, &e.to_string()),
        };
        self.imu_stamps.note(sample.t_s, msg.header.stamp);
        let frame_id = &msg.header.frame_id;
        let mut outputs = Vec::new();
        match self.imu_frame.admit(frame_id) {
            Admission::Admitted => {}
            Admission::Foreign => return self.foreign_frame(Input::Imu, frame_id),
            Admission::Switched => {
                self.frame_switched(Input::Imu, frame_id);
                // Another sensor: its samples share nothing with the old one's.
                let reset = self.engine.reset(sample.t_s, ResetReason::ImuFrameChanged);
                outputs.push(reset);
                self.pairing.clear();
            }
        }
        let last_t_s = self.engine.last_imu_t_s();
        let max_gap_s = self.engine.config().engine.max_imu_gap_s;
        let outliers = &mut self.counts.imu_stamp_outliers;
        match self.time_line.judge(&sample, last_t_s, max_gap_s, outliers) {
            Verdict::OnLine => self.feed_imu(&sample, frame_id, &mut outputs),
            Verdict::Held => {}
            Verdict::Jumped(run) => {
                let to_t_s = run.first().map_or(f64::NAN, |s| s.t_s);
                if let Some(from_t_s) = last_t_s.filter(|&from_t_s| to_t_s < from_t_s) {
                    self.counts.time_jump_resets += 1;
                    self.log.warn(
                        "time jump",
                        &format!("IMU time jumped back from {from_t_s:.3} s to {to_t_s:.3} s: resetting the filter"),
                    );
                    let reset = self.engine.reset(to_t_s, ResetReason::TimeJumpBackwards);
                    outputs.push(reset);
                    self.pairing.clear();
                }
                // A jump ahead is a gap: the engine resets on the first sample.
                for s in &run {
                    self.feed_imu(s, frame_id, &mut outputs);
                }
            }
        }
        self.publishable(outputs)
    }

    /// Feeds one sample of `frame_id` after the fixes the join releases at its time.
    fn feed_imu(&mut self, sample: &ImuSample, frame_id: &str, outputs: &mut Vec<Output>) {
        let released = self.pairing.on_time(sample.t_s);
        self.push_fixes(released, outputs);
        match self.engine.push_imu(sample) {
            Ok(o) => {
                self.imu_frame.accepted(frame_id);
                if outputs.is_empty() {
                    *outputs = o;
                } else {
                    outputs.extend(o);
                }
            }
            Err(e) => {
                self.log.warn(e.reason.name(), &format!("imu: {e}"));
            }
        }
    }

    /// Handles one GnssMeasurements (tight coupling).
    pub fn on_gnss(&mut self, msg: &GnssMeasurements) -> Vec<Published> {
        self.counts.stream_mut(Input::Gnss).received += 1;
        let epoch = match GnssEpoch::try_from(msg) {
            Ok(e) => e,
            Err(e) => return self.unconvertible(Input::Gnss, &e.to_string()),
        };
        self.measurement_stamps.note(epoch.t_s, msg.header.stamp);
        match self.gnss_frame.admit(&msg.header.frame_id) {
            Admission::Admitted => {}
            Admission::Foreign => return self.foreign_frame(Input::Gnss, &msg.header.frame_id),
            Admission::Switched => self.frame_switched(Input::Gnss, &msg.header.frame_id),
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
        let mut published = self.publishable(outputs);
        published.extend(self.no_fix_while_initializing(msg.header.stamp));
        published
    }

    /// The NO_FIX NavSatFix at a GNSS input's `stamp` while the filter has no solution.
    ///
    /// Choice: one per GNSS input (the rate a receiver's fix would come at), not one per
    /// IMU sample, and nothing on `odometry`, whose messages have no status.
    fn no_fix_while_initializing(&self, stamp: Time) -> Option<Published> {
        if self.engine.state().is_some() {
            return None;
        }
        self.outputs.no_fix(stamp)
    }

    /// Handles one NavSatFix (loose coupling); a fix without a solution is counted and
    /// dropped.
    pub fn on_fix(&mut self, msg: &NavSatFix) -> Vec<Published> {
        self.counts.stream_mut(Input::Fix).received += 1;
        let fix = match GnssFix::try_from(msg) {
            Ok(f) => f,
            Err(e) => return self.unconvertible(Input::Fix, &e.to_string()),
        };
        self.measurement_stamps.note(fix.t_s, msg.header.stamp);
        match self.fix_frame.admit(&msg.header.frame_id) {
            Admission::Admitted => {}
            Admission::Foreign => return self.foreign_frame(Input::Fix, &msg.header.frame_id),
            Admission::Switched => self.frame_switched(Input::Fix, &msg.header.frame_id),
        }
        self.outputs.fix_received(msg.status.service);
        let released = self.pairing.on_fix(FramedFix {
            fix,
            frame_id: msg.header.frame_id.clone(),
        });
        let mut published = self.publish_fixes(released);
        published.extend(self.no_fix_while_initializing(msg.header.stamp));
        published
    }

    /// Handles one velocity on `gnss/velocity` (loose coupling): it joins the fix of its
    /// stamp (see [`crate::ros::fix_pairing`] and
    /// [`FixVelocityJoin`](crate::ros::fix_velocity::FixVelocityJoin): in the map frame or
    /// the fix's frame). Any other frame is counted and the fix goes on without it.
    pub fn on_velocity(&mut self, msg: &TwistWithCovarianceStamped) -> Vec<Published> {
        self.counts.stream_mut(Input::Velocity).received += 1;
        let velocity = match GnssVelocity::try_from(msg) {
            Ok(v) => v,
            Err(e) => return self.unconvertible(Input::Velocity, &e.to_string()),
        };
        let released = self.pairing.on_velocity(velocity);
        self.publish_fixes(released)
    }

    /// Handles one nav_msgs/Odometry of the base controller on `wheel/odometry`: its
    /// forward speed ([`WheelOdometrySpeed`]) goes to the engine, which rejects and counts
    /// it unless `wheel_odometry.enabled`. The stream is locked to one `child_frame_id`,
    /// the frame of the twist.
    pub fn on_wheel_odometry(&mut self, msg: &Odometry) -> Vec<Published> {
        self.counts.stream_mut(Input::WheelOdometry).received += 1;
        let speed = match WheelOdometrySpeed::try_from(msg) {
            Ok(s) => s,
            Err(e) => return self.unconvertible(Input::WheelOdometry, &e.to_string()),
        };
        let frame_id = &speed.child_frame_id;
        match self.wheel_frame.admit(frame_id) {
            Admission::Admitted => {}
            Admission::Foreign => return self.foreign_frame(Input::WheelOdometry, frame_id),
            Admission::Switched => self.frame_switched(Input::WheelOdometry, frame_id),
        }
        let pushed = self
            .engine
            .push_wheel_speed(speed.t_s, speed.speed_mps, speed.sigma_mps);
        let outputs = match pushed {
            Ok(o) => {
                self.wheel_frame.accepted(frame_id);
                o
            }
            Err(e) => {
                self.log
                    .warn(e.reason.name(), &format!("wheel odometry: {e}"));
                Vec::new()
            }
        };
        self.publishable(outputs)
    }

    /// Handles one UBXNavRelPosNED of a moving-base pair on `ubx_nav_rel_pos_ned`: its
    /// baseline heading ([`crate::ros::rel_pos_ned`]) goes to the engine, which screens
    /// and counts it (`dual_antenna.*`). The stream is locked to one `header.frame_id`
    /// (the driver's `frame_id`: one receiver pair).
    pub fn on_rel_pos_ned(&mut self, msg: &UbxNavRelPosNed) -> Vec<Published> {
        self.counts.stream_mut(Input::RelPosNed).received += 1;
        let reading = match BaselineHeadingReading::try_from(msg) {
            Ok(r) => r,
            Err(e) => return self.unconvertible(Input::RelPosNed, &e.to_string()),
        };
        let frame_id = &msg.header.frame_id;
        match self.rel_pos_frame.admit(frame_id) {
            Admission::Admitted => {}
            Admission::Foreign => return self.foreign_frame(Input::RelPosNed, frame_id),
            Admission::Switched => self.frame_switched(Input::RelPosNed, frame_id),
        }
        let outputs = match self.engine.push_baseline_heading(reading) {
            Ok(o) => {
                self.rel_pos_frame.accepted(frame_id);
                o
            }
            Err(e) => {
                self.log
                    .warn(e.reason.name(), &format!("dual-antenna heading: {e}"));
                Vec::new()
            }
        };
        self.publishable(outputs)
    }

    /// Feeds joined fixes; what the engine returned, to publish.
    fn publish_fixes(&mut self, joined: Vec<Joined>) -> Vec<Published> {
        let mut outputs = Vec::new();
        self.push_fixes(joined, &mut outputs);
        self.publishable(outputs)
    }

    /// Feeds joined fixes into `outputs`, counting what became of their velocities.
    fn push_fixes(&mut self, joined: Vec<Joined>, outputs: &mut Vec<Output>) {
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
    }

    /// Counts and logs a message of `input` that did not convert.
    fn unconvertible(&mut self, input: Input, error: &str) -> Vec<Published> {
        self.counts.stream_mut(input).unconvertible += 1;
        let name = input.name();
        self.log.warn(
            &format!("unconvertible {name}"),
            &format!("dropped a message on {name}: {error}"),
        );
        Vec::new()
    }

    /// Counts and logs a message of `input` from another frame than the one it follows.
    fn foreign_frame(&mut self, input: Input, frame_id: &str) -> Vec<Published> {
        let expected = match input {
            Input::Imu => format!("`{}`", self.imu_frame.locked()),
            Input::Gnss => format!("`{}`", self.gnss_frame.locked()),
            Input::Fix => format!("`{}`", self.fix_frame.locked()),
            Input::Velocity => format!(
                "`{}` (ENU) or its fix's frame",
                self.outputs.frames().map_frame
            ),
            Input::WheelOdometry => format!("child frame `{}`", self.wheel_frame.locked()),
            Input::RelPosNed => format!("`{}`", self.rel_pos_frame.locked()),
        };
        self.counts.stream_mut(input).foreign_frame += 1;
        let name = input.name();
        self.log.warn(
            &format!("foreign frame {name}"),
            &format!("dropped a message on {name} from frame `{frame_id}`: the node follows {expected} (a second publisher?)"),
        );
        Vec::new()
    }

    /// Counts and logs that the stream of `input` now follows `frame_id` (its locked frame
    /// went silent).
    fn frame_switched(&mut self, input: Input, frame_id: &str) {
        self.counts.stream_mut(input).frame_switches += 1;
        let name = input.name();
        log::warn!("{name}: the locked frame went silent; now following frame `{frame_id}`");
    }
}
