//! The residual-based strategy (`residual_akf`) of Ding, Wang and Rizos (2007, J. Navig.
//! 60:517), eqs. (14)–(15): R̂ = mean over the last m epochs of ε εᵀ + H P̂ Hᵀ, ε the
//! post-update residual and P̂ the posterior covariance (see
//! [`crate::adaptive::residual_r`]).
//!
//! Choices:
//! - Tightly coupled: one scalar estimator per satellite and observable (the satellite set
//!   changes from epoch to epoch; a joint estimator would restart at every change).
//!   Loosely coupled: one estimator of the full fix covariance (position, and velocity
//!   when the fix has one), which keeps the correlations eq. (14) estimates; one such
//!   estimator per kind of measurement whose noise is one matrix.
//! - The estimate of the epochs before is used at the current epoch (eq. (14) needs the
//!   posterior of the epoch itself, so it cannot be used in that epoch's own update); until
//!   a window is full the nominal R is used. Estimated pseudo-range variances stay within
//!   the bounds of `adaptive.*`.
//! - Only measurements seen for the first time teach the estimators (not those re-applied
//!   after a roll-back), and a satellite unseen for longer than `adaptive.max_epoch_gap_s`
//!   starts a new window.
//! - Loosely coupled (issue 11): eq. (13), E{εεᵀ} = R − H P̂ Hᵀ, holds when the prediction
//!   error is what P⁻ says. Written with the innovation d and S = H P⁻ Hᵀ + R̂, a sample is
//!   R̂ + R̂ S⁻¹ (d dᵀ − S) S⁻¹ R̂, i.e. d dᵀ once R̂ ≫ H P⁻ Hᵀ: an error of the prediction
//!   that the update did not remove is learned as measurement noise, the larger R̂ lowers
//!   the gain, the prediction error grows and R̂ with it. Measured on
//!   tests/data/consumer_mems_hour.yaml: one street-canyon fix 134 m off raised the
//!   vertical R̂ from 3.6 to 285 m² (one sample of 64), and the loop then carried it to
//!   6.7e4 m² and the state 450 m away within 100 s while the receiver's fixes stayed
//!   within tens of metres. Two departures from the paper, which is silent on both, break
//!   the loop: an epoch whose prior innovation fails the χ² test of [`LEARN_CONFIDENCE`]
//!   against S (an outlier, or a prediction worse than P⁻ says: either way its residual
//!   does not measure the noise) does not teach, and R̂ is capped at
//!   [`JOINT_MAX_VARIANCE_RATIO`] times the receiver's covariance in every direction,
//!   the ceiling the per-satellite estimates have in `adaptive.*` (a fix 10 σ off its
//!   receiver's model is a fault, not noise to adapt to). A noise that truly rises by
//!   more than the test admits at once is then learned from its smaller draws only, so
//!   more slowly; a refused epoch leaves R̂ as it was.
//! - An estimate not learned from for longer than `adaptive.max_epoch_gap_s` is stale, and
//!   the nominal R is used until an epoch teaches again (the gap that restarts a window, as
//!   for a satellite unseen). Choice (departure from the paper, which is silent): a filter
//!   off by more than its P⁻ says has every prior innovation refused, so the R̂ it learned
//!   before stayed, and a large one (learned in a street canyon) kept the good fixes that
//!   followed from pulling it back: measured on tests/data/consumer_mems_drive.yaml, the
//!   vertical RMS over 320–340 s was 45.6 m against the EKF's 0.8 m. After that gap of
//!   refusals the filter is now the EKF of the receiver's claim, until a new window is
//!   full (docs/results.md).

use std::collections::hash_map::Entry;
use std::collections::HashMap;

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::adaptive::mahalanobis::chi_square_quantile;
use crate::adaptive::residual_r::{ResidualCovarianceEstimator, ResidualCovarianceOptions};
use crate::config::Config;
use crate::gnss::SatId;
use crate::linalg::symmetrize;

