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

use std::collections::hash_map::Entry;
use std::collections::HashMap;

use nalgebra::{DMatrix, DVector};

use crate::adaptive::residual_r::{ResidualCovarianceEstimator, ResidualCovarianceOptions};
use crate::config::Config;
use crate::gnss::SatId;

use super::super::output::MeasurementKind;
use super::{track_for, NoiseVerdict, Observable, ScalarMeasurement, VarianceBounds};

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

    /// The covariance of a measurement of `kind` whose noise is one matrix: the window's
    /// estimate when full and of the same dimension, else `nominal`.
    pub fn joint_covariance(&self, kind: MeasurementKind, nominal: &DMatrix<f64>) -> DMatrix<f64> {
        self.joint
            .get(&kind)
            .and_then(|t| t.estimator.estimate())
            .filter(|r| r.nrows() == nominal.nrows())
            .unwrap_or_else(|| nominal.clone())
    }

    /// Learns from the post-update residual ε = z − H x̂ of such a measurement and its
    /// H P̂ Hᵀ.
    pub fn after_joint_update(
        &mut self,
        kind: MeasurementKind,
        t_s: f64,
        residual: &DVector<f64>,
        hph: &DMatrix<f64>,
    ) {
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
}
