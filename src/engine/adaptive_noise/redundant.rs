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

use crate::adaptive::common_mode::scaled_residuals;
use crate::adaptive::redundant::{
    NoiseRegime, RedundantEstimate, RedundantNoiseEstimator, RedundantNoiseOptions, VarianceMethod,
};
use crate::config::Config;
use crate::gnss::SatId;
use crate::ins::error_state::{CLOCK_BIAS, CLOCK_DRIFT, DP, DV};

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
            correlation_aware: a.correlation_aware,
            variogram_max_lag: a.variogram_max_lag,
        };
        Self {
            options,
            bounds: VarianceBounds::new(config),
            max_gap_s: a.max_epoch_gap_s,
            tracks: HashMap::new(),
        }
    }

    /// The variances of an epoch's measurements at `t_s`, in order; with `learn` false
    /// (re-applied after a roll-back) the estimators are only read.
    pub fn variances(
        &mut self,
        t_s: f64,
        rows: &[ScalarMeasurement],
        learn: bool,
    ) -> Vec<NoiseVerdict> {
        let mut verdicts: Vec<NoiseVerdict> = rows
            .iter()
            .map(|row| NoiseVerdict::nominal(row.r_nominal))
            .collect();
        let mut differences: Vec<Option<f64>> = vec![None; rows.len()];
        for (i, row) in rows.iter().enumerate() {
            match self.difference(t_s, row, learn) {
                Ok(nabla_z) => differences[i] = Some(nabla_z),
                Err(verdict) => verdicts[i] = verdict,
            }
        }
        let formed: Vec<bool> = differences.iter().map(Option::is_some).collect();
        if self.options.correlation_aware {
            for observable in [Observable::Pseudorange, Observable::PseudorangeRate] {
                remove_common_mode(rows, &mut differences, observable);
            }
        }
        for (i, row) in rows.iter().enumerate() {
            match (differences[i], formed[i]) {
                (Some(nabla_z), _) => verdicts[i] = self.learn(row, nabla_z),
                (None, true) => self.restart(row),
                (None, false) => {}
            }
        }
        verdicts
    }

    /// The mutual difference ∇Z of `row` (eq. 14) to learn from, or the verdict to use
    /// when there is none (re-applied, out of order, first epoch, after a gap).
    fn difference(
        &mut self,
        t_s: f64,
        row: &ScalarMeasurement,
        learn: bool,
    ) -> Result<f64, NoiseVerdict> {
        let options = RedundantNoiseOptions {
            seed: estimator_seed(self.options.seed, row.sat, row.observable),
            ..self.options.clone()
        };
        let nominal = NoiseVerdict::nominal(row.r_nominal);
        let new_track = || {
            RedundantNoiseEstimator::new(options).map(|estimator| Track {
                estimator,
                previous: None,
                last_verdict: None,
            })
        };
        let Some(track) = track_for(&mut self.tracks, row, new_track) else {
            return Err(nominal);
        };
        let fresh = track.previous.is_some_and(|p| t_s > p.t_s);
        if !learn || !fresh {
            // Re-applied or out-of-order measurement: read the current estimate.
            return Err(track.last_verdict.unwrap_or(nominal));
        }
        let Some(previous) = track.previous else {
            return Err(nominal);
        };
        if t_s - previous.t_s > self.max_gap_s {
            track.estimator.push_gap();
            track.last_verdict = None;
            return Err(nominal);
        }
        let delta_gnss = row.measured - previous.measured;
        let delta_ins = row.predicted - previous.posterior_predicted;
        Ok(delta_gnss - delta_ins)
    }

    /// Restarts `row`'s window: its difference of this epoch is not usable.
    fn restart(&mut self, row: &ScalarMeasurement) {
        if let Some(track) = self.tracks.get_mut(&(row.sat, row.observable)) {
            track.estimator.push_gap();
            track.last_verdict = None;
        }
    }

    /// Pushes `nabla_z` into `row`'s estimator (made by [`Self::difference`]) and returns
    /// the verdict.
    fn learn(&mut self, row: &ScalarMeasurement, nabla_z: f64) -> NoiseVerdict {
        let (r_min, r_max) = self.bounds.of(row.observable);
        let nominal = NoiseVerdict::nominal(row.r_nominal);
        let Some(track) = self.tracks.get_mut(&(row.sat, row.observable)) else {
            return nominal;
        };
        let verdict = match track.estimator.push(nabla_z) {
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
            Ok(RedundantEstimate::NotEnoughData { .. }) | Err(_) => nominal,
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

/// The columns of H of the error common to every satellite's ∇Z of `observable`: the INS's
/// position (velocity) increment error and the clock's (drift's) unpredicted change.
fn common_mode_columns(observable: Observable) -> [usize; 4] {
    match observable {
        Observable::Pseudorange => [DP, DP + 1, DP + 2, CLOCK_BIAS],
        Observable::PseudorangeRate => [DV, DV + 1, DV + 2, CLOCK_DRIFT],
    }
}

/// Replaces the differences of `observable` by their part that no error common to all
/// satellites explains (see [`crate::adaptive::common_mode`]), weighted by the nominal
/// variances.
///
/// Choice (the correlation-aware option only): the lag sums of ∇Z would otherwise
/// accumulate the INS increment error, which is correlated from epoch to epoch (the
/// velocity error of the corrected state persists), and the clock's unpredicted change:
/// both grow with the lag like the slow error the variogram is after. A satellite that
/// the fit leaves without redundancy restarts its window (its residual says nothing);
/// with too few satellites for a fit the differences are kept as they are.
fn remove_common_mode(
    rows: &[ScalarMeasurement],
    differences: &mut [Option<f64>],
    observable: Observable,
) {
    let columns = common_mode_columns(observable);
    let members: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].observable == observable && differences[i].is_some())
        .collect();
    let values: Vec<f64> = members.iter().filter_map(|&i| differences[i]).collect();
    let geometry: Vec<[f64; 4]> = members
        .iter()
        .map(|&i| columns.map(|c| rows[i].row[c]))
        .collect();
    let weights: Vec<f64> = members.iter().map(|&i| 1.0 / rows[i].r_nominal).collect();
    if let Some(residuals) = scaled_residuals(&values, &geometry, &weights) {
        for (&i, residual) in members.iter().zip(residuals) {
            differences[i] = residual;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::measurement_rows::Row;
    use crate::gnss::Constellation;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// The pseudo-range σ estimated for satellite 1 after 200 epochs of 9 satellites whose
    /// ranges carry white noise of σ 1 m and a receiver clock walk of 5 m per epoch that
    /// the predictions do not know.
    fn estimated_sigma_m(correlation_aware: bool) -> f64 {
        let mut config = Config::default();
        config.adaptive.correlation_aware = correlation_aware;
        let mut noise = RedundantNoise::new(&config, false);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut clock_m = 0.0;
        let mut last = NoiseVerdict::nominal(0.0);
        for epoch in 0..200 {
            let t_s = f64::from(epoch);
            let step: f64 = StandardNormal.sample(&mut rng);
            clock_m += 5.0 * step;
            let rows: Vec<ScalarMeasurement> = (0..9)
                .map(|i| {
                    let (az, el) = (f64::from(i) * 2.4, 0.3 + 0.12 * f64::from(i % 5));
                    let mut row = Row::zeros();
                    row[DP] = -el.cos() * az.cos() * 6.4e6;
                    row[DP + 1] = -el.cos() * az.sin() * 4.9e6;
                    row[DP + 2] = -el.sin();
                    row[CLOCK_BIAS] = 1.0;
                    let e: f64 = StandardNormal.sample(&mut rng);
                    ScalarMeasurement {
                        sat: SatId {
                            constellation: Constellation::Gps,
                            prn: i as u16 + 1,
                        },
                        observable: Observable::Pseudorange,
                        measured: 2e7 + clock_m + e,
                        predicted: 2e7,
                        hph: 1.0,
                        row,
                        r_nominal: 9.0,
                        r_slow: 0.0,
                    }
                })
                .collect();
            let verdicts = noise.variances(t_s, &rows, true);
            noise.after_update(t_s, &rows, &vec![2e7; rows.len()]);
            last = verdicts[0];
        }
        assert!(last.estimated);
        last.r.sqrt()
    }

    #[test]
    fn the_correlation_aware_option_leaves_out_what_all_satellites_share() {
        let paper = estimated_sigma_m(false);
        let aware = estimated_sigma_m(true);
        assert!(
            paper > 3.0,
            "the paper's estimate takes the clock for noise: {paper}"
        );
        assert!((aware - 1.0).abs() < 0.25, "{aware}");
    }
}
