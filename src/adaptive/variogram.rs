//! The variance of a time-correlated error from its differences over several lags: the
//! correlation-aware option of the redundant-measurement estimator ([`super::redundant`]).
//!
//! The redundant estimator sees the one-epoch differences ∇Z(t) ≈ v(t) − v(t−1) of the
//! GNSS error v (eq. 14). For a stationary error, E[(v(t) − v(t−k))²] = 2σ²(1 − ρ_k): one
//! lag keeps only 1 − ρ₁ of the variance, so an error correlated over seconds (code
//! multipath, ρ₁ ≈ 0.8–0.95) looks small. The sum of k consecutive ∇Z is the lag-k
//! difference v(t) − v(t−k); their mean squares, halved, are the empirical semivariogram
//! γ̂(k), k = 1 … K. It is fitted with the model of a white error plus a first-order
//! Gauss-Markov (AR(1)) one,
//!
//! γ(k) = σ_w² + σ_m² (1 − φ^k),
//!
//! whose parameters the lags identify together: σ_w² (white), σ_m² (correlated) and φ (its
//! correlation per epoch). The variance returned is the sill σ_w² + σ_m², the whole
//! variance of v, slow part included; γ̂(1) is the paper's estimate (eq. 18).
//!
//! Choices:
//! - The fit is weighted least squares with Cressie's weights N_k / γ̂(k)² (N_k the number
//!   of lag-k differences in the window): every lag counts by its relative error.
//! - φ is found on a grid of correlation times τ = −1/ln φ (log-spaced, from a fifth of an
//!   epoch to `max_lag` epochs, and φ = 0); for each, σ_w² and σ_m² are the non-negative
//!   least-squares solution, which is closed-form for two unknowns. The best grid point
//!   wins; a tie keeps the shorter correlation time. A correlation time beyond the
//!   longest lag is not identified (the variogram is then a straight line whose sill
//!   could be anything): at τ = K the extrapolation from γ̂(K) to the sill is at most
//!   1/(1 − e⁻¹) ≈ 1.6, a bounded, conservative step.
//! - The lags used are at most a third of the window (K ≤ n/3), so the longest lag still
//!   has two thirds of the window's pairs.

use super::error::{check_finite, AdaptiveError};

/// Correlation-time grid points (excluding φ = 0).
const GRID_POINTS: usize = 48;
/// Shortest correlation time of the grid (epochs).
const TAU_MIN_EPOCHS: f64 = 0.2;

/// The fitted model of a window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VariogramFit {
    /// σ_w², the white part's variance (unit of the samples, squared).
    pub white_variance: f64,
    /// σ_m², the correlated part's variance.
    pub correlated_variance: f64,
    /// φ, the correlated part's correlation from one epoch to the next, in [0, 1).
    pub correlation_per_epoch: f64,
    /// The longest lag fitted (epochs).
    pub lags: usize,
}

impl VariogramFit {
    /// The sill σ_w² + σ_m²: the whole variance of the error.
    pub fn variance(&self) -> f64 {
        self.white_variance + self.correlated_variance
    }

    /// ρ₁ of the error, σ_m² φ / (σ_w² + σ_m²) (0 when it has no variance).
    pub fn lag1_correlation(&self) -> f64 {
        let total = self.variance();
        if total > 0.0 {
            self.correlated_variance * self.correlation_per_epoch / total
        } else {
            0.0
        }
    }
}

/// The empirical semivariogram γ̂(1) … γ̂(K) of the error whose one-epoch differences are
/// `increments`, with the number of differences of each lag.
fn semivariogram(increments: &[f64], lags: usize) -> Vec<(f64, usize)> {
    let mut cumulative = Vec::with_capacity(increments.len() + 1);
    cumulative.push(0.0);
    let mut sum = 0.0;
    for x in increments {
        sum += x;
        cumulative.push(sum);
    }
    (1..=lags)
        .map(|k| {
            let pairs = cumulative.len() - k;
            let square: f64 = cumulative
                .iter()
                .skip(k)
                .zip(&cumulative)
                .map(|(later, earlier)| (later - earlier).powi(2))
                .sum();
            (square / pairs as f64 / 2.0, pairs)
        })
        .collect()
}

