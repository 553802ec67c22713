//! The redundant-measurement strategies (srmakf, ermakf) of the ERMAKF paper, section 3.
//!
//! For each satellite and observable the second-order mutual difference is
//! ∇Z(k) = ΔZ_GNSS(k) − ΔZ_INS(k) (eq. 14), with ΔZ_GNSS(k) = Z_GNSS(k) − Z_GNSS(k−1) and
//! ΔZ_INS(k) the change of the INS-predicted value over the same interval.
//!
//! Choices where the paper is brief:
//! - ΔZ_INS(k) = Z_INS⁻(k) − Z_INS⁺(k−1): the prediction from the prior state at k less the
//!   prediction from the corrected state at k−1. Both lie on one uncorrected INS
//!   trajectory, so the filter's own update at k−1 does not leak into ∇Z (the paper's
//!   claim that the estimate is independent of the state estimate needs exactly this).
//! - The predictions include the filter's receiver clock offset and drift, so ΔZ_INS
//!   carries the predicted clock change and ∇Z keeps only the clock's unpredictable part
//!   (DESIGN.md, "Pitfalls"); an absorbed clock jump is in both differences and cancels.
//! - A satellite missing for longer than `adaptive.max_epoch_gap_s` restarts its window:
//!   a difference across a gap is not the eq. (14) quantity.
//! - Until `adaptive.min_samples` differences are in the window, the nominal σ is used.

use std::collections::HashMap;

use crate::adaptive::redundant::{
    NoiseRegime, RedundantEstimate, RedundantNoiseEstimator, RedundantNoiseOptions, VarianceMethod,
};
use crate::config::Config;
use crate::gnss::SatId;

use super::{
    estimator_seed, track_for, NoiseVerdict, Observable, ScalarMeasurement, VarianceBounds,
};

/// What is remembered of a satellite's previous epoch.
#[derive(Debug, Clone, Copy)]
struct Previous {
    t_s: f64,
    measured: f64,
    posterior_predicted: f64,
}

#[derive(Debug, Clone)]
struct Track {
    estimator: RedundantNoiseEstimator,
    previous: Option<Previous>,
    last_verdict: Option<NoiseVerdict>,
}

/// Redundant-measurement noise estimation for every satellite and observable.
#[derive(Debug, Clone)]
pub struct RedundantNoise {
    options: RedundantNoiseOptions,
    bounds: VarianceBounds,
    max_gap_s: f64,
    tracks: HashMap<(SatId, Observable), Track>,
}

impl RedundantNoise {
    /// `enhanced`: the ERMAKF (random weighting, KDE detection, Burg AR variance);
    /// otherwise the simple RMAE of eqs. (17)–(18).
    pub fn new(config: &Config, enhanced: bool) -> Self {
        let a = &config.adaptive;
        let options = RedundantNoiseOptions {
            window_size_m: a.window_size_m,
            min_samples: a.min_samples,
            random_weighting: enhanced && a.random_weighting,
            kde_threshold: a.kde_threshold,
            kde_consecutive_epochs: a.kde_consecutive_epochs,
            ar_max_order: a.ar_max_order,
            ar_order_criterion: a.ar_order_criterion,
            ar_denominator_floor: a.ar_denominator_floor,
            seed: a.random_seed,
            detect_non_gaussian: enhanced,
        };
        Self {
            options,
            bounds: VarianceBounds::new(config),
            max_gap_s: a.max_epoch_gap_s,
            tracks: HashMap::new(),
        }
    }

    /// The variance of one measurement at `t_s`; with `learn` false (re-applied after a
    /// roll-back) the estimator is only read.
    pub fn variance(&mut self, t_s: f64, row: &ScalarMeasurement, learn: bool) -> NoiseVerdict {
        let (r_min, r_max) = self.bounds.of(row.observable);
        let options = RedundantNoiseOptions {
            seed: estimator_seed(self.options.seed, row.sat, row.observable),
            ..self.options.clone()
        };
        let max_gap_s = self.max_gap_s;
        let new_track = || {
            RedundantNoiseEstimator::new(options).map(|estimator| Track {
                estimator,
                previous: None,
                last_verdict: None,
            })
        };
        let Some(track) = track_for(&mut self.tracks, row, new_track) else {
            return NoiseVerdict::nominal(row.r_nominal);
        };
        let fresh = track.previous.is_some_and(|p| t_s > p.t_s);
        if !learn || !fresh {
            // Re-applied or out-of-order measurement: read the current estimate.
            return track
                .last_verdict
                .unwrap_or_else(|| NoiseVerdict::nominal(row.r_nominal));
        }
        let Some(previous) = track.previous else {
            return NoiseVerdict::nominal(row.r_nominal);
        };
        if t_s - previous.t_s > max_gap_s {
            track.estimator.push_gap();
            track.last_verdict = None;
            return NoiseVerdict::nominal(row.r_nominal);
        }
        let delta_gnss = row.measured - previous.measured;
        let delta_ins = row.predicted - previous.posterior_predicted;
        let verdict = match track.estimator.push(delta_gnss - delta_ins) {
            Ok(RedundantEstimate::Ready(est)) => NoiseVerdict {
                r: est.r_variance.clamp(r_min, r_max),
                estimated: true,
                kde_credibility: est.credibility.map_or(f64::NAN, |c| c.density),
                gaussian: est.credibility.map(|_| est.regime == NoiseRegime::Gaussian),
                ar_order: match est.method {
                    VarianceMethod::BurgAr { order, .. } => u8::try_from(order).ok(),
                    _ => None,
                },
            },
            Ok(RedundantEstimate::NotEnoughData { .. }) | Err(_) => {
                NoiseVerdict::nominal(row.r_nominal)
            }
        };
        track.last_verdict = verdict.estimated.then_some(verdict);
        verdict
    }

    /// Remembers each measurement with its prediction from the corrected state.
    pub fn after_update(&mut self, t_s: f64, rows: &[ScalarMeasurement], posterior: &[f64]) {
        for (row, &posterior_predicted) in rows.iter().zip(posterior) {
            if let Some(track) = self.tracks.get_mut(&(row.sat, row.observable)) {
                if track.previous.is_none_or(|p| t_s > p.t_s) && posterior_predicted.is_finite() {
                    track.previous = Some(Previous {
                        t_s,
                        measured: row.measured,
                        posterior_predicted,
                    });
                }
            }
        }
    }

    pub fn reset(&mut self) {
        self.tracks.clear();
    }
}
