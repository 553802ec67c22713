//! One run of the ROS adapter over a recorded bag, as the live node runs over the same
//! messages played onto DDS: the input messages go to the [`RosAdapter`], what it
//! publishes goes to a sink (the output bag and CSV of `replay`; nothing for `compare`)
//! and then to the [`Scorer`] with the references of the bag. `replay` and `compare` both
//! run through here.

use std::path::Path;

use crate::config::{Config, Coupling};
use crate::engine::{InitPhase, RejectionCounters, RejectionReason};
use crate::eval::ErrorSummary;
use crate::ros::adapter::{Input, InputCounts, OdomTfCounts, OutputFrames, Published, RosAdapter};
use crate::ros::bag::{BagError, BagReader};

use super::bag_inputs::{BagInput, BagInputs, BagTopics, ReadProblems};
use super::scoring::{Scorer, SessionReport};

/// The input streams a run of `config` feeds: the IMU, the measurements of the
/// configured coupling and, with `wheel_odometry.enabled` and `dual_antenna.enabled`, the
/// wheel odometry and the dual-antenna pair's relative position.
///
/// Choice: the node receives the other coupling's measurements too, and its engine
/// rejects each as `wrong_coupling` without any other effect; a bag carries both (the
/// simulator writes both), so a run counts them once as unfed instead of logging a
/// rejection for each. The same for a wheel odometry or dual-antenna heading the
/// configuration does not use.
fn fed_inputs(config: &Config) -> Vec<Input> {
    let mut fed = match config.filter.coupling {
        Coupling::Tight => vec![Input::Imu, Input::Gnss],
        Coupling::Loose => vec![Input::Imu, Input::Fix, Input::Velocity],
    };
    if config.wheel_odometry.enabled {
        fed.push(Input::WheelOdometry);
    }
    if config.dual_antenna.enabled {
        fed.push(Input::RelPosNed);
    }
    fed
}

/// What became of a run's inputs.
#[derive(Debug, Clone)]
pub struct BagRun {
    /// The scoring of the published solutions (their number, errors and σ).
    pub report: SessionReport,
    /// What was read and skipped while reading the bag.
    pub problems: ReadProblems,
    /// The adapter's counts (as the node's /diagnostics reports them).
    pub counts: InputCounts,
    /// Velocities dropped for want of a fix of their stamp.
    pub unpaired_velocities: u64,
    /// What became of the base controller's `/tf` (`tf_mode` `map_to_odom` only).
    pub odom_tf: Option<OdomTfCounts>,
    /// The engine's rejections by reason.
    pub rejections: RejectionCounters,
    /// Where the start-up stood at the end of the bag (None: the filter was running).
    pub start_phase: Option<InitPhase>,
    /// Resets by the divergence monitor (as `divergence_resets` on /diagnostics).
    pub divergence_resets: u64,
}

/// What became of the receiver velocities of a bag (counted as the node counts them).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct VelocityCounts {
    /// Joined with the fix of their stamp.
    pub paired: u64,
    /// Dropped for want of a fix of their stamp.
    pub unpaired: u64,
    /// Paired but in a frame neither the map frame nor their fix's: not used.
    pub foreign_frame: u64,
}

impl BagRun {
    /// What became of the receiver velocities.
    pub fn velocities(&self) -> VelocityCounts {
        VelocityCounts {
            paired: self.counts.velocity_paired,
            unpaired: self.unpaired_velocities,
            foreign_frame: self.counts.stream(Input::Velocity).foreign_frame,
        }
    }

    /// The summary of the scored errors (None when nothing was scored).
    pub fn summary(&self) -> Option<ErrorSummary> {
        (!self.report.errors.is_empty()).then(|| self.report.summary(f64::NEG_INFINITY))
    }