use super::super::output::MeasurementKind;
use super::{track_for, NoiseVerdict, Observable, ScalarMeasurement, VarianceBounds};

/// Confidence of the χ² test an update's prior innovation must pass for its residual to
/// teach the joint estimator.
pub const LEARN_CONFIDENCE: f64 = 0.999;

/// Largest ratio of the estimated to the nominal variance of a measurement whose noise is
/// one matrix (a receiver's fix), in any direction.
pub const JOINT_MAX_VARIANCE_RATIO: f64 = 100.0;

#[derive(Debug, Clone)]
struct Track {
    estimator: ResidualCovarianceEstimator,
    last_t_s: f64,
}

/// Residual-based measurement-noise estimation.
#[derive(Debug, Clone)]
pub struct ResidualNoise {
    options: ResidualCovarianceOptions,
    bounds: VarianceBounds,
    max_gap_s: f64,
    tracks: HashMap<(SatId, Observable), Track>,
    joint: HashMap<MeasurementKind, Track>,
}

impl ResidualNoise {
    pub fn new(config: &Config) -> Self {
        let window = config.robust.residual_window_epochs;
        Self {
            options: ResidualCovarianceOptions {
                window,
                min_samples: window,
                ..ResidualCovarianceOptions::default()
            },
            bounds: VarianceBounds::new(config),
            max_gap_s: config.adaptive.max_epoch_gap_s,
            tracks: HashMap::new(),
            joint: HashMap::new(),
        }
    }

    /// The variance of a scalar measurement: the window's estimate when full, else the
    /// nominal one.
    pub fn variance(&self, row: &ScalarMeasurement) -> NoiseVerdict {
        let (lo, hi) = self.bounds.of(row.observable);
        match self
            .tracks
            .get(&(row.sat, row.observable))
            .and_then(|t| t.estimator.estimate())
        {
            Some(r) => NoiseVerdict {
                r: r[(0, 0)].clamp(lo, hi),
                estimated: true,
                ..NoiseVerdict::nominal(row.r_nominal)
            },
            None => NoiseVerdict::nominal(row.r_nominal),
        }
    }

    /// Learns from the measurements of an update at `t_s`: `posterior[i]` is the prediction
    /// of `rows[i]` from the corrected state (NaN: failed) and `posterior_hph[i]` its
    /// h P̂ hᵀ.
    pub fn after_update(
        &mut self,
        t_s: f64,
        rows: &[ScalarMeasurement],
        posterior: &[f64],
        posterior_hph: &[f64],
    ) {
        for ((row, predicted), hph) in rows.iter().zip(posterior).zip(posterior_hph) {
            let residual = row.measured - predicted;
            if !(residual.is_finite() && hph.is_finite()) {
                continue;
            }
            let options = self.options;
            let new_track = || {
                ResidualCovarianceEstimator::new(options).map(|estimator| Track {
                    estimator,
                    last_t_s: f64::NEG_INFINITY,
                })
            };
            let Some(track) = track_for(&mut self.tracks, row, new_track) else {
                continue;
            };
            learn(track, t_s, self.max_gap_s, |e| {
                e.push(
                    &DVector::from_element(1, residual),
                    &DMatrix::from_element(1, 1, *hph),
                )
            });
        }
    }

    /// The covariance of a measurement of `kind` at `t_s` whose noise is one matrix: the
    /// window's estimate when full, of the same dimension and learned from an epoch within
    /// `adaptive.max_epoch_gap_s` before, at most [`JOINT_MAX_VARIANCE_RATIO`] times
    /// `nominal` in every direction; else `nominal`.
    pub fn joint_covariance(
        &self,
        kind: MeasurementKind,
        t_s: f64,
        nominal: &DMatrix<f64>,
    ) -> DMatrix<f64> {
        self.joint
            .get(&kind)
            .filter(|t| t_s - t.last_t_s <= self.max_gap_s)
            .and_then(|t| t.estimator.estimate())
            .filter(|r| r.nrows() == nominal.nrows())
            .and_then(|r| capped_by_nominal(&r, nominal))
            .unwrap_or_else(|| nominal.clone())
    }

