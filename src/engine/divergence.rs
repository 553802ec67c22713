//! The divergence monitor (issue 11, item 3): the filter's prior position against an
//! independent GNSS position — the receiver's fix (loose coupling), the engine's own
//! single-point solution (tight coupling) — in units of their combined σ.
//!
//! Choice: a sustained disagreement, not a windowed normalised-innovation test. A robust
//! filter stays pulled by one outlier for many epochs, so its innovations fail a NIS test
//! epoch after epoch (5 of 5 in a window) on the clean fixes that follow, while the filter
//! is a few metres off at most. The monitor instead declares divergence only when
//! - every GNSS epoch of at least [`MIN_SPAN_S`] (and at least [`MIN_EPOCHS`] epochs, none
//!   more than [`MAX_EPOCH_GAP_S`] apart) puts the filter beyond [`DISAGREE_SIGMA`] of the
//!   combined σ (the Mahalanobis distance with the filter's position covariance plus the
//!   GNSS position's own), and
//! - the GNSS positions are consistent with each other: each epoch's offset (GNSS less
//!   filter) points within [`MAX_TURN_RAD`] of the previous one's, so the GNSS sees the
//!   filter off the same way epoch after epoch. Outlier fixes point anywhere and break the
//!   run, whatever their size; a filter pulled by an outlier is within a few σ of the
//!   following fixes. The lengths are not compared: a filter that diverged takes large
//!   corrections (an EKF jumps most of the way to the first fix after a fault and is then
//!   off by its velocity error), so its offset shrinks or grows by far more than the
//!   GNSS's σ from one epoch to the next.
//!
//! - the disagreement stands under the GNSS position's covariance as the update weighed
//!   it too: a receiver fix's claim scaled by the consistency judge
//!   (`loose.fix_consistency`). Under the bare claim (0.7 m) the foliage's fixes, 10–15 m
//!   off in the same direction for seconds, put a sound filter beyond 5σ: on the
//!   consumer-MEMS hour (seed 4, docs/results.md) the monitor reset it there, the start in
//!   motion took its heading from those fixes, and the filter ran off by kilometres. The
//!   claim still decides what follows (a leap, a dispute): the published covariance is
//!   widened whenever the two disagree under it, which costs nothing when the filter is
//!   right, while a reset throws a sound filter away.
//! - the disagreement did not appear as a GNSS jump: an offset that leaps beyond
//!   [`DISAGREE_SIGMA`] between two consecutive epochs (at most [`MAX_EPOCH_GAP_S`] apart)
//!   from an epoch that agreed is the GNSS moving, unless the GNSS velocity (Doppler, or
//!   the receiver's) is beyond [`DISAGREE_SIGMA`] of the filter's and far enough off to
//!   have carried the filter half the leap in the time ([`VELOCITY_CARRY_SHARE`]): an IMU
//!   fault the screening lets through (a burst of 4 g for half a second) makes the filter
//!   leap within a second, and it gets there with a velocity error, while a position jump
//!   of the GNSS (a reflection) leaves its Doppler velocity alone. A GNSS leap (fixes
//!   biased by NLOS reception in a street canyon, confidently wrong for a hundred seconds
//!   in tests/consumer_mems_drive.rs) starts no run until an epoch agrees again; a filter
//!   that drifts crosses 5σ in small steps.
//!   After an outage there is no epoch before to compare with, and the drift of the
//!   outage is judged as above.
//!
//! While such a disagreement after a GNSS leap lasts, one of the two is wrong and the
//! monitor cannot tell which: it is a dispute ([`DivergenceMonitor::dispute_offset_enu_m`]),
//! and the engine widens the covariance it publishes by the offset's outer product, so
//! that either answer lies within it (the filter's own covariance, which the updates use,
//! is left alone), and `/diagnostics` warns. Loosely coupled, the receiver's fixes are
//! then held back by the leap, so that the filter does not follow it
//! ([`super::dispute`]); a receiver fix is judged before its update for that. Limit,
//! tightly coupled (and loosely once a hold ends): a filter that has followed a
//! confidently wrong GNSS all the way agrees with it again, and the dispute ends; its
//! error is then beyond the published covariance (measured in docs/results.md).
//!
//! A wrong filter and the GNSS agreeing on that are what divergence is; one epoch that
//! cannot be judged (no independent position) ends the run. Limits: a GNSS that is
//! confidently wrong from the first epoch after an outage is taken for the truth; a
//! filter that leaps within a second is taken for a GNSS jump when the GNSS gives no
//! velocity (receiver fixes without one, loosely coupled).

