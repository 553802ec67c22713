//! Burg's recursion for autoregressive (AR) modelling of a real sequence (ERMAKF paper,
//! section 3.3, eqs. 25–28) and AR order selection by Akaike's criterion (the paper's) or
//! Schwarz's (an option: AIC cannot pick the true order reliably, see [`OrderCriterion`]).
//!
//! Sign conventions (the paper mixes two):
//! - Eqs. (25)–(27) build the *prediction-error filter* e_n = x_n + Σ_{m=1}^{l} a_m^(l) x_{n−m}
//!   with reflection coefficient k_l = −2 Σ f_n b_{n−1} / Σ (f_n² + b_{n−1}²).
//! - Eq. (28) writes the AR model as x_n = Σ_{i=1}^{p} a_i x_{n−i} + v.
//!
//! This module returns the eq. (28) convention: [`ArModel::coefficients`] φ_i = −a_i^(p) of
//! eq. (27), and [`ArModel::reflection_coefficients`] κ_l = −k_l of eq. (26), which is the
//! partial autocorrelation at lag l (positive for positively correlated sequences). Both
//! match `statsmodels.regression.linear_model.burg` / `pacf_burg`.
//!
//! Math note (typo in eq. 27): the backward error update is b_n^(l) = b_{n−1}^(l−1) +
//! k_l f_n^(l−1) (forward error at n, not n−1); that is the update for which the k_l of
//! eq. (26) minimises the summed forward and backward error energy.
//!
//! Choice (demeaning): the functions here model the sequence *as given*, without
//! subtracting its mean, because the mutual difference ∇Z is zero-mean by construction
//! (eq. 15) and eq. (29) uses its raw second moment. A caller that wants a demeaned fit
//! subtracts the mean first; that equals statsmodels' `demean=True`.

use super::error::{check_finite, AdaptiveError};

/// An AR(p) model fitted by Burg's method, in the convention x_n = Σ φ_i x_{n−i} + v.
#[derive(Debug, Clone, PartialEq)]
pub struct ArModel {
    /// φ_1..φ_p (empty for p = 0).
    pub coefficients: Vec<f64>,
    /// κ_1..κ_p, the partial autocorrelations (κ_l = −k_l of eq. 26); |κ_l| ≤ 1.
    pub reflection_coefficients: Vec<f64>,
    /// Variance of the white innovation v: the mean of the forward and backward squared
    /// prediction errors of order p, (1/(2(N−p))) Σ_{n=p}^{N−1} (f_n² + b_n²); for p = 0
    /// it is the mean square (1/N) Σ x_n².
    pub innovation_variance: f64,
    /// Number of samples the model was fitted to.
    pub n_samples: usize,
}

impl ArModel {
    /// The model order p.
    pub fn order(&self) -> usize {
        self.coefficients.len()
    }
}

/// Reflection coefficients κ_1..κ_p and innovation variances σ²_0..σ²_p of every order up
/// to `order`, from one pass of Burg's recursion (orders are nested).
struct BurgPath {
    reflection: Vec<f64>,
    innovation_variance: Vec<f64>,
}