    /// Learns from the post-update residual ε = z − H x̂ of such a measurement and its
    /// H P̂ Hᵀ, unless the update's prior innovation fails the consistency test of
    /// [`LEARN_CONFIDENCE`] (`prior_nis`: dᵀ S⁻¹ d with S = H P⁻ Hᵀ + R̂).
    pub fn after_joint_update(
        &mut self,
        kind: MeasurementKind,
        t_s: f64,
        residual: &DVector<f64>,
        hph: &DMatrix<f64>,
        prior_nis: f64,
    ) {
        let consistent = chi_square_quantile(LEARN_CONFIDENCE, residual.len())
            .is_ok_and(|threshold| prior_nis <= threshold);
        if !consistent {
            return;
        }
        let track = match self.joint.entry(kind) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => {
                let Ok(estimator) = ResidualCovarianceEstimator::new(self.options) else {
                    return;
                };
                e.insert(Track {
                    estimator,
                    last_t_s: f64::NEG_INFINITY,
                })
            }
        };
        learn(track, t_s, self.max_gap_s, |e| e.push(residual, hph));
    }

    pub fn reset(&mut self) {
        self.tracks.clear();
        self.joint.clear();
    }
}

/// `estimate` with the eigenvalues of N^(-1/2) R̂ N^(-T/2) (N = L Lᵀ the nominal covariance)
/// lowered to [`JOINT_MAX_VARIANCE_RATIO`]: no direction's variance exceeds that many times
/// the nominal one. None when the nominal has no Cholesky factor or the eigen-solver fails
/// (the caller then uses the nominal).
fn capped_by_nominal(estimate: &DMatrix<f64>, nominal: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let l = nominal.clone().cholesky()?.l();
    let l_inv = l.clone().try_inverse()?;
    let ratio = symmetrize(&(&l_inv * estimate * l_inv.transpose()));
    let eigen = SymmetricEigen::try_new(ratio, f64::EPSILON, 10_000)?;
    let capped = eigen.eigenvalues.map(|v| v.min(JOINT_MAX_VARIANCE_RATIO));
    let ratio =
        &eigen.eigenvectors * DMatrix::from_diagonal(&capped) * eigen.eigenvectors.transpose();
    Some(symmetrize(&(&l * ratio * l.transpose())))
}