use nalgebra::{Matrix3, Vector3};

use super::dispute::{Dispute, Hold, RecentOffsets};
use super::filter_state::FilterState;
use super::output::position_covariance_enu_m2;
use crate::config::Config;
use crate::earth::{self, Llh};
use crate::filter::measurement_rows::AntennaGeometry;
use crate::ins::error_state::DV;

/// Mahalanobis distance beyond which an epoch disagrees (σ of the combined covariance).
///
/// Choice: 5 (the innovation gate's default): in 3D a clean epoch passes it with
/// probability 1 − 1.4·10⁻⁵, so a run of disagreeing epochs is never chance.
pub const DISAGREE_SIGMA: f64 = 5.0;
/// Shortest span of disagreeing epochs that is divergence (s).
///
/// Choice: 3 s: four epochs of a 1 Hz receiver, detected within 5 s of the first epoch
/// after the fault; longer than a robust filter's pull by one outlier lasts beyond 5σ.
pub const MIN_SPAN_S: f64 = 3.0;
/// Fewest disagreeing epochs that are divergence.
pub const MIN_EPOCHS: u32 = 4;
/// Largest angle between the offsets of consecutive epochs of one run (rad). Choice: 60°.
pub const MAX_TURN_RAD: f64 = std::f64::consts::FRAC_PI_3;
/// Longest time between two epochs of one run (s): an outage ends it.
pub const MAX_EPOCH_GAP_S: f64 = 2.0;
/// Least share of a leap of the offset that the filter's velocity error must be able to
/// carry it, over the time between the two epochs, for the leap to be the filter's.
///
/// Choice: one half. A filter that leapt got there by a velocity error: one that stood
/// over the whole gap carries it |Δv|·Δt, one that grew evenly from nothing (a burst)
/// half that. A velocity error that carries less cannot have made the leap: the GNSS
/// moved, and its velocity disagrees by its own errors (in the simulated street canyon
/// of the consumer-MEMS hour, NLOS Doppler puts the receiver's velocity 2–5σ from a sound
/// filter's at every epoch, about 1 m/s, while its fixes leap 6–140 m; at 5.2σ one such
/// epoch took a leap of the fixes for the filter's, and iarf with receiver velocities
/// followed them 29 m off at a σ of 4–5 m, docs/results.md).
pub const VELOCITY_CARRY_SHARE: f64 = 0.5;

/// The filter's disagreement with an independent GNSS position at one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disagreement {
    pub t_s: f64,
    /// GNSS position less the filter's (antenna), ENU (m).
    pub offset_enu_m: Vector3<f64>,
    /// The filter's position covariance plus the GNSS position's, ENU (m²).
    pub covariance_enu_m2: Matrix3<f64>,
    /// The same with the GNSS position's covariance as the update weighed it (a receiver
    /// fix's claim scaled by `loose.fix_consistency`), ENU (m²).
    pub weighed_covariance_enu_m2: Matrix3<f64>,
    /// The GNSS velocity less the filter's, when the GNSS gave a velocity: who moved when
    /// the offset leaps.
    pub velocity_offset: Option<VelocityOffset>,
}

/// The GNSS velocity less the filter's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityOffset {
    /// Its Mahalanobis distance (σ) under the two velocities' covariances.
    pub sigmas: f64,
    /// Its length (m/s).
    pub norm_mps: f64,
}

