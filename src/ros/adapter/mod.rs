//! The ROS adapter: decoded ROS messages in, ROS messages to publish out, around the one
//! [`Engine`]. No DDS, no clock, no file: the live node ([`crate::ros::node`]) drives it
//! from its subscriptions and `gnss_ins replay` from a bag's messages, so both convert,
//! lock frames, join fixes with velocities, reset on time jumps, drop non-finite outputs
//! and count what they drop by the same code.
//!
//! Data flow of one IMU sample: `sensor_msgs/Imu` → [`RosAdapter::on_imu`] (conversion
//! [`ImuSample::try_from`](crate::ins::ImuSample), frame lock, time line (a stamp far off
//! it is dropped, a sustained jump resets), the fixes
//! the join releases at this IMU time) → [`Engine::push_imu`] (mechanization and
//! covariance propagation, a [`Solution`](crate::engine::Solution) per sample or at
//! `output.rate_hz`) → `outputs` (the guard: every number finite, no negative variance;
//! then Odometry, NavSatFix and, with `publish_tf`, the TF of `tf_mode` (`odom_tf`:
//! `map → base`, or `map → odom` from the `/tf` fed to [`RosAdapter::on_tf`]), stamped with the sample's
//! own ROS stamp from `stamp_book`) → [`Published::Solution`], which keeps the solution
//! for `replay`'s CSV and scoring; a refused one, or a GNSS input while the filter has
//! no solution, becomes [`Published::NoFix`].
//!
//! Data flow of one GNSS epoch: `GnssMeasurements` → [`RosAdapter::on_gnss`] (conversion
//! [`GnssEpoch::try_from`](crate::gnss::GnssEpoch), frame lock) → [`Engine::push_gnss`]
//! (held until the IMU passes its stamp, then the tight update, or a roll-back when late)
//! → [`Published::Epoch`] with its NoiseEstimates; the solutions after it follow with the
//! next IMU samples. A `NavSatFix` ([`RosAdapter::on_fix`]) first waits in the fix /
//! velocity join for the `gnss/velocity` of its stamp, then goes to [`Engine::push_fix`].
//!
//! Adding an input message: its conversion in [`crate::ros::convert`], one handler method
//! in `inputs.rs` (and its [`InputMessage`] variant and [`Input`] counters); then the
//! node's subscription and the bag topic of `gnss_ins replay`.

mod counts;
mod diagnostics;
mod frame_lock;
mod guard;
mod inputs;
mod odom_tf;
mod outputs;
mod phase_counts;
mod stamp_book;
#[cfg(test)]
mod tests;
mod time_line;

use crate::config::Config;
use crate::engine::{Engine, NotRuntimeTunable};
use crate::ros::fix_velocity::FixVelocityJoin;

use crate::ros::log_limit::LogLimiter;
pub use counts::{Input, InputCounts};
use frame_lock::FrameLock;
pub use inputs::InputMessage;
pub use odom_tf::{OdomTfCounts, TfMode};
pub use outputs::{OutputFrames, Published, PublishedEpoch, PublishedSolution, SolutionMessages};
pub use phase_counts::PhaseCounts;
use stamp_book::StampBook;
use time_line::TimeLine;
pub use time_line::{TIME_JUMP_BACK_S, TIME_JUMP_CONFIRM_SAMPLES};

/// The engine with the node's message handling; see the module documentation.
pub struct RosAdapter {
    engine: Engine,
    counts: InputCounts,
    log: LogLimiter,
    imu_frame: FrameLock,
    time_line: TimeLine,
    gnss_frame: FrameLock,
    fix_frame: FrameLock,
    /// The wheel odometry's `child_frame_id`.
    wheel_frame: FrameLock,
    /// The dual-antenna pair's `header.frame_id`.
    rel_pos_frame: FrameLock,
    pairing: FixVelocityJoin,
    outputs: outputs::Framing,
    /// The stamps of the IMU samples, which solutions carry.
    imu_stamps: StampBook,
    /// The stamps of the GNSS epochs and fixes, which their reports carry.
    measurement_stamps: StampBook,
    /// What the carrier-phase updates did with the phase changes.
    phases: PhaseCounts,
}

impl RosAdapter {
    /// An adapter running `config`, publishing in `frames`.
    pub fn new(config: Config, frames: OutputFrames) -> Self {
        Self {
            pairing: FixVelocityJoin::new(&frames.map_frame),
            outputs: outputs::Framing::new(frames, config.output.datum),
            engine: Engine::new(config),
            counts: InputCounts::default(),
            log: LogLimiter::default(),
            imu_frame: FrameLock::default(),
            time_line: TimeLine::default(),
            gnss_frame: FrameLock::default(),
            fix_frame: FrameLock::default(),
            wheel_frame: FrameLock::default(),
            rel_pos_frame: FrameLock::default(),
            imu_stamps: StampBook::default(),
            measurement_stamps: StampBook::default(),
            phases: PhaseCounts::default(),
        }
    }

    /// The adapter for a run that publishes nothing (`gnss_ins replay` without an output
    /// bag, `compare`): solutions are judged and handed out as before, but not framed
    /// into messages, which would cost a run of the filter about a sixth more.
    pub fn without_messages(mut self) -> Self {
        self.outputs.without_messages();
        self
    }

    /// The adapter that admits IMU samples from `frame_id` only (the node's `imu_frame`),
    /// instead of learning the IMU's frame from the stream.
    pub fn with_imu_frame(mut self, frame_id: &str) -> Self {
        self.imu_frame = FrameLock::configured(frame_id);
        self
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

    /// What the carrier-phase updates did with the phase changes (`gnss.tdcp`).
    pub fn phase_counts(&self) -> &PhaseCounts {
        &self.phases
    }

    /// What became of the base controller's transforms, in `tf_mode` `map_to_odom` only
    /// (with `publish_tf`).
    pub fn odom_tf_counts(&self) -> Option<OdomTfCounts> {
        (self.outputs.frames().published_tf() == TfMode::MapToOdom)
            .then(|| self.outputs.odom.counts())
    }

    /// Velocities dropped for want of a fix of their stamp.
    pub fn unpaired_velocities(&self) -> u64 {
        self.pairing.unpaired_velocities()
    }
}
