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
//! - the disagreement did not appear as a GNSS jump: an offset that leaps beyond
//!   [`DISAGREE_SIGMA`] between two consecutive epochs (at most [`MAX_EPOCH_GAP_S`] apart)
//!   from an epoch that agreed is the GNSS moving, not the filter — the IMU cannot carry
//!   the state that far beyond its own σ in a second, and a filter that drifts crosses
//!   5σ in small steps. Such a disagreement (fixes biased by NLOS reception in a street
//!   canyon, confidently wrong for a hundred seconds in tests/consumer_mems_drive.rs)
//!   starts no run until an epoch agrees again. After an outage there is no epoch before
//!   to compare with, and the drift of the outage is judged as above.
//!
//! A wrong filter and the GNSS agreeing on that are what divergence is; one epoch that
//! cannot be judged (no independent position) ends the run. Limits: a filter that jumps
//! within a second (an IMU fault the screening lets through, a second after a GNSS
//! epoch) is taken for a GNSS jump; a GNSS that is confidently wrong from the first epoch
//! after an outage is taken for the truth.

use nalgebra::{Matrix3, Vector3};

use super::filter_state::FilterState;
use super::output::position_covariance_enu_m2;
use crate::config::Config;
use crate::earth::{self, Llh};
use crate::filter::measurement_rows::AntennaGeometry;

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

/// The filter's disagreement with an independent GNSS position at one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disagreement {
    pub t_s: f64,
    /// GNSS position less the filter's (antenna), ENU (m).
    pub offset_enu_m: Vector3<f64>,
    /// The filter's position covariance plus the GNSS position's, ENU (m²).
    pub covariance_enu_m2: Matrix3<f64>,
}

impl Disagreement {
    /// The filter's disagreement with the GNSS antenna position `gnss` of covariance
    /// `gnss_covariance_enu_m2`.
    ///
    /// Choice: the filter's covariance is that of its IMU position; the lever arm's share
    /// through the attitude error (centimetres for a lever of a metre) is left out.
    pub fn of(
        prior: &FilterState,
        gnss: &Llh,
        gnss_covariance_enu_m2: &Matrix3<f64>,
        config: &Config,
    ) -> Self {
        // The body rate moves only the antenna's velocity, not its position.
        let no_rate = Vector3::zeros();
        let geo = AntennaGeometry::new(&prior.nav, &config.mounting.lever_arm_b_m, &no_rate);
        let rot = earth::rot_ecef_to_enu(&prior.nav.p);
        let antenna_ecef_m = geo.antenna_ecef_m(&prior.nav.p);
        Self {
            t_s: prior.nav.t_s,
            offset_enu_m: rot * (earth::llh_to_ecef(gnss) - antenna_ecef_m),
            covariance_enu_m2: position_covariance_enu_m2(&prior.nav.p, &prior.p)
                + gnss_covariance_enu_m2,
        }
    }

    /// The Mahalanobis distance of the offset (σ); None when the covariance is not
    /// positive definite.
    pub fn sigmas(&self) -> Option<f64> {
        let chol = self.covariance_enu_m2.cholesky()?;
        let d2 = self.offset_enu_m.dot(&chol.solve(&self.offset_enu_m));
        d2.is_finite().then(|| d2.sqrt())
    }
}

/// The current run of disagreeing epochs.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    first_t_s: f64,
    last_t_s: f64,
    last_offset_enu_m: Vector3<f64>,
    epochs: u32,
}

/// The epoch before: its time, its offset if it was judged, and whether it disagreed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Previous {
    t_s: f64,
    offset_enu_m: Option<Vector3<f64>>,
    disagreed: bool,
}

/// See the module documentation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DivergenceMonitor {
    run: Option<Run>,
    previous: Option<Previous>,
    /// The current disagreement began with a GNSS jump: no run until an epoch agrees.
    gnss_jumped: bool,
}

impl DivergenceMonitor {
    /// Takes the GNSS epoch at `t_s` and its disagreement (None: no independent position
    /// at this epoch, as in tight coupling when the gate kept most pseudo-ranges); true
    /// when the filter has diverged.
    pub fn check(&mut self, t_s: f64, epoch: Option<&Disagreement>) -> bool {
        let judged = epoch.and_then(|d| Some((d, d.sigmas()?)));
        let disagreeing = judged.filter(|(_, s)| *s > DISAGREE_SIGMA).map(|(d, _)| d);
        let previous = self.previous.filter(|p| t_s - p.t_s <= MAX_EPOCH_GAP_S);
        self.previous = Some(Previous {
            t_s,
            offset_enu_m: judged.map(|(d, _)| d.offset_enu_m),
            disagreed: disagreeing.is_some(),
        });
        let Some(d) = disagreeing else {
            self.run = None;
            self.gnss_jumped = false;
            return false;
        };
        if let Some(Previous {
            offset_enu_m: Some(before),
            disagreed: false,
            ..
        }) = previous
        {
            let step = Disagreement {
                offset_enu_m: d.offset_enu_m - before,
                ..*d
            };
            self.gnss_jumped |= step.sigmas().is_some_and(|s| s > DISAGREE_SIGMA);
        }
        if self.gnss_jumped {
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

    /// Forgets everything (after a reset).
    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn epoch(t_s: f64, east_m: f64) -> Disagreement {
        Disagreement {
            t_s,
            offset_enu_m: Vector3::new(east_m, 0.0, 0.0),
            covariance_enu_m2: Matrix3::identity(),
        }
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
    fn outliers_jumps_gaps_and_unjudged_epochs_start_no_divergence() {
        let mut monitor = DivergenceMonitor::default();
        // Outliers in turning directions: the GNSS is not consistent with itself.
        for k in 0..10 {
            let t_s = f64::from(k);
            let mut outlier = epoch(t_s, 0.0);
            let turn_rad = t_s * 1.2;
            outlier.offset_enu_m = Vector3::new(turn_rad.cos(), turn_rad.sin(), 0.0) * 30.0;
            assert!(!monitor.check(t_s, Some(&outlier)));
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
        assert!(!monitor.check(53.0, Some(&broken)));
    }
}
