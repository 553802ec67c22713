//! Ding, Wang and Rizos' process-noise scaling in the engine (2007, J. Navig. 60:517,
//! section 2.2): α of eq. (19) from the innovations of a window of m epochs, and
//! Q̂ = Q √α, eq. (22), applied to the process noise of every following IMU step.
//!
//! Choice (when the rule is applied): once per full window, after which the window is
//! cleared, and the new scale multiplies the previous one (Q_{k−1} of eq. (22) is the Q in
//! use). Fed back at every epoch over a sliding window the loop winds up, because the
//! window still holds innovations produced by the old Q (measured on a scalar random walk
//! in tests/iarf_math.rs); once per window it settles near the Q that makes the predicted
//! innovation covariance match the observed one. The accumulated scale is kept within
//! `robust.q_scale_min`..`robust.q_scale_max`, one step's α within
//! `robust.q_alpha_min`..`robust.q_alpha_max`.

use nalgebra::{DMatrix, DVector};

use crate::adaptive::q_scaling::{ProcessNoiseScaler, ProcessNoiseScalingOptions};
use crate::config::Config;

/// The scale of Q and the window that updates it.
#[derive(Debug, Clone)]
pub struct QScaling {
    /// None when `filter.q_scaling` is off.
    scaler: Option<ProcessNoiseScaler>,
    window: usize,
    scale: f64,
    last_alpha: f64,
    scale_min: f64,
    scale_max: f64,
}

impl QScaling {
    /// Q scaling as configured (inactive when `filter.q_scaling` is false).
    pub fn new(config: &Config) -> Self {
        let r = &config.robust;
        let scaler = if config.filter.q_scaling {
            ProcessNoiseScaler::new(ProcessNoiseScalingOptions {
                window: r.q_window_epochs,
                min_samples: r.q_window_epochs,
                alpha_min: r.q_alpha_min,
                alpha_max: r.q_alpha_max,
            })
            .ok()
        } else {
            None
        };
        Self {
            scaler,
            window: r.q_window_epochs,
            scale: 1.0,
            last_alpha: f64::NAN,
            scale_min: r.q_scale_min,
            scale_max: r.q_scale_max,
        }
    }

    /// True when Q scaling runs.
    pub fn is_active(&self) -> bool {
        self.scaler.is_some()
    }

    /// The factor on the configured Q in use (1 when inactive).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The last α of eq. (19) applied (NaN before the first full window).
    pub fn last_alpha(&self) -> f64 {
        self.last_alpha
    }

    /// Adds one epoch: innovation (m), the R used (m × m) and H P⁻ Hᵀ (m × m). When the
    /// window is full, α is applied to the scale and the window restarts.
    pub fn push(&mut self, innovation: &DVector<f64>, r: &DMatrix<f64>, hph: &DMatrix<f64>) {
        let Some(scaler) = self.scaler.as_mut() else {
            return;
        };
        if scaler.push(innovation, r, hph).is_err() {
            // A malformed epoch (non-finite or negative trace) teaches nothing.
            return;
        }
        if scaler.len() < self.window {
            return;
        }
        if let Some(factor) = scaler.scaling_factor() {
            self.last_alpha = factor.alpha;
            self.scale = (self.scale * factor.alpha.sqrt()).clamp(self.scale_min, self.scale_max);
        }
        scaler.reset();
    }

    /// Back to the configured Q with an empty window (after a filter reset).
    pub fn reset(&mut self) {
        if let Some(s) = self.scaler.as_mut() {
            s.reset();
        }
        self.scale = 1.0;
        self.last_alpha = f64::NAN;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_moves_once_per_full_window_by_the_root_of_alpha() {
        let mut config = Config::default();
        config.filter.q_scaling = true;
        config.robust.q_window_epochs = 5;
        let mut q = QScaling::new(&config);
        assert!(q.is_active());
        let r = DMatrix::from_element(1, 1, 1.0);
        let hph = DMatrix::from_element(1, 1, 2.0);
        // d² = 9: α = (9 − 1) / 2 = 4 per epoch, so √α = 2 after the fifth epoch only.
        for i in 0..4 {
            q.push(&DVector::from_element(1, 3.0), &r, &hph);
            assert_eq!(q.scale(), 1.0, "epoch {i}");
        }
        q.push(&DVector::from_element(1, 3.0), &r, &hph);
        assert!((q.scale() - 2.0).abs() < 1e-15);
        assert!((q.last_alpha() - 4.0).abs() < 1e-15);
        q.reset();
        assert_eq!(q.scale(), 1.0);
        assert!(!QScaling::new(&Config::default()).is_active());
    }
}
