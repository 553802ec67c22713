//! A stationary autoregressive process AR(p) with a given steady-state σ, for the
//! time-correlated multipath errors of the simulator:
//!
//! x_k = φ_1 x_{k−1} + … + φ_p x_{k−p} + σ_w ξ_k,  ξ_k ~ N(0, 1).
//!
//! Math note: the step-down (reverse Levinson-Durbin) recursion turns φ into the
//! reflection coefficients k_1 … k_p and the lower-order predictors φ^(j); the process is
//! stationary exactly when every |k_j| < 1, and its variance is then
//! γ_0 = σ_w² / Π (1 − k_j²). Starting the process with the innovations form
//! x_1 = √v_0 ξ, x_{j+1} = Σ_i φ^(j)_i x_{j+1−i} + √v_j ξ with v_j = γ_0 Π_{i≤j}(1 − k_i²)
//! draws the first p values from the exact stationary joint distribution, so there is no
//! start-up transient.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use thiserror::Error;

/// Largest accepted AR order. Choice: multipath models use orders 1–3; 8 leaves room while
/// keeping the per-step cost trivial.
pub const MAX_AR_ORDER: usize = 8;

/// Why AR coefficients were refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ArProcessError {
    /// No coefficient, or more than [`MAX_AR_ORDER`].
    #[error("AR order {order} outside 1..={max}")]
    InvalidOrder { order: usize, max: usize },
    /// A coefficient or the σ is not finite, or the σ is negative.
    #[error("non-finite AR coefficient or invalid σ {sigma}")]
    InvalidValue { sigma: f64 },
    /// The coefficients describe a non-stationary process (reflection coefficient |k| ≥ 1).
    #[error(
        "AR coefficients are not stationary: reflection coefficient {reflection} at order {order}"
    )]
    NotStationary { order: usize, reflection: f64 },
}

/// The validated model of a stationary AR(p) process: its coefficients, the innovation σ
/// that gives the requested steady-state σ, and the start-up predictors.
#[derive(Debug, Clone, PartialEq)]
pub struct ArModel {
    /// φ_1 … φ_p.
    coefficients: Vec<f64>,
    /// Steady-state σ of x.
    sigma: f64,
    /// Innovation σ_w.
    innovation_sigma: f64,
    /// φ^(j) for j = 0 … p−1 (φ^(0) empty), used by the stationary start.
    lower_order: Vec<Vec<f64>>,
    /// √v_j for j = 0 … p−1.
    start_sigmas: Vec<f64>,
}

impl ArModel {
    /// Validates `coefficients` (φ_1 … φ_p) and scales the innovations so that the
    /// steady-state σ of the process is `sigma` (0 gives a process that stays at zero).
    pub fn new(coefficients: &[f64], sigma: f64) -> Result<Self, ArProcessError> {
        let order = coefficients.len();
        if order == 0 || order > MAX_AR_ORDER {
            return Err(ArProcessError::InvalidOrder {
                order,
                max: MAX_AR_ORDER,
            });
        }
        if !(sigma.is_finite() && sigma >= 0.0 && coefficients.iter().all(|c| c.is_finite())) {
            return Err(ArProcessError::InvalidValue { sigma });
        }
        // Step-down recursion from φ^(p) = φ to φ^(0) = ().
        let mut predictors: Vec<Vec<f64>> = vec![coefficients.to_vec()];
        let mut reflections = vec![0.0; order];
        let mut current = coefficients.to_vec();
        for j in (1..=order).rev() {
            let k = current.last().copied().unwrap_or(0.0);
            if k.is_nan() || k.abs() >= 1.0 {
                return Err(ArProcessError::NotStationary {
                    order: j,
                    reflection: k,
                });
            }
            if let Some(slot) = reflections.get_mut(j - 1) {
                *slot = k;
            }
            let denom = 1.0 - k * k;
            let lower: Vec<f64> = (0..j - 1)
                .map(|i| (current[i] + k * current[j - 2 - i]) / denom)
                .collect();
            predictors.push(lower.clone());
            current = lower;
        }
        predictors.reverse(); // predictors[j] = φ^(j), j = 0 … p.
        predictors.truncate(order);
        let gain: f64 = reflections.iter().map(|k| 1.0 - k * k).product();
        let innovation_sigma = sigma * gain.sqrt();
        let mut start_sigmas = Vec::with_capacity(order);
        let mut v = sigma * sigma;
        for k in &reflections {
            start_sigmas.push(v.sqrt());
            v *= 1.0 - k * k;
        }
        Ok(Self {
            coefficients: coefficients.to_vec(),
            sigma,
            innovation_sigma,
            lower_order: predictors,
            start_sigmas,
        })
    }

