//! Windowed innovation-based estimate of the measurement noise variance with a randomness
//! test and an AR(1) correction: the EIAKF baseline of the ERMAKF paper (its reference
//! \[24\], Ghaleb et al.), for one scalar observable.
//!
//! Per epoch the caller passes the innovation ν = z − h(x̂⁻) and the scalar H P⁻ Hᵀ of the
//! same row. Over the last N innovations:
//! - Ĉ = (1/N) Σ ν² (innovation covariance);
//! - randomness test: lag-1 autocorrelation r₁ = Σ ν_n ν_{n−1} / Σ ν_n², statistic
//!   z = √N · r₁, which is N(0, 1) for a white sequence (Bartlett); the sequence is declared
//!   correlated when |z| exceeds the two-sided normal quantile at `significance`;
//! - if correlated, AR(1) by Yule–Walker (a = r₁) and the eq. (29) correction with p = 1:
//!   Ĉ ← Ĉ / (1 − a r₁) = Ĉ / (1 − r₁²), an inflation;
//! - R̂ = Ĉ − H P⁻ Hᵀ, floored (see [`InnovationOptions`]);
//! - resolvability test: R̂ is only reported as resolved when Ĉ exceeds H P⁻ Hᵀ by more
//!   than its own sampling noise (one-sided χ² test, see
//!   [`InnovationCovarianceEstimator::push`]).
//!
//! Choice (test): the lag-1 z-test, because the correction it gates is an AR(1) model; a
//! Ljung–Box test over more lags would flag correlations that AR(1) does not model.
//! Innovations are not demeaned: under the null hypothesis of an optimal filter they are
//! zero-mean and white, and a bias is itself a sign of a mis-modelled filter.

use std::collections::VecDeque;

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use super::ar_variance::{ar_corrected_variance, autocorrelation_coefficients, mean_square};
use super::error::{check_finite, AdaptiveError};

/// Options of one [`InnovationCovarianceEstimator`].
#[derive(Debug, Clone, PartialEq)]
pub struct InnovationOptions {
    /// Window length N (epochs). Default 50.
    pub window_size: usize,
    /// Innovations needed before the first estimate (epochs); at least 3, at most
    /// `window_size`. Default 20.
    pub min_samples: usize,
    /// Two-sided significance level α of the lag-1 whiteness test, and one-sided level of
    /// the resolvability test, in (0, 1). Default 0.05.
    pub significance: f64,
    /// Absolute floor of R̂ (unit of ν, squared). Default 0, i.e. only the relative floor.
    pub min_variance: f64,
    /// Relative floor of R̂ as a fraction of the (corrected) innovation variance Ĉ, in
    /// (0, 1]. Default 0.1.
    pub min_fraction_of_innovation: f64,
    /// Floor of the AR(1) correction denominator 1 − r₁², in (0, 1]. Default 0.1.
    pub ar_denominator_floor: f64,
}

impl Default for InnovationOptions {
    fn default() -> Self {
        Self {
            window_size: 50,
            min_samples: 20,
            significance: 0.05,
            min_variance: 0.0,
            min_fraction_of_innovation: 0.1,
            ar_denominator_floor: 0.1,
        }
    }
}

