//! The innovation-based strategy (eiakf), the ERMAKF paper's baseline after its reference
//! [24]: per satellite and observable, R̂ = Ĉ_ν − h P⁻ hᵀ over a window of innovations,
//! with a whiteness test and an AR(1) (Yule-Walker) correction when the innovations are
//! correlated (see [`crate::adaptive::innovation`]). The innovation of the current epoch
//! is in its own window: the paper's reference estimates R before each update.

use std::collections::HashMap;

use crate::adaptive::innovation::{
    InnovationCovarianceEstimator, InnovationOptions, InnovationOutcome,
};
use crate::config::Config;
use crate::gnss::SatId;

use super::{track_for, NoiseVerdict, Observable, ScalarMeasurement, VarianceBounds};

#[derive(Debug, Clone)]
struct Track {
    estimator: InnovationCovarianceEstimator,
    last_t_s: f64,
    last_verdict: Option<NoiseVerdict>,
}

/// Innovation-based noise estimation for every satellite and observable.
#[derive(Debug, Clone)]
pub struct InnovationNoise {
    /// An empty estimator that every new track copies (its quantile table is computed
    /// once, not per satellite); None when the options were refused (every verdict is
    /// then the nominal variance).
    prototype: Option<InnovationCovarianceEstimator>,
    bounds: VarianceBounds,
    max_gap_s: f64,
    tracks: HashMap<(SatId, Observable), Track>,
}

impl InnovationNoise {
    pub fn new(config: &Config) -> Self {
        let a = &config.adaptive;
        let options = InnovationOptions {
            window_size: a.innovation_window,
            min_samples: a.min_samples.min(a.innovation_window),
            significance: a.innovation_significance,
            ar_denominator_floor: a.ar_denominator_floor,
            ..InnovationOptions::default()
        };
        Self {
            prototype: InnovationCovarianceEstimator::new(options).ok(),
            bounds: VarianceBounds::new(config),
            max_gap_s: a.max_epoch_gap_s,
            tracks: HashMap::new(),
        }
    }

    /// The variance of one measurement at `t_s`; with `learn` false (re-applied after a
    /// roll-back) the estimator is only read.
    pub fn variance(&mut self, t_s: f64, row: &ScalarMeasurement, learn: bool) -> NoiseVerdict {
        let (r_min, r_max) = self.bounds.of(row.observable);
        let new_track = || {
            self.prototype
                .clone()
                .map(|estimator| Track {
                    estimator,
                    last_t_s: f64::NEG_INFINITY,
                    last_verdict: None,
                })
                .ok_or(())
        };
        let Some(track) = track_for(&mut self.tracks, row, new_track) else {
            return NoiseVerdict::nominal(row.r_nominal);
        };
        if !learn || t_s <= track.last_t_s {
            return track
                .last_verdict
                .unwrap_or_else(|| NoiseVerdict::nominal(row.r_nominal));
        }
        if t_s - track.last_t_s > self.max_gap_s {
            track.estimator.reset();
        }
        track.last_t_s = t_s;
        let innovation = row.measured - row.predicted;
        let verdict = match track.estimator.push(innovation, row.hph) {
            // Choice: a window that cannot resolve R (see `InnovationEstimate::resolved`)
            // gives the nominal variance of the fixed σ model, not its floored estimate:
            // the model is what the filter would use with no estimator at all, while the
            // floor would claim a precision nothing measured.
            Ok(InnovationOutcome::Ready(est)) if est.resolved => NoiseVerdict {
                r: est.r_variance.clamp(r_min, r_max),
                estimated: true,
                kde_credibility: f64::NAN,
                gaussian: None,
                ar_order: est.correlated.then_some(1),
            },
            Ok(InnovationOutcome::Ready(_) | InnovationOutcome::NotEnoughData { .. }) | Err(_) => {
                NoiseVerdict::nominal(row.r_nominal)
            }
        };
        track.last_verdict = verdict.estimated.then_some(verdict);
        verdict
    }

    pub fn reset(&mut self) {
        self.tracks.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::measurement_rows::Row;
    use crate::gnss::Constellation;

    fn rate_row(innovation: f64, hph: f64) -> ScalarMeasurement {
        ScalarMeasurement {
            sat: SatId {
                constellation: Constellation::Gps,
                prn: 5,
            },
            observable: Observable::PseudorangeRate,
            measured: innovation,
            predicted: 0.0,
            hph,
            row: Row::zeros(),
            r_nominal: 0.04,
            r_slow: 0.0,
        }
    }

    /// The last verdict after a full window of innovations of ±0.2 m/s in the pattern
    /// + + − − (Ĉ = 0.04, lag-1 autocorrelation 0.02: white) with `hph` on every row.
    fn verdict_after_a_window(hph: f64) -> NoiseVerdict {
        let config = Config::default();
        let mut noise = InnovationNoise::new(&config);
        let epochs = config.adaptive.innovation_window;
        let mut last = None;
        for k in 0..epochs {
            let sign = if k % 4 < 2 { 1.0 } else { -1.0 };
            last = Some(noise.variance(k as f64, &rate_row(0.2 * sign, hph), true));
        }
        last.unwrap()
    }

    #[test]
    fn a_window_the_predicted_covariance_explains_gives_the_nominal_variance() {
        // H P Hᵀ = 0.035 of Ĉ = 0.04: the difference 0.005 is within the sampling noise of
        // Ĉ over 50 epochs, so the filter keeps the nominal 0.04, not an R of 0.005.
        let v = verdict_after_a_window(0.035);
        assert!(!v.estimated);
        assert_eq!(v.r, 0.04);
    }

    #[test]
    fn a_window_well_above_the_predicted_covariance_gives_its_estimate() {
        let v = verdict_after_a_window(0.01);
        assert!(v.estimated);
        assert!((v.r - 0.03).abs() < 1e-12, "{}", v.r);
    }
}