/// Pushes one sample into a track unless `t_s` was already learned; a gap longer than
/// `max_gap_s` restarts the window first.
fn learn<F, T, E>(track: &mut Track, t_s: f64, max_gap_s: f64, push: F)
where
    F: FnOnce(&mut ResidualCovarianceEstimator) -> Result<T, E>,
{
    if t_s <= track.last_t_s {
        return;
    }
    if t_s - track.last_t_s > max_gap_s {
        track.estimator.reset();
    }
    if push(&mut track.estimator).is_ok() {
        track.last_t_s = t_s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::Constellation;

    #[test]
    fn estimate_is_used_after_a_full_window_and_each_epoch_teaches_once() {
        let mut config = Config::default();
        config.robust.residual_window_epochs = 5;
        let mut noise = ResidualNoise::new(&config);
        let row = ScalarMeasurement {
            sat: SatId {
                constellation: Constellation::Gps,
                prn: 3,
            },
            observable: Observable::Pseudorange,
            measured: 10.0,
            predicted: 0.0,
            hph: 1.0,
            row: crate::filter::measurement_rows::Row::zeros(),
            r_nominal: 9.0,
            r_slow: 0.0,
        };
        for k in 0..4 {
            noise.after_update(f64::from(k), &[row], &[8.0], &[0.5]);
            assert!(!noise.variance(&row).estimated);
        }
        // The same epoch again (a roll-back) does not count.
        noise.after_update(3.0, &[row], &[8.0], &[0.5]);
        assert!(!noise.variance(&row).estimated);
        noise.after_update(4.0, &[row], &[8.0], &[0.5]);
        let v = noise.variance(&row);
        // ε = 2: ε² + hPh = 4.5.
        assert!(v.estimated);
        assert!((v.r - 4.5).abs() < 1e-12);
    }

    fn fix_noise(window: usize) -> ResidualNoise {
        let mut config = Config::default();
        config.robust.residual_window_epochs = window;
        ResidualNoise::new(&config)
    }

    #[test]
    fn the_fix_covariance_estimate_stays_within_its_ceiling_over_the_nominal() {
        let mut noise = fix_noise(2);
        let nominal = DMatrix::from_diagonal(&DVector::from_vec(vec![0.25, 0.25, 1.0]));
        // Residuals of 20 m on the first axis (a variance of 400 m² = 1600 nominal) that
        // pass the learning test (their prior innovation was consistent).
        let residual = DVector::from_vec(vec![20.0, 0.0, 0.0]);
        let hph = DMatrix::from_diagonal_element(3, 3, 0.01);
        for k in 0..2 {
            noise.after_joint_update(MeasurementKind::Fix, f64::from(k), &residual, &hph, 1.0);
        }
        let r = noise.joint_covariance(MeasurementKind::Fix, 2.0, &nominal);
        assert!((r[(0, 0)] - JOINT_MAX_VARIANCE_RATIO * 0.25).abs() < 1e-9);
        // The other axes keep their estimate (0.01 m², above the floor).
        assert!((r[(2, 2)] - 0.01).abs() < 1e-9);
    }

    #[test]
    fn an_epoch_whose_prior_innovation_fails_the_test_does_not_teach() {
        let mut noise = fix_noise(2);
        let nominal = DMatrix::identity(3, 3);
        let residual = DVector::from_vec(vec![0.5, 0.5, 0.5]);
        let hph = DMatrix::from_diagonal_element(3, 3, 0.1);
        let threshold = chi_square_quantile(LEARN_CONFIDENCE, 3).unwrap();
        noise.after_joint_update(MeasurementKind::Fix, 0.0, &residual, &hph, 1.0);
        noise.after_joint_update(MeasurementKind::Fix, 1.0, &residual, &hph, threshold * 1.01);
        assert_eq!(
            noise.joint_covariance(MeasurementKind::Fix, 2.0, &nominal),
            nominal
        );
        noise.after_joint_update(MeasurementKind::Fix, 2.0, &residual, &hph, threshold);
        let r = noise.joint_covariance(MeasurementKind::Fix, 3.0, &nominal);
        assert!((r[(0, 0)] - 0.35).abs() < 1e-9);
    }

    #[test]
    fn an_estimate_not_taught_for_longer_than_the_gap_gives_way_to_the_nominal() {
        let mut noise = fix_noise(2);
        let nominal = DMatrix::identity(3, 3);
        let residual = DVector::from_vec(vec![3.0, 0.0, 0.0]);
        let hph = DMatrix::from_diagonal_element(3, 3, 0.1);
        for k in 0..2 {
            noise.after_joint_update(MeasurementKind::Fix, f64::from(k), &residual, &hph, 1.0);
        }
        let gap_s = Config::default().adaptive.max_epoch_gap_s;
        let r = noise.joint_covariance(MeasurementKind::Fix, 1.0 + gap_s, &nominal);
        assert!((r[(0, 0)] - 9.1).abs() < 1e-9, "{r}");
        // Refused epochs since (none taught): stale.
        let later_s = 1.0 + gap_s + 1.0;
        assert_eq!(
            noise.joint_covariance(MeasurementKind::Fix, later_s, &nominal),
            nominal
        );
        // One that teaches restarts the window: nominal until it is full again.
        noise.after_joint_update(MeasurementKind::Fix, later_s, &residual, &hph, 1.0);
        assert_eq!(
            noise.joint_covariance(MeasurementKind::Fix, later_s + 1.0, &nominal),
            nominal
        );
    }
}
