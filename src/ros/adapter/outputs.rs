//! Engine outputs into the messages to publish: framing (datum, frames, stamps), the
//! non-finite guard and the TF; status events are logged.

use crate::earth::Llh;
use crate::engine::{EpochReport, Output, Solution, StatusEvent};
use crate::ros::convert::seconds_to_time;
use crate::ros::msg::{NavSatFix, NoiseEstimates, Odometry, TFMessage};
use crate::ros::outbound;

use super::RosAdapter;

/// The frames of the published messages and whether the TF is published.
///
/// Choice: fixed at start (read-only through the parameter services): a TF tree whose
/// frames change while it runs would break its listeners.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputFrames {
    /// Parent frame of Odometry and TF (default `map`).
    pub map_frame: String,
    /// Child frame of Odometry and TF, frame of NavSatFix (default `base_link`).
    pub base_frame: String,
    /// Publish the TF `map_frame` → `base_frame` (default false).
    pub publish_tf: bool,
}

impl Default for OutputFrames {
    fn default() -> Self {
        Self {
            map_frame: "map".to_owned(),
            base_frame: "base_link".to_owned(),
            publish_tf: false,
        }
    }
}

/// What one engine output became: the messages to publish, each with the output it came
/// from (what `gnss_ins replay` scores and writes to its CSV), so nothing is converted
/// twice and nothing unpublished is scored.
#[derive(Debug, Clone, PartialEq)]
pub enum Published {
    /// A solution, on `odometry`, `fix` and (with `publish_tf`) `/tf`.
    Solution(PublishedSolution),
    /// An epoch's report, on `~/noise_estimates`.
    Epoch {
        /// The engine's report.
        report: EpochReport,
        /// Its message.
        noise: NoiseEstimates,
    },
}

/// A solution and its messages (every value finite).
#[derive(Debug, Clone, PartialEq)]
pub struct PublishedSolution {
    /// The engine's solution.
    pub solution: Box<Solution>,
    /// Pose in `map_frame` (ENU at the datum), twist in `base_frame`.
    pub odometry: Box<Odometry>,
    /// The body position, in `base_frame`.
    pub fix: NavSatFix,
    /// `map_frame` → `base_frame` (only with `publish_tf`).
    pub tf: Option<TFMessage>,
}

/// Why a solution was not published.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Unpublishable {
    /// A value, or its time, is not finite.
    NonFinite,
    /// A covariance has a negative variance on its diagonal (the filter diverged).
    NegativeVariance,
}

/// The output frames and the datum of the Odometry.
#[derive(Debug, Clone)]
pub(super) struct Framing {
    frames: OutputFrames,
    /// The configured datum, else the first solution's position.
    datum: Option<Llh>,
}

impl Framing {
    pub(super) fn new(frames: OutputFrames, datum: Option<Llh>) -> Self {
        Self { frames, datum }
    }

    pub(super) fn frames(&self) -> &OutputFrames {
        &self.frames
    }

    /// The messages of `solution`, unless its time has no ROS stamp or a value is not
    /// finite, or a variance is negative.
    ///
    /// Choice: a negative variance is as unusable as a NaN (its σ is not a number, and
    /// a consumer inverting the covariance would be misled), so such a solution is
    /// dropped and counted too; only the diagonals are checked, which costs nothing.
    fn solution(&mut self, solution: Box<Solution>) -> Result<PublishedSolution, Unpublishable> {
        let stamp = seconds_to_time(solution.nav.t_s).map_err(|_| Unpublishable::NonFinite)?;
        let datum = *self.datum.get_or_insert(solution.nav.p);
        let f = &self.frames;
        let odometry = outbound::odometry(&solution, &datum, stamp, &f.map_frame, &f.base_frame);
        let fix = outbound::nav_sat_fix(&solution, stamp, &f.base_frame);
        if !(odometry_is_finite(&odometry) && fix_is_finite(&fix)) {
            return Err(Unpublishable::NonFinite);
        }
        let (pose, twist) = (&odometry.pose.covariance, &odometry.twist.covariance);
        let negative = (0..6).any(|k| pose[7 * k] < 0.0 || twist[7 * k] < 0.0)
            || (0..3).any(|k| fix.position_covariance[4 * k] < 0.0);
        if negative {
            return Err(Unpublishable::NegativeVariance);
        }
        Ok(PublishedSolution {
            tf: f.publish_tf.then(|| outbound::transform(&odometry)),
            solution,
            odometry: Box::new(odometry),
            fix,
        })
    }
}

impl RosAdapter {
    /// The messages of the engine's `outputs`; solutions with a non-finite value are
    /// counted and dropped.
    pub(super) fn publishable(&mut self, outputs: Vec<Output>) -> Vec<Published> {
        let mut published = Vec::with_capacity(outputs.len());
        for output in outputs {
            match output {
                Output::Solution(solution) => match self.outputs.solution(solution) {
                    Ok(s) => published.push(Published::Solution(s)),
                    Err(Unpublishable::NonFinite) => {
                        self.counts.non_finite_outputs += 1;
                        self.log.warn(
                            "non_finite_output",
                            "solution with a non-finite value dropped",
                        );
                    }
                    Err(Unpublishable::NegativeVariance) => {
                        self.counts.negative_variance_outputs += 1;
                        self.log.warn(
                            "negative_variance_output",
                            "solution with a negative variance dropped",
                        );
                    }
                },
                Output::Epoch(report) => {
                    if let Ok(stamp) = seconds_to_time(report.t_s) {
                        let noise = outbound::noise_estimates(
                            &report,
                            stamp,
                            &self.outputs.frames.base_frame,
                        );
                        published.push(Published::Epoch { report, noise });
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
        published
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
