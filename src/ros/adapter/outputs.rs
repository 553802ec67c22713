//! Engine outputs into the messages to publish: framing (datum, frames, stamps) and the
//! TF, behind the guard ([`super::guard`]); status events are logged.

use crate::earth::Llh;
use crate::engine::{EpochReport, MeasurementKind, Output, Solution, StatusEvent};
use crate::ros::msg::{NavSatFix, NavSatStatus, NoiseEstimates, Odometry, TFMessage, Time};
use crate::ros::outbound;

use super::guard::{self, Unpublishable};
use super::odom_tf::{OdomHistory, TfMode};
use super::stamp_book::StampBook;
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
    /// Parent of `base_frame` in the base controller's `/tf` (default `odom`), for
    /// [`TfMode::MapToOdom`].
    pub odom_frame: String,
    /// Publish a TF at all (default false; false publishes none whatever `tf_mode` says).
    pub publish_tf: bool,
    /// Which TF, with `publish_tf` (default [`TfMode::MapToBaseLink`]).
    pub tf_mode: TfMode,
}

impl OutputFrames {
    /// The TF published: `tf_mode` with `publish_tf`, else none.
    pub fn published_tf(&self) -> TfMode {
        if self.publish_tf {
            self.tf_mode
        } else {
            TfMode::None
        }
    }
}

impl Default for OutputFrames {
    fn default() -> Self {
        Self {
            map_frame: "map".to_owned(),
            base_frame: "base_link".to_owned(),
            odom_frame: "odom".to_owned(),
            publish_tf: false,
            tf_mode: TfMode::MapToBaseLink,
        }
    }
}

/// What one engine output became: the messages to publish, each with the output it came
/// from (what `gnss_ins replay` scores and writes to its CSV), so nothing is converted
/// twice and nothing unpublished is scored.
#[derive(Debug, Clone, PartialEq)]
pub enum Published {
    /// A solution, on `odometry`, `fix/filtered` and (with `publish_tf`) `/tf`.
    Solution(PublishedSolution),
    /// An epoch's report, on `~/noise_estimates`.
    Epoch(Box<PublishedEpoch>),
    /// On `fix/filtered` as `STATUS_NO_FIX` (see [`outbound::no_fix`]): at the stamp of a
    /// solution the guard refused, and of each GNSS input while the filter has no solution
    /// (initializing, or after a reset until it starts again).
    NoFix(Box<NavSatFix>),
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
    /// With `publish_tf`: `map_frame` → `base_frame` ([`TfMode::MapToBaseLink`]) or
    /// `map_frame` → `odom_frame` ([`TfMode::MapToOdom`], once an `odom_frame` →
    /// `base_frame` near the stamp was heard).
    pub tf: Option<TFMessage>,
}

/// The output frames and the datum of the Odometry.
#[derive(Debug, Clone)]
pub(super) struct Framing {
    frames: OutputFrames,
    /// The configured datum, else the first solution's position.
    datum: Option<Llh>,
    /// Whether solutions are framed into messages.
    messages: bool,
    /// NavSatFix service bits of the last update that used a measurement.
    service: u16,
    /// NavSatFix service bits of the last receiver fix received (loose coupling).
    fix_service: u16,
    /// The base controller's `odom → base` transforms ([`TfMode::MapToOdom`]).
    pub(super) odom: OdomHistory,
}

impl Framing {
    pub(super) fn new(frames: OutputFrames, datum: Option<Llh>) -> Self {
        Self {
            odom: OdomHistory::new(&frames.odom_frame, &frames.base_frame),
            frames,
            datum,
            messages: true,
            service: NavSatStatus::SERVICE_UNKNOWN,
            fix_service: NavSatStatus::SERVICE_UNKNOWN,
        }
    }

    /// Remembers the service bits of a receiver fix, which its update will have used.
    pub(super) fn fix_received(&mut self, service: u16) {
        self.fix_service = service;
    }

