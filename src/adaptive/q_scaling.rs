//! Process-noise scaling of Ding, Wang & Rizos (2007, J. Navig. 60:517), section 2.2:
//! the factor α of eq. (19),
//!   α = tr{(1/m) Σ d dᵀ − R} / tr{H P⁻ Hᵀ},
//! from the innovations d = z − H x⁻ of the last m epochs, and the rule Q̂ = Q √α, eq. (22).
//!
//! Choices:
//! - Only traces enter eq. (19), and tr(d dᵀ) = dᵀd, so each epoch is kept as three scalars
//!   (dᵀd, tr R, tr H P⁻ Hᵀ), and α = Σ(dᵀd − tr R) / Σ tr(H P⁻ Hᵀ) over the window. This is
//!   eq. (19) when R and H P⁻ Hᵀ are constant over the window, and stays meaningful when the
//!   number of satellites changes from epoch to epoch (each innovation is compared with its
//!   own predicted covariance).
//! - α is clamped to [alpha_min, alpha_max]: the numerator is negative whenever the
//!   innovations are smaller than the measurement noise alone, where √α is undefined.
//! - No α is given before `min_samples` epochs ("not enough data").
//! - Math note on eq. (22): Q_{k−1} there is the Q of the previous prediction, so applied
//!   epoch after epoch the rule is a multiplicative feedback that settles where α = 1
//!   (section 2.2: "only when the predicted and the calculated innovation covariance are
//!   consistently equal, α is stabilised at value one"). [`scale_process_noise`] applies
//!   one step; which Q it is handed (nominal or previously scaled) is the engine's choice.
//!   Measured on a scalar random walk (tests/iarf_math.rs): fed back at *every* epoch over
//!   a sliding window the loop winds up (Q swings over five decades), because the window
//!   still holds innovations produced by the old Q; fed back once per full window and the
//!   window then cleared ([`ProcessNoiseScaler::reset`]), it settles within ~7 % of the
//!   true Q; applied to the nominal Q instead (no feedback) it corrects only part of a
//!   mis-set Q (0.1 → 0.2, 10 → 5.5 for a true 1).

use super::math_error::{check_matrix, check_option, check_vector, AdaptiveMathError};
use super::residual_r::validate_window;
use crate::linalg::symmetrize;
use nalgebra::{DMatrix, DVector};
use std::collections::VecDeque;

/// Options of the process-noise scaling factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessNoiseScalingOptions {
    /// Window length m (epochs). Default 64, the window of Ding et al. (section 3.2).
    pub window: usize,
    /// Epochs needed before α is given (1 ≤ min_samples ≤ window). Default 16. Choice:
    /// with r ≈ 8 rows per epoch, 16 epochs hold ~128 squared innovations, a relative spread
    /// of about √(2/128) ≈ 13 % on the numerator.
    pub min_samples: usize,
    /// Lower bound on α (dimensionless, > 0). Default 0.01 (Q scaled by ≥ 0.1 per step).
    /// Choice: the paper sets no bound; see the module notes.
    pub alpha_min: f64,
    /// Upper bound on α (dimensionless, ≥ alpha_min). Default 100 (Q scaled by ≤ 10 per
    /// step). Choice: the paper sets no bound.
    pub alpha_max: f64,
}

impl Default for ProcessNoiseScalingOptions {
    fn default() -> Self {
        Self {
            window: 64,
            min_samples: 16,
            alpha_min: 0.01,
            alpha_max: 100.0,
        }
    }
}

impl ProcessNoiseScalingOptions {
    /// Checks the window and 0 < alpha_min ≤ 1 ≤ alpha_max.
    pub fn validate(&self) -> Result<(), AdaptiveMathError> {
        validate_window(self.window, self.min_samples)?;
        check_option(
            "alpha_min",
            self.alpha_min,
            self.alpha_min > 0.0 && self.alpha_min <= 1.0,
            "must be in (0, 1]",
        )?;
        check_option(
            "alpha_max",
            self.alpha_max,
            self.alpha_max >= 1.0,
            "must be >= 1",
        )
    }
}

/// One α value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalingFactor {
    /// α clamped to [alpha_min, alpha_max].
    pub alpha: f64,
    /// α of eq. (19) before clamping (may be negative).
    pub unclamped: f64,
    /// Epochs that entered it.
    pub samples: usize,
}

#[derive(Debug, Clone, Copy)]
struct EpochTraces {
    innovation_norm_squared: f64,
    r_trace: f64,
    predicted_trace: f64,
}

/// Windowed estimator of the process-noise scaling factor α, eq. (19).
#[derive(Debug, Clone)]
pub struct ProcessNoiseScaler {
    options: ProcessNoiseScalingOptions,
    samples: VecDeque<EpochTraces>,
}