/// A GNSS velocity, ENU (m/s), and its covariance (m²/s²).
pub type GnssVelocityEnu = (Vector3<f64>, Matrix3<f64>);

impl Disagreement {
    /// The filter's disagreement with the GNSS antenna position `gnss` of covariance
    /// `gnss_covariance_enu_m2`, which the update weighed `gnss_weight_scale` (≥ 1) times
    /// larger, and with the GNSS velocity when there is one.
    ///
    /// Choice: the filter's covariances are those of its IMU position and velocity; the
    /// lever arm's share through the attitude error and the body rate (centimetres and
    /// centimetres per second for a lever of a metre) is left out.
    pub fn of(
        prior: &FilterState,
        gnss: &Llh,
        gnss_covariance_enu_m2: &Matrix3<f64>,
        gnss_weight_scale: f64,
        gnss_velocity: Option<&GnssVelocityEnu>,
        config: &Config,
    ) -> Self {
        // The body rate moves only the antenna's velocity, not its position.
        let no_rate = Vector3::zeros();
        let geo = AntennaGeometry::new(&prior.nav, &config.mounting.lever_arm_b_m, &no_rate);
        let rot = earth::rot_ecef_to_enu(&prior.nav.p);
        let antenna_ecef_m = geo.antenna_ecef_m(&prior.nav.p);
        let velocity_offset = gnss_velocity.and_then(|(v_enu_mps, cov_enu_m2_s2)| {
            let filter_cov: Matrix3<f64> = prior.p.fixed_view::<3, 3>(DV, DV).into();
            let offset_mps = v_enu_mps - prior.nav.v_n;
            Some(VelocityOffset {
                sigmas: mahalanobis(&offset_mps, &(filter_cov + cov_enu_m2_s2))?,
                norm_mps: offset_mps.norm(),
            })
        });
        let filter_covariance_enu_m2 = position_covariance_enu_m2(&prior.nav.p, &prior.p);
        Self {
            t_s: prior.nav.t_s,
            offset_enu_m: rot * (earth::llh_to_ecef(gnss) - antenna_ecef_m),
            covariance_enu_m2: filter_covariance_enu_m2 + gnss_covariance_enu_m2,
            weighed_covariance_enu_m2: filter_covariance_enu_m2
                + gnss_covariance_enu_m2 * gnss_weight_scale.max(1.0),
            velocity_offset,
        }
    }

    /// Whether the filter, not the GNSS, may have made the leap `leap_enu_m` of the offset
    /// since the epoch `dt_s` before: its velocity is beyond [`DISAGREE_SIGMA`] of the
    /// GNSS's, as a filter that leapt is (a GNSS position that jumped leaves its Doppler
    /// velocity alone), and off by enough to have carried it [`VELOCITY_CARRY_SHARE`] of
    /// the way in the time.
    fn filter_may_have_leapt(&self, leap_enu_m: &Vector3<f64>, dt_s: f64) -> bool {
        self.velocity_offset.is_some_and(|v| {
            v.sigmas > DISAGREE_SIGMA
                && v.norm_mps * dt_s >= VELOCITY_CARRY_SHARE * leap_enu_m.norm()
        })
    }

    /// The Mahalanobis distance of the offset (σ); None when the covariance is not
    /// positive definite.
    pub fn sigmas(&self) -> Option<f64> {
        mahalanobis(&self.offset_enu_m, &self.covariance_enu_m2)
    }

    /// The same under the GNSS covariance as the update weighed it.
    fn weighed_sigmas(&self) -> Option<f64> {
        mahalanobis(&self.offset_enu_m, &self.weighed_covariance_enu_m2)
    }
}

#[cfg(test)]
impl Disagreement {
    /// The GNSS `east_m` east of the filter at `t_s` (1 m σ, weighed as claimed), with no
    /// GNSS velocity.
    pub(crate) fn east_of_filter(t_s: f64, east_m: f64) -> Self {
        Self {
            t_s,
            offset_enu_m: Vector3::new(east_m, 0.0, 0.0),
            covariance_enu_m2: Matrix3::identity(),
            weighed_covariance_enu_m2: Matrix3::identity(),
            velocity_offset: None,
        }
    }
}