    /// φ_1 … φ_p.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// Steady-state σ of the process.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// σ_w of the driving white noise.
    pub fn innovation_sigma(&self) -> f64 {
        self.innovation_sigma
    }

    /// A process started in its stationary distribution (its first value is drawn).
    pub fn start(&self, rng: &mut ChaCha8Rng) -> ArProcess {
        // history[0] is the newest value.
        let mut history: Vec<f64> = Vec::with_capacity(self.coefficients.len());
        for (predictor, start_sigma) in self.lower_order.iter().zip(&self.start_sigmas) {
            let mean: f64 = predictor.iter().zip(&history).map(|(a, x)| a * x).sum();
            let xi: f64 = StandardNormal.sample(rng);
            history.insert(0, mean + start_sigma * xi);
        }
        ArProcess { history }
    }

    /// Moves `process` one step on and returns its new value.
    pub fn step(&self, process: &mut ArProcess, rng: &mut ChaCha8Rng) -> f64 {
        let mean: f64 = self
            .coefficients
            .iter()
            .zip(&process.history)
            .map(|(a, x)| a * x)
            .sum();
        let xi: f64 = StandardNormal.sample(rng);
        let x = mean + self.innovation_sigma * xi;
        process.history.insert(0, x);
        process.history.truncate(self.coefficients.len());
        x
    }
}

/// The state of one AR process: its last p values, newest first.
#[derive(Debug, Clone, PartialEq)]
pub struct ArProcess {
    history: Vec<f64>,
}

impl ArProcess {
    /// The current (newest) value.
    pub fn value(&self) -> f64 {
        self.history.first().copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::rand_core::SeedableRng;

    #[test]
    fn ar1_and_ar2_variances_match_closed_forms() {
        // AR(1): γ0 = σw² / (1 − φ²).
        let m = ArModel::new(&[0.9], 2.0).unwrap();
        assert!((m.innovation_sigma() - 2.0 * (1.0f64 - 0.81).sqrt()).abs() < 1e-12);
        // AR(2): γ0 = σw² (1 − φ2) / ((1 + φ2)((1 − φ2)² − φ1²)).
        let (p1, p2) = (1.4, -0.49);
        let m = ArModel::new(&[p1, p2], 3.0).unwrap();
        let ratio = (1.0 - p2) / ((1.0 + p2) * ((1.0 - p2) * (1.0 - p2) - p1 * p1));
        let expect = 3.0 / ratio.sqrt();
        assert!((m.innovation_sigma() - expect).abs() < 1e-12);
    }

    #[test]
    fn non_stationary_and_bad_inputs_are_refused() {
        assert!(matches!(
            ArModel::new(&[1.0], 1.0),
            Err(ArProcessError::NotStationary { .. })
        ));
        // z² − 2.2 z + 1.21 = (z − 1.1)²: a double pole outside the unit circle.
        assert!(ArModel::new(&[2.2, -1.21], 1.0).is_err());
        assert!(ArModel::new(&[], 1.0).is_err());
        assert!(ArModel::new(&[0.5], -1.0).is_err());
        assert!(ArModel::new(&[f64::NAN], 1.0).is_err());
    }

    #[test]
    fn sample_variance_and_lag_one_correlation() {
        let (p1, p2) = (1.4, -0.49);
        let m = ArModel::new(&[p1, p2], 1.5).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // Many short independent runs: the stationary start and the recursion together.
        const BLOCKS: usize = 20_000;
        let mut sum2 = 0.0;
        let mut n = 0.0;
        let mut lag1 = 0.0;
        for _ in 0..BLOCKS {
            let mut p = m.start(&mut rng);
            let mut prev = p.value();
            sum2 += prev * prev;
            n += 1.0;
            for _ in 0..5 {
                let x = m.step(&mut p, &mut rng);
                sum2 += x * x;
                lag1 += x * prev;
                n += 1.0;
                prev = x;
            }
        }
        let var = sum2 / n;
        // ρ1 = φ1 / (1 − φ2).
        let rho1 = p1 / (1.0 - p2);
        let c1 = lag1 / (BLOCKS as f64 * 5.0) / 2.25;
        // Bounds: even if the values of a block were fully correlated, a block's mean of
        // x²/σ² has variance ≤ 2 and of x_k x_{k−1}/σ² ≤ E[x⁴]/σ⁴ = 3, so over 20 000
        // independent blocks the sd is ≤ 0.010 and ≤ 0.012: the bounds are 5 sd.
        assert!((var / 2.25 - 1.0).abs() < 0.05, "{var}");
        assert!((c1 - rho1).abs() < 0.06, "{c1} vs {rho1}");
    }
}
