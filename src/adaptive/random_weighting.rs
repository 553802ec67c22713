//! Random weighting of the windowed second moment, ERMAKF paper eq. (19).
//!
//! The weights are Dirichlet(1, …, 1): i.i.d. standard exponentials normalised by their sum.
//! They come from a seeded ChaCha8 generator so that a replay of the same data with the same
//! seed gives bit-identical estimates.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Exp1};

use super::error::{check_finite, AdaptiveError};

/// A reproducible source of Dirichlet(1, …, 1) weight vectors.
#[derive(Debug, Clone)]
pub struct DirichletWeights {
    rng: ChaCha8Rng,
}

impl DirichletWeights {
    /// A generator seeded with `seed`; the same seed gives the same sequence of weights.
    pub fn new(seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// Draws `m` weights w_1..w_m ≥ 0 with Σ w = 1, uniform on the simplex. `m = 0` gives an
    /// empty vector.
    pub fn draw(&mut self, m: usize) -> Vec<f64> {
        let mut weights: Vec<f64> = (0..m).map(|_| Exp1.sample(&mut self.rng)).collect();
        let total: f64 = weights.iter().sum();
        if total > 0.0 {
            weights.iter_mut().for_each(|w| *w /= total);
        } else {
            // Math note: the sum of m ≥ 1 exponentials is positive with probability one;
            // should every draw underflow to zero, equal weights are the uniform average.
            let equal = 1.0 / m.max(1) as f64;
            weights.iter_mut().for_each(|w| *w = equal);
        }
        weights
    }

    /// Draws fresh weights for `samples` and returns the random-weighted second moment
    /// Σ w_m x_m² of eq. (19) in one pass, without storing the weights: with
    /// w_m = e_m / Σ e (e_m the standard exponentials) it is Σ e_m x_m² / Σ e_m. It
    /// consumes the same draws as [`Self::draw`] and equals [`Self::draw`] followed by
    /// [`random_weighted_second_moment`] up to rounding (the estimator's hot path: one
    /// pass instead of three and no allocation).
    ///
    /// Errors: an empty window or a non-finite sample (no draws are consumed then).
    pub fn second_moment(&mut self, samples: &[f64]) -> Result<f64, AdaptiveError> {
        const WHAT: &str = "random-weighted second moment";
        if samples.is_empty() {
            return Err(AdaptiveError::NotEnoughSamples {
                what: WHAT,
                got: 0,
                needed: 1,
            });
        }
        check_finite(WHAT, samples)?;
        let (mut total, mut weighted) = (0.0, 0.0);
        for x in samples {
            let e: f64 = Exp1.sample(&mut self.rng);
            total += e;
            weighted += e * x * x;
        }
        Ok(if total > 0.0 {
            weighted / total
        } else {
            // Every draw underflowed (see `draw`): equal weights.
            samples.iter().map(|x| x * x).sum::<f64>() / samples.len() as f64
        })
    }
}

/// Random-weighted second moment Σ w_m x_m² of eq. (19).
///
/// Choice: eq. (19) as printed is (1/M) Σ w_m x_m² with Σ w_m = 1, which would be M times
/// smaller than the unweighted moment (1/M) Σ x_m² of eq. (18) it is meant to replace. With
/// weights summing to one, Σ w_m x_m² is the estimator whose expectation over the weights
/// equals eq. (18), so that is what is computed.
///
/// Errors: `samples` and `weights` of different lengths, an empty window, or non-finite
/// values.
pub fn random_weighted_second_moment(
    samples: &[f64],
    weights: &[f64],
) -> Result<f64, AdaptiveError> {
    const WHAT: &str = "random-weighted second moment";
    if samples.len() != weights.len() {
        return Err(AdaptiveError::LengthMismatch {
            what: WHAT,
            left: samples.len(),
            right: weights.len(),
        });
    }
    if samples.is_empty() {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: 0,
            needed: 1,
        });
    }
    check_finite(WHAT, samples)?;
    check_finite(WHAT, weights)?;
    Ok(samples.iter().zip(weights).map(|(x, w)| w * x * x).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_are_reproducible() {
        let mut a = DirichletWeights::new(7);
        let mut b = DirichletWeights::new(7);
        let wa = a.draw(100);
        assert_eq!(wa, b.draw(100));
        assert!((wa.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(wa.iter().all(|w| *w >= 0.0));
        assert_ne!(wa, a.draw(100));
    }

    #[test]
    fn dirichlet_marginal_moments() {
        // Each weight of Dirichlet(1,…,1) with m components has mean 1/m and variance
        // (m − 1)/(m²(m + 1)).
        let m = 5;
        let draws = 20_000;
        let mut gen = DirichletWeights::new(11);
        let firsts: Vec<f64> = (0..draws).map(|_| gen.draw(m)[0]).collect();
        let mean = firsts.iter().sum::<f64>() / draws as f64;
        let var = firsts.iter().map(|w| (w - mean).powi(2)).sum::<f64>() / (draws - 1) as f64;
        let m_f = m as f64;
        let var_expected = (m_f - 1.0) / (m_f * m_f * (m_f + 1.0));
        assert!((mean - 0.2).abs() < 0.005, "mean {mean}");
        assert!(
            (var / var_expected - 1.0).abs() < 0.05,
            "var {var} vs {var_expected}"
        );
    }

    #[test]
    fn one_pass_moment_equals_weights_then_moment() {
        let x: Vec<f64> = (0..100).map(|i| ((i * 29) % 17) as f64 - 8.0).collect();
        let mut a = DirichletWeights::new(5);
        let mut b = DirichletWeights::new(5);
        for _ in 0..20 {
            let two_pass = random_weighted_second_moment(&x, &a.draw(x.len())).unwrap();
            let one_pass = b.second_moment(&x).unwrap();
            assert!(
                (one_pass / two_pass - 1.0).abs() < 1e-13,
                "{one_pass} vs {two_pass}"
            );
        }
        assert!(b.second_moment(&[]).is_err());
        assert!(b.second_moment(&[1.0, f64::NAN]).is_err());
    }

    #[test]
    fn equal_weights_give_the_mean_square() {
        let x = [1.0, -2.0, 3.0, 0.5];
        let w = [0.25; 4];
        let m = random_weighted_second_moment(&x, &w).unwrap();
        assert!((m - (1.0 + 4.0 + 9.0 + 0.25) / 4.0).abs() < 1e-15);
    }

    #[test]
    fn length_mismatch_is_a_typed_error() {
        assert!(matches!(
            random_weighted_second_moment(&[1.0, 2.0], &[1.0]),
            Err(AdaptiveError::LengthMismatch { .. })
        ));
    }
}