fn burg_path(x: &[f64], order: usize) -> Result<BurgPath, AdaptiveError> {
    const WHAT: &str = "Burg AR fit";
    let n = x.len();
    let needed = order + 2;
    if n < needed {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: n,
            needed,
        });
    }
    check_finite(WHAT, x)?;
    let energy: f64 = x.iter().map(|v| v * v).sum();
    if energy <= 0.0 {
        return Err(AdaptiveError::ZeroVariance { what: WHAT });
    }

    // Step 1, eq. (25): forward and backward errors of order 0 are the sequence itself.
    let mut forward = x.to_vec();
    let mut backward = x.to_vec();
    let mut reflection = Vec::with_capacity(order);
    let mut innovation_variance = Vec::with_capacity(order + 1);
    innovation_variance.push(energy / n as f64);

    for stage in 1..=order {
        // Step 2, eq. (26), over n = stage..N−1 (0-based): pairs f_n^(l−1), b_{n−1}^(l−1).
        let pairs = forward
            .iter()
            .skip(stage)
            .zip(backward.iter().skip(stage - 1));
        let (cross, power) =
            pairs.fold((0.0, 0.0), |(c, p), (f, b)| (c + f * b, p + f * f + b * b));
        if power <= 0.0 {
            // The lower-order model already predicts the sequence exactly.
            return Err(AdaptiveError::ZeroVariance {
                what: "Burg AR fit (prediction error vanished)",
            });
        }
        let k_paper = -2.0 * cross / power;

        // Step 3, eq. (27), typo corrected: going downwards, b[idx − 1] still holds
        // order l−1 when b[idx] is overwritten.
        for idx in (stage..n).rev() {
            let f_prev = forward[idx];
            let b_prev = backward[idx - 1];
            forward[idx] = f_prev + k_paper * b_prev;
            backward[idx] = b_prev + k_paper * f_prev;
        }

        // Math note: Σ (f^(l)² + b^(l)²) = (1 − k_l²) Σ (f^(l−1)² + b_{·−1}^(l−1)²) exactly
        // for Burg's k_l, so the order-l error variance follows without another pass.
        let sigma2 = (1.0 - k_paper * k_paper) * power / (2.0 * (n - stage) as f64);
        if sigma2 <= 0.0 {
            return Err(AdaptiveError::ZeroVariance {
                what: "Burg AR fit (prediction error vanished)",
            });
        }
        reflection.push(-k_paper);
        innovation_variance.push(sigma2);
    }
    Ok(BurgPath {
        reflection,
        innovation_variance,
    })
}

/// AR coefficients φ_1..φ_p (x_n = Σ φ_i x_{n−i} + v) from partial autocorrelations by the
/// Levinson–Durbin step of eq. (27): φ_m^(l) = φ_m^(l−1) − κ_l φ_{l−m}^(l−1), φ_l^(l) = κ_l.
fn coefficients_from_reflection(reflection: &[f64]) -> Vec<f64> {
    let mut phi: Vec<f64> = Vec::with_capacity(reflection.len());
    for &kappa in reflection {
        let updated: Vec<f64> = phi
            .iter()
            .zip(phi.iter().rev())
            .map(|(p_m, p_l_minus_m)| p_m - kappa * p_l_minus_m)
            .collect();
        phi = updated;
        phi.push(kappa);
    }
    phi
}

/// Fits an AR(`order`) model to `x` (as given, not demeaned) by Burg's recursion.
///
/// Errors: fewer than `order + 2` samples, a non-finite sample, an all-zero sequence, or a
/// sequence that a lower order already predicts exactly (zero prediction error).
pub fn burg(x: &[f64], order: usize) -> Result<ArModel, AdaptiveError> {
    let path = burg_path(x, order)?;
    let innovation_variance =
        path.innovation_variance
            .last()
            .copied()
            .ok_or(AdaptiveError::ZeroVariance {
                what: "Burg AR fit",
            })?;
    Ok(ArModel {
        coefficients: coefficients_from_reflection(&path.reflection),
        reflection_coefficients: path.reflection,
        innovation_variance,
        n_samples: x.len(),
    })
}

/// Akaike's information criterion of an AR(p) fit to N samples in the form used here:
/// AIC(p) = N ln σ²_p + 2p, with σ²_p the Burg innovation variance.
///
/// Choice: the estimated innovation variance itself is common to every order and left out
/// of the parameter count (adding 2 to every AIC(p) does not change the minimiser).
pub fn aic(n_samples: usize, innovation_variance: f64, order: usize) -> f64 {
    n_samples as f64 * innovation_variance.ln() + 2.0 * order as f64
}

/// Schwarz's Bayesian information criterion in the same form:
/// BIC(p) = N ln σ²_p + p ln N.
pub fn bic(n_samples: usize, innovation_variance: f64, order: usize) -> f64 {
    let n = n_samples as f64;
    n * innovation_variance.ln() + order as f64 * n.ln()
}

/// Criterion for choosing the AR order (parameter `adaptive.ar_order_criterion`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrderCriterion {
    /// Akaike's criterion [`aic`], as in the ERMAKF paper. Not consistent: it picks a
    /// too-high order with a probability that does not vanish as N grows (about 16 % with
    /// one spare order, about 29 % with many; Shibata 1976).
    #[default]
    Aic,
    /// Schwarz's criterion [`bic`]: consistent (the right order with probability → 1).
    Bic,
}