impl ProcessNoiseScaler {
    /// An empty estimator; the options are validated.
    pub fn new(options: ProcessNoiseScalingOptions) -> Result<Self, AdaptiveMathError> {
        options.validate()?;
        Ok(Self {
            options,
            samples: VecDeque::with_capacity(options.window),
        })
    }

    /// Adds one epoch: innovation d = z − H x⁻ (r), the R used (r×r) and H P⁻ Hᵀ (r×r).
    pub fn push(
        &mut self,
        innovation: &DVector<f64>,
        measurement_covariance: &DMatrix<f64>,
        h_p_ht: &DMatrix<f64>,
    ) -> Result<(), AdaptiveMathError> {
        check_vector("innovation", innovation)?;
        let r = innovation.len();
        check_matrix("measurement covariance R", measurement_covariance, r, r)?;
        check_matrix("H P⁻ Hᵀ", h_p_ht, r, r)?;
        let predicted_trace = h_p_ht.trace();
        if predicted_trace < 0.0 {
            return Err(AdaptiveMathError::NotPositive {
                what: "trace of H P⁻ Hᵀ",
                value: predicted_trace,
            });
        }
        if self.samples.len() == self.options.window {
            self.samples.pop_front();
        }
        self.samples.push_back(EpochTraces {
            innovation_norm_squared: innovation.norm_squared(),
            r_trace: measurement_covariance.trace(),
            predicted_trace,
        });
        Ok(())
    }

    /// Epochs in the window.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True when the window is empty.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Clears the window.
    pub fn reset(&mut self) {
        self.samples.clear();
    }

    /// α of eq. (19), or None before `min_samples` epochs or when Σ tr(H P⁻ Hᵀ) = 0.
    pub fn scaling_factor(&self) -> Option<ScalingFactor> {
        if self.samples.len() < self.options.min_samples {
            return None;
        }
        let (numerator, denominator) = self.samples.iter().fold((0.0, 0.0), |(n, d), s| {
            (
                n + s.innovation_norm_squared - s.r_trace,
                d + s.predicted_trace,
            )
        });
        if denominator <= 0.0 {
            return None;
        }
        let unclamped = numerator / denominator;
        Some(ScalingFactor {
            alpha: unclamped.clamp(self.options.alpha_min, self.options.alpha_max),
            unclamped,
            samples: self.samples.len(),
        })
    }
}

/// Q̂ = Q √α, eq. (22), symmetrised (α > 0; a positive multiple keeps Q positive definite).
pub fn scale_process_noise(
    process_noise: &DMatrix<f64>,
    alpha: f64,
) -> Result<DMatrix<f64>, AdaptiveMathError> {
    if !(alpha.is_finite() && alpha > 0.0) {
        return Err(AdaptiveMathError::NotPositive {
            what: "process-noise scaling factor",
            value: alpha,
        });
    }
    let n = process_noise.nrows();
    check_matrix("process noise Q", process_noise, n, n)?;
    Ok(symmetrize(process_noise) * alpha.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_example_and_clamping() {
        let opts = ProcessNoiseScalingOptions {
            window: 2,
            min_samples: 1,
            alpha_min: 0.5,
            alpha_max: 4.0,
        };
        let mut s = ProcessNoiseScaler::new(opts).unwrap();
        let r = DMatrix::from_element(1, 1, 1.0);
        let hph = DMatrix::from_element(1, 1, 2.0);
        s.push(&DVector::from_element(1, 3.0), &r, &hph).unwrap();
        // (9 - 1) / 2 = 4
        let a = s.scaling_factor().unwrap();
        assert_eq!((a.alpha, a.unclamped), (4.0, 4.0));
        s.push(&DVector::from_element(1, 0.0), &r, &hph).unwrap();
        // (8 - 1) / 4 = 1.75
        assert!((s.scaling_factor().unwrap().alpha - 1.75).abs() < 1e-15);
        s.push(&DVector::from_element(1, 0.0), &r, &hph).unwrap();
        // window 2: (-1 - 1) / 4 = -0.5 -> clamped to 0.5
        let a = s.scaling_factor().unwrap();
        assert_eq!((a.alpha, a.unclamped, a.samples), (0.5, -0.5, 2));
        s.reset();
        assert!(s.scaling_factor().is_none());
    }

    #[test]
    fn q_is_scaled_by_the_square_root() {
        let q = DMatrix::from_row_slice(2, 2, &[1.0, 0.1, 0.1, 2.0]);
        let qs = scale_process_noise(&q, 4.0).unwrap();
        assert!((qs - &q * 2.0).amax() < 1e-15);
        assert!(scale_process_noise(&q, -1.0).is_err());
    }
}