/// Fits the white + AR(1) variogram to the window whose consecutive one-epoch differences
/// are `increments` (oldest first, contiguous), with lags up to `max_lag` (and a third of
/// the window).
///
/// Errors: fewer than 3 increments, a non-finite one, or `max_lag` 0.
pub fn fit_variogram(increments: &[f64], max_lag: usize) -> Result<VariogramFit, AdaptiveError> {
    const WHAT: &str = "variogram fit";
    if increments.len() < 3 {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: increments.len(),
            needed: 3,
        });
    }
    if max_lag == 0 {
        return Err(AdaptiveError::InvalidParameter {
            name: "max_lag",
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    check_finite(WHAT, increments)?;
    let lags = max_lag.min(increments.len() / 3).max(1);
    let gamma = semivariogram(increments, lags);
    if gamma.iter().all(|(g, _)| *g <= 0.0) || lags == 1 {
        return Ok(VariogramFit {
            white_variance: gamma[0].0,
            correlated_variance: 0.0,
            correlation_per_epoch: 0.0,
            lags,
        });
    }
    let weights: Vec<f64> = gamma
        .iter()
        .map(|&(g, n)| if g > 0.0 { n as f64 / (g * g) } else { 0.0 })
        .collect();
    let tau_max = lags as f64;
    let ratio = (tau_max / TAU_MIN_EPOCHS).powf(1.0 / (GRID_POINTS - 1) as f64);
    let grid = std::iter::once(0.0)
        .chain((0..GRID_POINTS).map(|i| (-1.0 / (TAU_MIN_EPOCHS * ratio.powi(i as i32))).exp()));
    let mut best: Option<(f64, VariogramFit)> = None;
    for phi in grid {
        let (white, correlated, cost) = fit_at(&gamma, &weights, phi);
        if best.as_ref().is_none_or(|(c, _)| cost < *c) {
            best = Some((
                cost,
                VariogramFit {
                    white_variance: white,
                    correlated_variance: correlated,
                    correlation_per_epoch: phi,
                    lags,
                },
            ));
        }
    }
    best.map(|(_, fit)| fit)
        .ok_or(AdaptiveError::ZeroVariance { what: WHAT })
}

/// The non-negative weighted least-squares (σ_w², σ_m²) of γ(k) = σ_w² + σ_m²(1 − φ^k) and
/// its weighted squared residual.
fn fit_at(gamma: &[(f64, usize)], weights: &[f64], phi: f64) -> (f64, f64, f64) {
    let basis: Vec<f64> = (1..=gamma.len() as i32)
        .map(|k| 1.0 - phi.powi(k))
        .collect();
    let (mut s11, mut s12, mut s22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for ((&(g, _), &w), &b) in gamma.iter().zip(weights).zip(&basis) {
        s11 += w;
        s12 += w * b;
        s22 += w * b * b;
        r1 += w * g;
        r2 += w * g * b;
    }
    let cost = |a: f64, c: f64| -> f64 {
        gamma
            .iter()
            .zip(weights)
            .zip(&basis)
            .map(|((&(g, _), &w), &b)| w * (g - a - c * b).powi(2))
            .sum()
    };
    let det = s11 * s22 - s12 * s12;
    if det > 1e-12 * s11 * s22 {
        let a = (r1 * s22 - r2 * s12) / det;
        let c = (s11 * r2 - s12 * r1) / det;
        if a >= 0.0 && c >= 0.0 {
            return (a, c, cost(a, c));
        }
    }
    // A bound is active (or the two columns are parallel): the better one-parameter fit.
    let white_only = if s11 > 0.0 { r1 / s11 } else { 0.0 }.max(0.0);
    let correlated_only = if s22 > 0.0 { r2 / s22 } else { 0.0 }.max(0.0);
    let (cost_white, cost_correlated) = (cost(white_only, 0.0), cost(0.0, correlated_only));
    if cost_white <= cost_correlated {
        (white_only, 0.0, cost_white)
    } else {
        (0.0, correlated_only, cost_correlated)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// One-epoch differences of white (σ_w) plus AR(1) (σ_m, φ) noise, n + 1 values.
    fn increments(n: usize, sigma_w: f64, sigma_m: f64, phi: f64, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let drive = sigma_m * (1.0 - phi * phi).sqrt();
        let mut m = sigma_m * normal();
        let mut previous = m + sigma_w * normal();
        (0..n)
            .map(|_| {
                m = phi * m + drive * normal();
                let v = m + sigma_w * normal();
                let d = v - previous;
                previous = v;
                d
            })
            .collect()
    }

    #[test]
    fn white_noise_gives_the_papers_estimate() {
        let x = increments(3000, 1.0, 0.0, 0.0, 1);
        let fit = fit_variogram(&x, 20).unwrap();
        assert!((fit.variance() - 1.0).abs() < 0.1, "{fit:?}");
        assert!(fit.lag1_correlation() < 0.1, "{fit:?}");
    }

    #[test]
    fn correlated_noise_is_found_whole() {
        // σ 3 m at ρ₁ = 0.9 beside 1 m white: the one-lag mean square sees about a third.
        let x = increments(3000, 1.0, 3.0, 0.9, 2);
        let one_lag = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64 / 2.0;
        let fit = fit_variogram(&x, 30).unwrap();
        let truth = 10.0;
        assert!(one_lag < 0.35 * truth, "{one_lag}");
        assert!(
            (fit.variance() / truth - 1.0).abs() < 0.2,
            "{fit:?} against {truth}"
        );
        assert!((fit.correlation_per_epoch - 0.9).abs() < 0.05, "{fit:?}");
    }

    #[test]
    fn a_window_of_a_hundred_epochs_is_within_a_fifth_on_average() {
        // The estimator's default window: the median over independent windows.
        let mut ratios: Vec<f64> = (0..200)
            .map(|seed| {
                let x = increments(100, 1.0, 3.0, 0.9, 100 + seed);
                fit_variogram(&x, 20).unwrap().variance().sqrt() / 10f64.sqrt()
            })
            .collect();
        ratios.sort_by(f64::total_cmp);
        let median = ratios[ratios.len() / 2];
        assert!((median - 1.0).abs() < 0.2, "median σ ratio {median}");
    }

    #[test]
    fn degenerate_input_is_an_error_or_zero() {
        assert!(fit_variogram(&[1.0, 2.0], 5).is_err());
        assert!(fit_variogram(&[1.0, f64::NAN, 2.0, 1.0], 5).is_err());
        assert!(fit_variogram(&[1.0; 9], 0).is_err());
        let zero = fit_variogram(&[0.0; 30], 5).unwrap();
        assert_eq!(zero.variance(), 0.0);
    }
}