impl InnovationOptions {
    /// Checks the ranges documented on each field.
    pub fn validate(&self) -> Result<(), AdaptiveError> {
        let invalid = |name, value: f64, reason| {
            Err(AdaptiveError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if self.min_samples < 3 {
            return invalid("min_samples", self.min_samples as f64, "must be at least 3");
        }
        if self.window_size < self.min_samples {
            return invalid(
                "window_size",
                self.window_size as f64,
                "must be at least min_samples",
            );
        }
        if !(self.significance > 0.0 && self.significance < 1.0) {
            return invalid("significance", self.significance, "must lie in (0, 1)");
        }
        if !(self.min_variance >= 0.0 && self.min_variance.is_finite()) {
            return invalid(
                "min_variance",
                self.min_variance,
                "must be non-negative and finite",
            );
        }
        if !(self.min_fraction_of_innovation > 0.0 && self.min_fraction_of_innovation <= 1.0) {
            return invalid(
                "min_fraction_of_innovation",
                self.min_fraction_of_innovation,
                "must lie in (0, 1]",
            );
        }
        if !(self.ar_denominator_floor > 0.0 && self.ar_denominator_floor <= 1.0) {
            return invalid(
                "ar_denominator_floor",
                self.ar_denominator_floor,
                "must lie in (0, 1]",
            );
        }
        Ok(())
    }
}

/// The estimate after one innovation, once the window holds enough data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnovationEstimate {
    /// Innovations in the window (the newest included).
    pub n_samples: usize,
    /// Ĉ = (1/N) Σ ν², before any correction.
    pub innovation_variance: f64,
    /// Lag-1 autocorrelation r₁ of the window (0 for an all-zero window).
    pub lag1_autocorrelation: f64,
    /// Test statistic √N · r₁.
    pub z_statistic: f64,
    /// True when |z| exceeded the critical value: the AR(1) correction was applied.
    pub correlated: bool,
    /// Ĉ after the AR(1) correction (equal to `innovation_variance` when not correlated).
    pub corrected_innovation_variance: f64,
    /// R̂ = corrected Ĉ − H P⁻ Hᵀ, after the floors.
    pub r_variance: f64,
    /// True when a floor set `r_variance`.
    pub floored: bool,
    /// True when the window resolves R: the corrected Ĉ is significantly above H P⁻ Hᵀ.
    /// False: Ĉ is within its own sampling noise of what the predicted covariance alone
    /// explains, and `r_variance` is a difference of two nearly equal numbers that says
    /// nothing about R.
    pub resolved: bool,
}

/// Outcome of [`InnovationCovarianceEstimator::push`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InnovationOutcome {
    /// Fewer than `min_samples` innovations in the window: no estimate.
    NotEnoughData {
        /// Innovations in the window now.
        n_samples: usize,
        /// Innovations needed.
        min_samples: usize,
    },
    /// An estimate to use.
    Ready(InnovationEstimate),
}

/// Windowed innovation-covariance estimator of one scalar observable.
#[derive(Debug, Clone)]
pub struct InnovationCovarianceEstimator {
    options: InnovationOptions,
    critical_z: f64,
    /// χ²ₖ(1 − α)/k for k = 1 ..= `window_size` degrees of freedom (index k − 1): the
    /// ratio Ĉ / H P⁻ Hᵀ that a window of k independent innovations exceeds with
    /// probability α when R = 0.
    resolvable_ratio: Vec<f64>,
    window: VecDeque<f64>,
}

impl InnovationCovarianceEstimator {
    /// A new estimator with an empty window.
    pub fn new(options: InnovationOptions) -> Result<Self, AdaptiveError> {
        options.validate()?;
        let standard_normal = Normal::standard();
        let critical_z = standard_normal.inverse_cdf(1.0 - options.significance / 2.0);
        let resolvable_ratio = (1..=options.window_size)
            .map(|k| {
                let dof = k as f64;
                ChiSquared::new(dof)
                    .map(|d| d.inverse_cdf(1.0 - options.significance) / dof)
                    .map_err(|_| AdaptiveError::InvalidParameter {
                        name: "window_size",
                        value: dof,
                        reason: "no χ² distribution with these degrees of freedom",
                    })
            })
            .collect::<Result<_, _>>()?;
        Ok(Self {
            window: VecDeque::with_capacity(options.window_size),
            critical_z,
            resolvable_ratio,
            options,
        })
    }

    /// Two-sided critical value of |√N r₁| at the configured significance.
    pub fn critical_z(&self) -> f64 {
        self.critical_z
    }

    /// Innovations in the window.
    pub fn n_samples(&self) -> usize {
        self.window.len()
    }

    /// Empties the window (after a gap or a filter re-initialisation).
    pub fn reset(&mut self) {
        self.window.clear();
    }