/// The Mahalanobis length of `x` under `covariance` (σ); None when the covariance is not
/// positive definite.
fn mahalanobis(x: &Vector3<f64>, covariance: &Matrix3<f64>) -> Option<f64> {
    let chol = covariance.cholesky()?;
    let d2 = x.dot(&chol.solve(x));
    d2.is_finite().then(|| d2.sqrt())
}

/// The current run of disagreeing epochs.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    first_t_s: f64,
    last_t_s: f64,
    last_offset_enu_m: Vector3<f64>,
    epochs: u32,
}

/// The epoch before: its time, its disagreement if it was judged, and whether it
/// disagreed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Previous {
    t_s: f64,
    judged: Option<Disagreement>,
    disagreed: bool,
}

/// See the module documentation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DivergenceMonitor {
    run: Option<Run>,
    previous: Option<Previous>,
    /// The offsets of the last judged epochs.
    recent: RecentOffsets,
    /// The current disagreement began with a GNSS jump: no run until an epoch agrees.
    dispute: Option<Dispute>,
    /// The offset of the last epoch checked, GNSS less filter (m), when it disagreed
    /// after a GNSS jump.
    dispute_offset_enu_m: Option<Vector3<f64>>,
}

impl DivergenceMonitor {
    /// Takes the GNSS epoch at `t_s` and its disagreement (None: no independent position
    /// at this epoch, as in tight coupling when the gate kept most pseudo-ranges); true
    /// when the filter has diverged.
    pub fn check(&mut self, t_s: f64, epoch: Option<&Disagreement>) -> bool {
        let judged = epoch.and_then(|d| Some((d, d.sigmas()?)));
        let disagreeing = judged.filter(|(_, s)| *s > DISAGREE_SIGMA).map(|(d, _)| d);
        let previous = self.previous.filter(|p| t_s - p.t_s <= MAX_EPOCH_GAP_S);
        if let Some((d, _)) = judged {
            match self.hold() {
                Some(Hold::MovedBack { offset_enu_m, .. }) => {
                    self.recent.push(&(d.offset_enu_m - offset_enu_m));
                }
                Some(Hold::LeftOut { .. }) => {}
                None => self.recent.push(&d.offset_enu_m),
            }
        }
        self.dispute_offset_enu_m = None;
        self.previous = Some(Previous {
            t_s,
            judged: judged.map(|(d, _)| *d),
            disagreed: disagreeing.is_some(),
        });
        let Some(d) = disagreeing else {
            self.run = None;
            self.dispute = None;
            return false;
        };
        if let Some((before, disagreed_before)) =
            previous.and_then(|p| Some((p.judged?, p.disagreed)))
        {
            let step = Disagreement {
                offset_enu_m: d.offset_enu_m - before.offset_enu_m,
                ..*d
            };
            let leapt = step.sigmas().is_some_and(|s| s > DISAGREE_SIGMA);
            let dt_s = d.t_s - before.t_s;
            let gnss_leapt = leapt && !d.filter_may_have_leapt(&step.offset_enu_m, dt_s);
            // Choice: the fixes are held only after a leap beyond the fixes' covariance
            // as the update weighed it, which the noise of a degraded stretch is not (in
            // simulated foliage, fixes 5-15 m off every way under a claim of 0.7 m).
            let fixes_leapt =
                gnss_leapt && step.weighed_sigmas().is_some_and(|s| s > DISAGREE_SIGMA);
            if gnss_leapt && !disagreed_before {
                let hold = fixes_leapt && self.recent.newest_stands_out();
                self.dispute = Some(Dispute::begin(d, hold));
            } else if let Some(dispute) = &mut self.dispute {
                dispute.next(d, leapt, fixes_leapt);
            }
        }
        if self.dispute.is_some() {
            self.run = None;
            self.dispute_offset_enu_m = Some(d.offset_enu_m);
            return false;
        }
        if !d.weighed_sigmas().is_some_and(|s| s > DISAGREE_SIGMA) {
            self.run = None;
            return false;
        }
        let continues = self.run.filter(|run| {
            d.t_s - run.last_t_s <= MAX_EPOCH_GAP_S
                && d.offset_enu_m.angle(&run.last_offset_enu_m) <= MAX_TURN_RAD
        });
        let run = match continues {
            Some(run) => Run {
                last_t_s: d.t_s,
                last_offset_enu_m: d.offset_enu_m,
                epochs: run.epochs + 1,
                ..run
            },
            None => Run {
                first_t_s: d.t_s,
                last_t_s: d.t_s,
                last_offset_enu_m: d.offset_enu_m,
                epochs: 1,
            },
        };
        self.run = Some(run);
        run.epochs >= MIN_EPOCHS && run.last_t_s - run.first_t_s >= MIN_SPAN_S
    }