impl OrderCriterion {
    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Aic => "aic",
            Self::Bic => "bic",
        }
    }
}

/// Fits Burg AR models of every order p ∈ 0..=`max_order` to `x` (as given, not demeaned)
/// and returns the one minimising `criterion`; on a tie the lower order wins.
///
/// Errors as [`burg`] with `order = max_order`: at least `max_order + 2` samples are needed.
pub fn select_order(
    x: &[f64],
    max_order: usize,
    criterion: OrderCriterion,
) -> Result<ArModel, AdaptiveError> {
    let path = burg_path(x, max_order)?;
    let n = x.len();
    let score = |sigma2: f64, order: usize| match criterion {
        OrderCriterion::Aic => aic(n, sigma2, order),
        OrderCriterion::Bic => bic(n, sigma2, order),
    };
    let mut best_order = 0;
    let mut best_score = f64::INFINITY;
    for (order, &sigma2) in path.innovation_variance.iter().enumerate() {
        let value = score(sigma2, order);
        if value < best_score {
            best_score = value;
            best_order = order;
        }
    }
    let reflection: Vec<f64> = path.reflection.iter().take(best_order).copied().collect();
    let innovation_variance =
        path.innovation_variance
            .get(best_order)
            .copied()
            .ok_or(AdaptiveError::ZeroVariance {
                what: "Burg AR fit",
            })?;
    Ok(ArModel {
        coefficients: coefficients_from_reflection(&reflection),
        reflection_coefficients: reflection,
        innovation_variance,
        n_samples: n,
    })
}

/// [`select_order`] with Akaike's criterion AIC(p) = N ln σ²_p + 2p (the paper's choice).
pub fn select_order_aic(x: &[f64], max_order: usize) -> Result<ArModel, AdaptiveError> {
    select_order(x, max_order, OrderCriterion::Aic)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn too_few_samples_is_a_typed_error() {
        let err = burg(&[1.0, 2.0, 3.0], 2).unwrap_err();
        assert_eq!(
            err,
            AdaptiveError::NotEnoughSamples {
                what: "Burg AR fit",
                got: 3,
                needed: 4
            }
        );
    }

    #[test]
    fn zero_sequence_is_a_typed_error() {
        assert!(matches!(
            burg(&[0.0; 10], 1),
            Err(AdaptiveError::ZeroVariance { .. })
        ));
    }

    #[test]
    fn nan_is_a_typed_error() {
        assert!(matches!(
            select_order_aic(&[1.0, f64::NAN, 0.5, 0.2], 1),
            Err(AdaptiveError::NonFinite { index: 1, .. })
        ));
    }

    #[test]
    fn order_zero_is_the_mean_square() {
        let model = burg(&[1.0, -2.0, 3.0], 0).unwrap();
        assert_eq!(model.order(), 0);
        assert!((model.innovation_variance - 14.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn order_one_matches_the_closed_form() {
        // κ_1 = 2 Σ x_n x_{n−1} / Σ (x_n² + x_{n−1}²) over n = 1..N−1.
        let x = [0.3, -1.2, 0.8, 2.0, -0.4];
        let cross: f64 = x.windows(2).map(|w| w[0] * w[1]).sum();
        let power: f64 = x.windows(2).map(|w| w[0] * w[0] + w[1] * w[1]).sum();
        let kappa = 2.0 * cross / power;
        let model = burg(&x, 1).unwrap();
        assert!((model.coefficients[0] - kappa).abs() < 1e-14);
        assert!((model.reflection_coefficients[0] - kappa).abs() < 1e-14);
        let sigma2 = (1.0 - kappa * kappa) * power / (2.0 * 4.0);
        assert!((model.innovation_variance - sigma2).abs() < 1e-14);
    }

    #[test]
    fn levinson_step_matches_hand_expansion() {
        // Order 2: φ_1 = κ_1 − κ_2 κ_1, φ_2 = κ_2.
        let phi = coefficients_from_reflection(&[0.5, -0.3]);
        assert!((phi[0] - (0.5 + 0.3 * 0.5)).abs() < 1e-15);
        assert!((phi[1] + 0.3).abs() < 1e-15);
    }
}
