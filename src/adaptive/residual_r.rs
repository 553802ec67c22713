//! Residual-based measurement-noise estimate of Ding, Wang & Rizos (2007, J. Navig. 60:517),
//! eq. (14), R̂ = E{εεᵀ} + H P̂ Hᵀ, with the expectation a moving window of m epochs,
//! eq. (15). ε = z − H x̂ is the post-update residual, P̂ the posterior covariance.
//!
//! Choices:
//! - Each window sample is εεᵀ + H P̂ Hᵀ of its own epoch, and R̂ their mean. When H P̂ Hᵀ
//!   is constant over the window this is eq. (14)–(15) exactly; when it changes, it is
//!   still unbiased for a stationary R (E{εεᵀ} = R − H P̂ Hᵀ holds epoch by epoch, eq. (13)).
//! - The window has one dimension. A sample of another dimension (a satellite set
//!   change) restarts it, reported by [`WindowEvent::Restarted`]. An engine whose
//!   measurement set changes should keep one estimator per channel (dimension 1).
//! - Positivity: every sample is a sum of positive semi-definite matrices, so R̂ can only
//!   be singular (fewer samples than rows, or H P̂ Hᵀ ≈ 0), never negative. R̂ is
//!   symmetrised and its eigenvalues are raised to `variance_floor`; no estimate is given
//!   before `min_samples` samples ("not enough data": the caller keeps its nominal R).

use super::math_error::{check_matrix, check_vector, AdaptiveMathError};
use crate::linalg::symmetrize;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use std::collections::VecDeque;

/// Options of the residual-based R estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualCovarianceOptions {
    /// Window length m (epochs). Default 64, the window Ding et al. use (section 3.2).
    pub window: usize,
    /// Samples needed before an estimate is given (epochs, 1 ≤ min_samples ≤ window).
    /// Default 64 (a full window): with fewer, a variance estimate from m samples has a
    /// relative spread √(2/m) above 18 %.
    pub min_samples: usize,
    /// Smallest eigenvalue of R̂ (squared measurement units: m² for pseudo-ranges,
    /// (m/s)² for rates). Default 1e-4 (σ = 1 cm or 1 cm/s), well below any GNSS noise.
    pub variance_floor: f64,
}

impl Default for ResidualCovarianceOptions {
    fn default() -> Self {
        Self {
            window: 64,
            min_samples: 64,
            variance_floor: 1e-4,
        }
    }
}

impl ResidualCovarianceOptions {
    /// Checks window ≥ 1, 1 ≤ min_samples ≤ window, variance_floor > 0.
    pub fn validate(&self) -> Result<(), AdaptiveMathError> {
        validate_window(self.window, self.min_samples)?;
        super::math_error::check_option(
            "variance_floor",
            self.variance_floor,
            self.variance_floor > 0.0,
            "must be > 0",
        )
    }
}

/// Shared check of a window length and its minimum fill.
pub(crate) fn validate_window(window: usize, min_samples: usize) -> Result<(), AdaptiveMathError> {
    super::math_error::check_option("window", window as f64, window >= 1, "must be >= 1 epoch")?;
    super::math_error::check_option(
        "min_samples",
        min_samples as f64,
        min_samples >= 1 && min_samples <= window,
        "must be in [1, window]",
    )
}

/// What a push did to the window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowEvent {
    /// The sample was appended (the oldest dropped if the window was full).
    Appended,
    /// The sample had another dimension than the window: the window was cleared first.
    Restarted,
}

/// Windowed estimator of R from post-update residuals, eqs. (14)–(15).
#[derive(Debug, Clone)]
pub struct ResidualCovarianceEstimator {
    options: ResidualCovarianceOptions,
    samples: VecDeque<DMatrix<f64>>,
}

impl ResidualCovarianceEstimator {
    /// An empty estimator; the options are validated.
    pub fn new(options: ResidualCovarianceOptions) -> Result<Self, AdaptiveMathError> {
        options.validate()?;
        Ok(Self {
            options,
            samples: VecDeque::with_capacity(options.window),
        })
    }