    /// The GNSS position less the filter's (ENU, m) at the last epoch checked, when it
    /// disagreed after a GNSS leap that the IMU does not support: who is wrong is not
    /// known (see the module documentation). None otherwise.
    pub fn dispute_offset_enu_m(&self) -> Option<Vector3<f64>> {
        self.dispute_offset_enu_m
    }

    /// The fixes' hold of the current dispute (see [`Dispute`]); None without one.
    pub fn hold(&self) -> Option<Hold> {
        self.dispute.as_ref()?.hold()
    }

    /// Forgets everything (after a reset).
    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn epoch(t_s: f64, east_m: f64) -> Disagreement {
        Disagreement::east_of_filter(t_s, east_m)
    }

    fn check(monitor: &mut DivergenceMonitor, t_s: f64, east_m: f64) -> bool {
        monitor.check(t_s, Some(&epoch(t_s, east_m)))
    }

    #[test]
    fn a_sustained_consistent_disagreement_is_divergence() {
        let mut monitor = DivergenceMonitor::default();
        // The first epoch after an outage, 500 m off, and on.
        let verdicts: Vec<bool> = (0..5)
            .map(|k| check(&mut monitor, f64::from(k), 500.0 + f64::from(k)))
            .collect();
        assert_eq!(verdicts, [false, false, false, true, true]);
        // A filter drifting off in small steps from agreement.
        let mut monitor = DivergenceMonitor::default();
        let verdicts: Vec<bool> = [0.0, 4.0, 5.5, 7.0, 8.5, 10.0]
            .into_iter()
            .enumerate()
            .map(|(k, east_m)| check(&mut monitor, k as f64, east_m))
            .collect();
        assert_eq!(verdicts, [false, false, false, false, false, true]);
    }

    #[test]
    fn a_filter_that_leaps_while_the_gnss_goes_on_is_divergence() {
        let mut monitor = DivergenceMonitor::default();
        // The filter agrees, then leaps 20 m within a second (as when the GNSS jumps) with
        // a velocity 50σ and 40 m/s off the GNSS's.
        let verdicts: Vec<bool> = (0..6)
            .map(|k| {
                let t_s = f64::from(k);
                let (east_m, sigmas, norm_mps) = if k == 0 {
                    (0.5, 0.1, 0.01)
                } else {
                    (20.0, 50.0, 40.0)
                };
                let d = Disagreement {
                    velocity_offset: Some(VelocityOffset { sigmas, norm_mps }),
                    ..epoch(t_s, east_m)
                };
                monitor.check(t_s, Some(&d))
            })
            .collect();
        assert_eq!(verdicts, [false, false, false, false, true, true]);
        assert_eq!(
            monitor.dispute_offset_enu_m(),
            None,
            "a divergence is no dispute"
        );
        // The same leap with the velocities agreeing is the GNSS's: no divergence, but a
        // dispute while it lasts; and so it is with the GNSS velocity 6σ off, but by 2 m/s,
        // which cannot have carried the filter 19.5 m in a second (a canyon's Doppler).
        for (sigmas, norm_mps) in [(1.0, 0.1), (6.0, 2.0)] {
            let mut monitor = DivergenceMonitor::default();
            for k in 0..6 {
                let t_s = f64::from(k);
                let east_m = if k == 0 { 0.5 } else { 20.0 };
                let d = Disagreement {
                    velocity_offset: Some(VelocityOffset { sigmas, norm_mps }),
                    ..epoch(t_s, east_m)
                };
                assert!(!monitor.check(t_s, Some(&d)), "{sigmas}σ, epoch {k}");
                let disputed = (k > 0).then(|| Vector3::new(east_m, 0.0, 0.0));
                assert_eq!(monitor.dispute_offset_enu_m(), disputed, "epoch {k}");
            }
            // An epoch that agrees ends it.
            assert!(!check(&mut monitor, 6.0, 1.0));
            assert_eq!(monitor.dispute_offset_enu_m(), None);
        }
    }