    /// Takes the constellations `report` used as the solutions' service from now on.
    ///
    /// Choice: an update that used nothing keeps the last service (the solutions coast on
    /// the IMU, their covariance grows); a loosely-coupled update used the receiver's
    /// fix, which names its own service.
    fn used(&mut self, report: &EpochReport) {
        if report.measurements_used == 0 {
            return;
        }
        let service = match report.kind {
            MeasurementKind::Pseudoranges => outbound::service_of(
                report
                    .satellites
                    .iter()
                    .filter(|s| s.used_pseudorange || s.used_rate)
                    .map(|s| s.sat.constellation),
            ),
            MeasurementKind::Fix => self.fix_service,
            // The engine reports no epochs of its motion constraints, of the wheel
            // speed or of the baseline heading: they use no satellite of its own.
            MeasurementKind::ZeroVelocity
            | MeasurementKind::ZeroRate
            | MeasurementKind::NonHolonomic
            | MeasurementKind::WheelSpeed
            | MeasurementKind::BaselineHeading => return,
            // Choice: the phases' report rides inside its epoch's pseudo-range report,
            // which names the service; on its own it changes nothing.
            MeasurementKind::CarrierPhaseDeltas => return,
        };
        if service != NavSatStatus::SERVICE_UNKNOWN {
            self.service = service;
        }
    }

    /// The NO_FIX NavSatFix at `stamp`; None from an adapter that frames no messages.
    pub(super) fn no_fix(&self, stamp: Time) -> Option<Published> {
        self.messages
            .then(|| Published::NoFix(Box::new(outbound::no_fix(stamp, &self.frames.base_frame))))
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
    /// The solution itself is judged first, so an adapter that frames no messages drops
    /// the same solutions, except what only framing shows: the messages are checked
    /// again for an overflow or for a negative variance of the twist's rotated velocity
    /// covariance (a velocity block that is no covariance any more: a diverged filter;
    /// 10 of 1979 dropped solutions in the replay test of issue 12, item 7).
    ///
    /// The messages carry the stamp `imu_stamps` holds for the solution's time.
    fn solution(
        &mut self,
        solution: Box<Solution>,
        imu_stamps: &StampBook,
    ) -> Result<PublishedSolution, Unpublishable> {
        guard::judge(&solution)?;
        let messages = if self.messages {
            Some(Box::new(self.messages_of(&solution, imu_stamps)?))
        } else {
            None
        };
        Ok(PublishedSolution { solution, messages })
    }

    fn messages_of(
        &mut self,
        solution: &Solution,
        imu_stamps: &StampBook,
    ) -> Result<SolutionMessages, Unpublishable> {
        let stamp = imu_stamps
            .stamp(solution.nav.t_s)
            .map_err(|_| Unpublishable::NonFinite)?;
        let datum = *self.datum.get_or_insert(solution.nav.p);
        let f = &self.frames;
        let odometry = outbound::odometry(solution, &datum, stamp, &f.map_frame, &f.base_frame);
        let fix = outbound::nav_sat_fix(solution, stamp, &f.base_frame, self.service);
        guard::judge_messages(&odometry, &fix)?;
        let tf = match f.published_tf() {
            TfMode::MapToBaseLink => Some(outbound::transform(&odometry)),
            TfMode::MapToOdom => self.odom.map_to_odom(&odometry),
            TfMode::None => None,
        };
        Ok(SolutionMessages { tf, odometry, fix })
    }
}

impl RosAdapter {
    /// The messages of the engine's `outputs`; solutions the guard refuses are counted and
    /// dropped.
    pub(super) fn publishable(&mut self, outputs: Vec<Output>) -> Vec<Published> {
        let mut published = Vec::with_capacity(outputs.len());
        for output in outputs {
            match output {
                Output::Solution(solution) => {
                    let t_s = solution.nav.t_s;
                    let refused = match self.outputs.solution(solution, &self.imu_stamps) {
                        Ok(s) => {
                            published.push(Published::Solution(s));
                            continue;
                        }
                        Err(refused) => refused,
                    };
                    if let Ok(stamp) = self.imu_stamps.stamp(t_s) {
                        published.extend(self.outputs.no_fix(stamp));
                    }
                    match refused {
                        Unpublishable::NonFinite => {
                            self.counts.non_finite_outputs += 1;
                            self.log.warn(
                                "non_finite_output",
                                "solution with a non-finite value dropped",
                            );
                        }
                        Unpublishable::NegativeVariance => {
                            self.counts.negative_variance_outputs += 1;
                            self.log.warn(
                                "negative_variance_output",
                                "solution with a negative variance dropped",
                            );
                        }
                    }
                }
                Output::Epoch(report) => {
                    self.outputs.used(&report);
                    self.phases.add(&report);
                    if let Ok(stamp) = self.measurement_stamps.stamp(report.t_s) {
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