    /// IMU messages that did not reach the filter (undecodable, unconvertible, from a
    /// foreign frame, rejected by the engine) and the IMU messages read.
    pub fn imu_dropped(&self, imu_topic: &str) -> (u64, u64) {
        let undecodable: u64 = self
            .problems
            .undecodable
            .iter()
            .filter(|(key, _)| {
                key.strip_prefix(imu_topic)
                    .is_some_and(|reason| reason.starts_with(": "))
            })
            .map(|(_, n)| n)
            .sum();
        let rejected: u64 = [
            RejectionReason::ImuNotFinite,
            RejectionReason::ImuDuplicate,
            RejectionReason::ImuOutOfOrder,
            RejectionReason::ImuOutOfRange,
            RejectionReason::ImuInconsistent,
        ]
        .into_iter()
        .map(|r| self.rejections.count(r))
        .sum();
        let c = &self.counts;
        let dropped = undecodable
            + c.stream(Input::Imu).unconvertible
            + c.stream(Input::Imu).foreign_frame
            + rejected;
        (dropped, c.stream(Input::Imu).received + undecodable)
    }
}

/// A run of an adapter over a bag, scored by a scorer.
pub struct BagRunner {
    inputs: BagInputs,
    adapter: RosAdapter,
    scorer: Scorer,
    /// Messages in the bag (for progress).
    total_messages: u64,
}

impl BagRunner {
    /// A run of `adapter` over the messages of `reader` on `topics`, scored by `scorer`
    /// (the reference on `topics.truth`, or the scorer's own track).
    pub fn open(
        reader: &BagReader,
        topics: BagTopics,
        adapter: RosAdapter,
        scorer: Scorer,
    ) -> Result<Self, BagError> {
        let fed = fed_inputs(adapter.engine().config());
        Ok(Self {
            inputs: BagInputs::new(reader.messages()?, topics, &fed),
            adapter,
            scorer,
            total_messages: reader.topics().iter().map(|t| t.message_count).sum(),
        })
    }

    /// A run of `config` over the bag at `path` that publishes nothing, scored against
    /// `truth_topic` at most every `score_interval_s` (0: every match).
    pub fn scoring_only(
        path: &Path,
        config: &Config,
        truth_topic: Option<String>,
        score_interval_s: f64,
    ) -> Result<Self, BagError> {
        let reader = BagReader::open(path)?;
        let topics = BagTopics {
            truth: truth_topic,
            ..BagTopics::default()
        };
        let adapter = RosAdapter::new(config.clone(), OutputFrames::default()).without_messages();
        Self::open(
            &reader,
            topics,
            adapter,
            Scorer::new(score_interval_s, None),
        )
    }

    /// Runs to the end of the bag, handing each published output to `sink` before the
    /// scoring; `progress` is called now and then with the fraction of the messages done.
    /// Stops at the first error of the sink.
    pub fn run<E>(
        mut self,
        mut sink: impl FnMut(&Published) -> Result<(), E>,
        mut progress: impl FnMut(f64),
    ) -> Result<BagRun, E> {
        const PROGRESS_EVERY: u64 = 10_000;
        let mut next_progress = PROGRESS_EVERY;
        while let Some(item) = self.inputs.next() {
            match item {
                BagInput::Message(message) => {
                    for published in self.adapter.on_message(&message) {
                        sink(&published)?;
                        self.scorer.on_published(published);
                    }
                }
                BagInput::Tf(tf) => self.adapter.on_tf(&tf),
                BagInput::Undecodable { topic, error } => {
                    self.adapter.on_undecodable(&topic, &error);
                }
                BagInput::Reference(reference) => self.scorer.on_reference(reference),
            }
            let read = self.inputs.messages_read();
            if read >= next_progress && self.total_messages > 0 {
                next_progress = read + PROGRESS_EVERY;
                progress(read as f64 / self.total_messages as f64);
            }
        }
        progress(1.0);
        Ok(BagRun {
            report: self.scorer.finish(),
            problems: self.inputs.problems().clone(),
            counts: self.adapter.counts().clone(),
            unpaired_velocities: self.adapter.unpaired_velocities(),
            odom_tf: self.adapter.odom_tf_counts(),
            rejections: self.adapter.engine().counters().clone(),
            start_phase: self.adapter.engine().init_phase(),
            divergence_resets: self.adapter.engine().divergence_resets(),
        })
    }
}