    /// Adds the residual ε = z − H x̂ (r) and H P̂ Hᵀ (r×r) of one epoch.
    pub fn push(
        &mut self,
        residual: &DVector<f64>,
        h_p_ht: &DMatrix<f64>,
    ) -> Result<WindowEvent, AdaptiveMathError> {
        check_vector("post-update residual", residual)?;
        let r = residual.len();
        check_matrix("H P Hᵀ", h_p_ht, r, r)?;
        let event = match self.samples.front() {
            Some(first) if first.nrows() != r => {
                self.samples.clear();
                WindowEvent::Restarted
            }
            _ => WindowEvent::Appended,
        };
        if self.samples.len() == self.options.window {
            self.samples.pop_front();
        }
        self.samples
            .push_back(residual * residual.transpose() + symmetrize(h_p_ht));
        Ok(event)
    }

    /// Samples in the window.
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

    /// R̂ (r×r, symmetric positive definite), or None before `min_samples` samples (or if
    /// the eigen-solver fails, which it does not on finite symmetric input).
    pub fn estimate(&self) -> Option<DMatrix<f64>> {
        if self.samples.len() < self.options.min_samples {
            return None;
        }
        let first = self.samples.front()?;
        let mut sum = DMatrix::zeros(first.nrows(), first.ncols());
        for s in &self.samples {
            sum += s;
        }
        let mean = symmetrize(&(sum / self.samples.len() as f64));
        let eigen = SymmetricEigen::try_new(mean, f64::EPSILON, 10_000)?;
        let floored = eigen
            .eigenvalues
            .map(|v| v.max(self.options.variance_floor));
        Some(symmetrize(
            &(&eigen.eigenvectors
                * DMatrix::from_diagonal(&floored)
                * eigen.eigenvectors.transpose()),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_of_samples_and_window_sliding() {
        let opts = ResidualCovarianceOptions {
            window: 2,
            min_samples: 2,
            variance_floor: 1e-6,
        };
        let mut e = ResidualCovarianceEstimator::new(opts).unwrap();
        let hph = DMatrix::from_element(1, 1, 0.5);
        e.push(&DVector::from_element(1, 10.0), &hph).unwrap();
        assert!(e.estimate().is_none());
        e.push(&DVector::from_element(1, 1.0), &hph).unwrap();
        assert!((e.estimate().unwrap()[(0, 0)] - (50.5 + 0.5)).abs() < 1e-12);
        e.push(&DVector::from_element(1, 3.0), &hph).unwrap();
        assert!((e.estimate().unwrap()[(0, 0)] - (5.0 + 0.5)).abs() < 1e-12);
        let ev = e
            .push(&DVector::from_element(2, 1.0), &DMatrix::zeros(2, 2))
            .unwrap();
        assert_eq!(ev, WindowEvent::Restarted);
        assert_eq!(e.len(), 1);
        e.reset();
        assert!(e.is_empty());
    }

    #[test]
    fn singular_window_is_floored_to_positive_definite() {
        let opts = ResidualCovarianceOptions {
            window: 1,
            min_samples: 1,
            variance_floor: 1e-4,
        };
        let mut e = ResidualCovarianceEstimator::new(opts).unwrap();
        e.push(&DVector::from_vec(vec![1.0, 1.0]), &DMatrix::zeros(2, 2))
            .unwrap();
        let r = e.estimate().unwrap();
        let eig = SymmetricEigen::new(r).eigenvalues;
        assert!(eig.min() >= 1e-4 * (1.0 - 1e-9));
        assert!((eig.max() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn invalid_options_are_errors() {
        let bad = ResidualCovarianceOptions {
            min_samples: 65,
            ..Default::default()
        };
        assert!(ResidualCovarianceEstimator::new(bad).is_err());
        let bad = ResidualCovarianceOptions {
            window: 0,
            min_samples: 0,
            ..Default::default()
        };
        assert!(ResidualCovarianceEstimator::new(bad).is_err());
    }
}
