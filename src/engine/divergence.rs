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
//! A wrong filter and the GNSS agreeing on that are what divergence is; one epoch that
//! cannot be judged (no independent position) ends the run.

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

/// See the module documentation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DivergenceMonitor {
    run: Option<Run>,
}

impl DivergenceMonitor {
    /// Takes one epoch's disagreement (None: no independent position at this epoch);
    /// true when the filter has diverged.
    pub fn check(&mut self, epoch: Option<&Disagreement>) -> bool {
        let Some(d) = epoch.filter(|d| d.sigmas().is_some_and(|s| s > DISAGREE_SIGMA)) else {
            self.run = None;
            return false;
        };
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

    /// Forgets the run (after a reset).
    pub fn clear(&mut self) {
        self.run = None;
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

    #[test]
    fn a_sustained_consistent_disagreement_is_divergence() {
        let mut monitor = DivergenceMonitor::default();
        let verdicts: Vec<bool> = (0..5)
            .map(|k| monitor.check(Some(&epoch(f64::from(k), 500.0 + f64::from(k)))))
            .collect();
        assert_eq!(verdicts, [false, false, false, true, true]);
    }

    #[test]
    fn outliers_gaps_and_unjudged_epochs_end_the_run() {
        let mut monitor = DivergenceMonitor::default();
        // Outliers in turning directions: the GNSS is not consistent with itself.
        for k in 0..10 {
            let mut outlier = epoch(f64::from(k), 0.0);
            let turn_rad = f64::from(k) * 1.2;
            outlier.offset_enu_m = Vector3::new(turn_rad.cos(), turn_rad.sin(), 0.0) * 30.0;
            assert!(!monitor.check(Some(&outlier)));
        }
        // Within 5σ: no run.
        for k in 10..20 {
            assert!(!monitor.check(Some(&epoch(f64::from(k), 4.9))));
        }
        // A gap (an outage) and an epoch without an independent position restart it.
        for t in [20.0, 21.0, 22.0, 25.0, 26.0, 27.0] {
            assert!(!monitor.check(Some(&epoch(t, 50.0))));
        }
        assert!(!monitor.check(None));
        for t in [29.0, 30.0, 31.0] {
            assert!(!monitor.check(Some(&epoch(t, 50.0))));
        }
        assert!(monitor.check(Some(&epoch(32.0, 50.0))));
        // A covariance that is no covariance judges nothing.
        let mut broken = epoch(33.0, 50.0);
        broken.covariance_enu_m2 = -Matrix3::identity();
        assert!(!monitor.check(Some(&broken)));
    }
}