    #[test]
    fn only_a_disagreement_beyond_the_fixes_weighed_covariance_is_divergence() {
        // Fixes 8–12 m east of a filter, one way, for ten epochs: 8σ and more under their
        // claim of 1 m, within 3σ under the 25-fold variance the update weighed them with.
        let mut monitor = DivergenceMonitor::default();
        for k in 0..10 {
            let t_s = f64::from(k);
            let d = Disagreement {
                weighed_covariance_enu_m2: Matrix3::identity() * 25.0,
                ..epoch(t_s, 8.0 + f64::from(k % 5))
            };
            assert!(!monitor.check(t_s, Some(&d)), "epoch {k}");
            assert_eq!(monitor.dispute_offset_enu_m(), None);
        }
        // Beyond 5σ under both, they are.
        let verdicts: Vec<bool> = (10..14)
            .map(|k| {
                let t_s = f64::from(k);
                let d = Disagreement {
                    weighed_covariance_enu_m2: Matrix3::identity() * 25.0,
                    ..epoch(t_s, 30.0)
                };
                monitor.check(t_s, Some(&d))
            })
            .collect();
        assert_eq!(verdicts, [false, false, false, true]);
    }

    #[test]
    fn outliers_jumps_gaps_and_unjudged_epochs_start_no_divergence() {
        let mut monitor = DivergenceMonitor::default();
        // Outliers in turning directions: the GNSS is not consistent with itself. None
        // comes after an agreeing epoch: no dispute either.
        for k in 0..10 {
            let t_s = f64::from(k);
            let mut outlier = epoch(t_s, 0.0);
            let turn_rad = t_s * 1.2;
            outlier.offset_enu_m = Vector3::new(turn_rad.cos(), turn_rad.sin(), 0.0) * 30.0;
            assert!(!monitor.check(t_s, Some(&outlier)));
            assert_eq!(monitor.dispute_offset_enu_m(), None);
        }
        // Within 5σ, then the GNSS jumps 45 σ away and stays there: no divergence.
        for k in 10..40 {
            let east_m = if k < 20 { 4.9 } else { 50.0 };
            assert!(!check(&mut monitor, f64::from(k), east_m));
        }
        // An outage (a gap) restarts the run.
        let mut monitor = DivergenceMonitor::default();
        for t_s in [40.0, 41.0, 42.0, 45.0, 46.0, 47.0] {
            assert!(!check(&mut monitor, t_s, 50.0));
        }
        // So does an epoch without an independent position, and it shows no jump.
        assert!(!monitor.check(48.0, None));
        for t_s in [49.0, 50.0, 51.0] {
            assert!(!check(&mut monitor, t_s, 50.0));
        }
        assert!(check(&mut monitor, 52.0, 50.0));
        // A covariance that is no covariance judges nothing.
        let mut broken = epoch(53.0, 50.0);
        broken.covariance_enu_m2 = -Matrix3::identity();
        broken.weighed_covariance_enu_m2 = -Matrix3::identity();
        assert!(!monitor.check(53.0, Some(&broken)));
    }
}
