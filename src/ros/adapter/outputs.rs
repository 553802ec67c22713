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
    Epoch(Box<PublishedEpoch>),
}

/// An epoch's report and its message.
#[derive(Debug, Clone, PartialEq)]
pub struct PublishedEpoch {
    /// The engine's report.
    pub report: EpochReport,
    /// Its message.
    pub noise: NoiseEstimates,
}

/// A solution (every number finite, every variance non-negative) and its messages.
#[derive(Debug, Clone, PartialEq)]
pub struct PublishedSolution {
    /// The engine's solution.
    pub solution: Box<Solution>,
    /// Its messages; None from an adapter that frames none (see
    /// [`RosAdapter::without_messages`]).
    pub messages: Option<Box<SolutionMessages>>,
}

/// The messages of one solution.
#[derive(Debug, Clone, PartialEq)]
pub struct SolutionMessages {
    /// Pose in `map_frame` (ENU at the datum), twist in `base_frame`.
    pub odometry: Odometry,
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
    /// Whether solutions are framed into messages.
    messages: bool,
}

impl Framing {
    pub(super) fn new(frames: OutputFrames, datum: Option<Llh>) -> Self {
        Self {
            frames,
            datum,
            messages: true,
        }
    }

    pub(super) fn frames(&self) -> &OutputFrames {
        &self.frames
    }

    pub(super) fn without_messages(&mut self) {
        self.messages = false;
    }

    /// `solution` with its messages, unless a number of it or of its messages is not
    /// finite (or its time has no ROS stamp), or a variance is negative.
    ///
    /// Choice: a negative variance is as unusable as a NaN (its σ is not a number, and
    /// a consumer inverting the covariance would be misled), so such a solution is
    /// dropped and counted too. The solution itself is judged first, so an adapter that
    /// frames no messages drops the same solutions, except what only framing shows: the
    /// messages are checked again for an overflow or for a negative variance of the
    /// twist's rotated velocity covariance (a velocity block that is no covariance any
    /// more: a diverged filter; 10 of 1979 dropped solutions in the replay test of
    /// issue 12, item 7).
    fn solution(&mut self, solution: Box<Solution>) -> Result<PublishedSolution, Unpublishable> {
        judge(&solution)?;
        let messages = if self.messages {
            Some(Box::new(self.messages_of(&solution)?))
        } else {
            None
        };
        Ok(PublishedSolution { solution, messages })
    }

    fn messages_of(&mut self, solution: &Solution) -> Result<SolutionMessages, Unpublishable> {
        let stamp = seconds_to_time(solution.nav.t_s).map_err(|_| Unpublishable::NonFinite)?;
        let datum = *self.datum.get_or_insert(solution.nav.p);
        let f = &self.frames;
        let odometry = outbound::odometry(solution, &datum, stamp, &f.map_frame, &f.base_frame);
        let fix = outbound::nav_sat_fix(solution, stamp, &f.base_frame);
        if !(odometry_is_finite(&odometry) && fix_is_finite(&fix)) {
            return Err(Unpublishable::NonFinite);
        }
        let (pose, twist) = (&odometry.pose.covariance, &odometry.twist.covariance);
        let negative = (0..6).any(|k| pose[7 * k] < 0.0 || twist[7 * k] < 0.0)
            || (0..3).any(|k| fix.position_covariance[4 * k] < 0.0);
        if negative {
            return Err(Unpublishable::NegativeVariance);
        }
        Ok(SolutionMessages {
            tf: f.publish_tf.then(|| outbound::transform(&odometry)),
            odometry,
            fix,
        })
    }
}

/// Whether `solution` can be published: every number finite, its time a ROS stamp, every
/// variance (the covariance's diagonal) non-negative.
fn judge(solution: &Solution) -> Result<(), Unpublishable> {
    let s = solution;
    let vectors = [s.gyro_bias_rad_s, s.accel_bias_m_s2, s.angular_rate_b_rad_s];
    let finite = s.nav.is_finite()
        && seconds_to_time(s.nav.t_s).is_ok()
        && vectors.iter().all(|v| all_finite(v.as_slice()))
        && s.clock_bias_m.is_finite()
        && s.clock_drift_mps.is_finite()
        && all_finite(s.covariance.as_slice());
    if !finite {
        return Err(Unpublishable::NonFinite);
    }
    if s.covariance.diagonal().iter().any(|v| *v < 0.0) {
        return Err(Unpublishable::NegativeVariance);
    }
    Ok(())
}

/// True when none of `values` is NaN or infinite.
///
/// Choice: integer arithmetic on the bits, without stopping at the first bad value, so
/// the compiler turns it into vector instructions for the 400 covariance entries of each
/// solution (where `all(is_finite)` tests them one by one). The exponent bits are all
/// ones exactly for ±∞ and NaN; adding the exponent's lowest bit to them then carries
/// into bit 63, which the OR over all values keeps.
fn all_finite(values: &[f64]) -> bool {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    const EXPONENT_LSB: u64 = 1 << 52;
    let carries = values.iter().fold(0, |seen, v| {
        seen | ((v.to_bits() & EXPONENT) + EXPONENT_LSB)
    });
    carries >> 63 == 0
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
                        published
                            .push(Published::Epoch(Box::new(PublishedEpoch { report, noise })));
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

#[cfg(test)]
mod tests {
    use super::all_finite;

    #[test]
    fn all_finite_finds_every_kind_of_non_finite_value_anywhere() {
        let finite = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
        ];
        assert!(all_finite(&finite));
        assert!(all_finite(&[]));
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -f64::NAN] {
            for at in 0..finite.len() {
                let mut values = finite;
                values[at] = bad;
                assert!(!all_finite(&values), "{bad} at {at}");
            }
        }
    }
}