    /// Adds innovation `innovation` and the scalar `hph` = H P⁻ Hᵀ of the same row, and
    /// returns the estimate.
    ///
    /// Choice (floor): R̂ = max(Ĉ − H P⁻ Hᵀ, `min_fraction_of_innovation`·Ĉ,
    /// `min_variance`) with Ĉ the corrected innovation variance. A difference at or below
    /// zero means the predicted covariance already explains the innovations; a fraction of
    /// Ĉ keeps R̂ positive and on the scale of the data whatever the observable's unit.
    ///
    /// Choice (resolvability): when H P⁻ Hᵀ is of the size of R, Ĉ − H P⁻ Hᵀ is the
    /// difference of two nearly equal numbers, and Ĉ carries a sampling error of about
    /// Ĉ·√(2/N). A P⁻ that is a little pessimistic (a conservative process noise, or the
    /// slow error part added to R) then pushes R̂ to the floor, and the filter, weighing
    /// its measurements by that R̂, becomes over-confident (a mean open-sky NEES of 14–29
    /// for 9 degrees of freedom, from pseudo-range rates whose H P⁻ Hᵀ exceeds R). So the
    /// estimate is `resolved` only when N_eff·Ĉ / H P⁻ Hᵀ exceeds the χ²(N_eff) quantile
    /// at 1 − `significance`: the window's innovations are then, at that level, more than
    /// the predicted covariance explains. N_eff is N, or N(1 − r₁²)/(1 + r₁²) when the
    /// AR(1) correction applies (the variance of a correlated window's mean square). The
    /// test uses the newest H P⁻ Hᵀ for the whole window, which changes slowly between
    /// epochs. The caller decides what to use when R is not resolved.
    ///
    /// Errors: non-finite input or a negative `hph` (the estimator is left unchanged).
    pub fn push(&mut self, innovation: f64, hph: f64) -> Result<InnovationOutcome, AdaptiveError> {
        check_finite("innovation estimator input", &[innovation, hph])?;
        if hph < 0.0 {
            return Err(AdaptiveError::InvalidParameter {
                name: "hph",
                value: hph,
                reason: "H P Hᵀ must be non-negative",
            });
        }
        if self.window.len() == self.options.window_size {
            self.window.pop_front();
        }
        self.window.push_back(innovation);
        let n = self.window.len();
        if n < self.options.min_samples {
            return Ok(InnovationOutcome::NotEnoughData {
                n_samples: n,
                min_samples: self.options.min_samples,
            });
        }

        let window = self.window.make_contiguous();
        let innovation_variance = mean_square(window)?;
        let r1 = match autocorrelation_coefficients(window, 1) {
            Ok(beta) => beta.first().copied().unwrap_or(0.0),
            // An all-zero window: no correlation to speak of.
            Err(AdaptiveError::ZeroVariance { .. }) => 0.0,
            Err(e) => return Err(e),
        };
        let z_statistic = (n as f64).sqrt() * r1;
        let correlated = z_statistic.abs() > self.critical_z;
        let corrected_innovation_variance = if correlated {
            // Yule–Walker AR(1): a = r₁; eq. (29) with p = 1.
            ar_corrected_variance(window, &[r1], self.options.ar_denominator_floor)?.variance
        } else {
            innovation_variance
        };

        let difference = corrected_innovation_variance - hph;
        let floor = (self.options.min_fraction_of_innovation * corrected_innovation_variance)
            .max(self.options.min_variance);
        let floored = difference < floor;
        let effective_samples = if correlated {
            let r1_squared = r1 * r1;
            n as f64 * (1.0 - r1_squared) / (1.0 + r1_squared)
        } else {
            n as f64
        };
        // Truncated to whole degrees of freedom, at least one: fewer make the test stricter.
        let dof_index = (effective_samples.floor() as usize).clamp(1, n) - 1;
        let resolved = corrected_innovation_variance > self.resolvable_ratio[dof_index] * hph;
        Ok(InnovationOutcome::Ready(InnovationEstimate {
            n_samples: n,
            innovation_variance,
            lag1_autocorrelation: r1,
            z_statistic,
            correlated,
            corrected_innovation_variance,
            r_variance: if floored { floor } else { difference },
            floored,
            resolved,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ready(outcome: InnovationOutcome) -> InnovationEstimate {
        match outcome {
            InnovationOutcome::Ready(e) => e,
            other => panic!("expected an estimate, got {other:?}"),
        }
    }

    #[test]
    fn critical_value_at_five_percent() {
        let est = InnovationCovarianceEstimator::new(InnovationOptions::default()).unwrap();
        assert!((est.critical_z() - 1.959_963_984_540_054).abs() < 1e-9);
    }

    /// An estimator whose window of four innovations gives its first estimate when full.
    fn four_sample_estimator() -> InnovationCovarianceEstimator {
        InnovationCovarianceEstimator::new(InnovationOptions {
            window_size: 4,
            min_samples: 4,
            ..InnovationOptions::default()
        })
        .unwrap()
    }

    #[test]
    fn alternating_sequence_by_hand() {
        // ν = ±1 alternating, N = 4: Ĉ = 1, r₁ = −3/4, z = 2·(−3/4) = −1.5: white at 5 %.
        let mut est = four_sample_estimator();
        for v in [1.0, -1.0, 1.0] {
            assert!(matches!(
                est.push(v, 0.2).unwrap(),
                InnovationOutcome::NotEnoughData { .. }
            ));
        }
        let e = ready(est.push(-1.0, 0.2).unwrap());
        assert!((e.lag1_autocorrelation + 0.75).abs() < 1e-15);
        assert!((e.z_statistic + 1.5).abs() < 1e-15);
        assert!(!e.correlated);
        assert!((e.r_variance - 0.8).abs() < 1e-15);
        assert!(!e.floored);
        // Ĉ / H P Hᵀ = 5 against χ²₄(0.95)/4 = 2.372.
        assert!(e.resolved);
    }

    #[test]
    fn resolved_only_when_the_window_exceeds_the_predicted_covariance_significantly() {
        // ν = ±1 alternating over N = 4 (white at 5 %): Ĉ = 1, N Ĉ / H P Hᵀ against
        // χ²₄(0.95) = 9.4877: resolved below H P Hᵀ = 4/9.4877 = 0.4216, not above it.
        let last = |hph: f64| {
            let mut est = four_sample_estimator();
            let outcomes: Vec<_> = [1.0, -1.0, 1.0, -1.0]
                .iter()
                .map(|&v| est.push(v, hph).unwrap())
                .collect();
            ready(outcomes[3])
        };
        let limit = 4.0 / 9.487_729_036_781_154;
        assert!(last(limit * 0.99).resolved);
        let unresolved = last(limit * 1.01);
        assert!(!unresolved.resolved);
        // Its difference is still positive: significance, not sign, decides.
        assert!(!unresolved.floored && unresolved.r_variance > 0.5);
    }

    #[test]
    fn correlated_window_is_inflated_and_floored() {
        // A slowly varying window: r₁ near 1, test rejects, AR(1) inflation, and a large
        // H P Hᵀ forces the relative floor.
        let opts = InnovationOptions {
            window_size: 30,
            min_samples: 30,
            ..InnovationOptions::default()
        };
        let mut est = InnovationCovarianceEstimator::new(opts).unwrap();
        let mut last = None;
        for i in 0..30 {
            last = Some(est.push(1.0 + 0.01 * i as f64, 100.0).unwrap());
        }
        let e = ready(last.unwrap());
        assert!(e.correlated);
        let r1 = e.lag1_autocorrelation;
        let expected = e.innovation_variance / (1.0 - r1 * r1).max(0.1);
        assert!((e.corrected_innovation_variance - expected).abs() < 1e-12 * expected);
        assert!(e.corrected_innovation_variance > e.innovation_variance);
        assert!(e.floored);
        assert!((e.r_variance - 0.1 * e.corrected_innovation_variance).abs() < 1e-15);
        assert!(!e.resolved);
    }

    #[test]
    fn negative_hph_is_rejected() {
        let mut est = InnovationCovarianceEstimator::new(InnovationOptions::default()).unwrap();
        assert!(est.push(1.0, -0.1).is_err());
        assert_eq!(est.n_samples(), 0);
    }
}
