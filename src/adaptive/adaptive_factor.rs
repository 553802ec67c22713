//! The adaptive factor α of the IARF paper (Jiang & Zhang 2018, Sensors 18:695), section
//! 2.2, eqs. (9)–(10), and the adaptive gain of section 2.1, eqs. (14)–(16) / (18)–(19),
//! in which the predicted covariance P⁻ is inflated to P⁻/α.

use super::math_error::{check_matrix, check_option, AdaptiveMathError};
use crate::linalg::{symmetrize, Factorization, SpdFactor};
use nalgebra::{DMatrix, DVector};

/// The adaptive-factor function of the statistic ΔV̄ (dimensionless in, dimensionless out).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AdaptiveFactorFunction {
    /// Eq. (9): α = 1 for |ΔV̄| ≤ c, c/|ΔV̄| above. The paper gives 1.0 ≤ c ≤ 1.5 and uses
    /// c = 1.0 in all its experiments (section 5, schemes 2–4).
    TwoSegment {
        /// Threshold c (dimensionless).
        c: f64,
    },
    /// Eq. (10): α = 1 for |ΔV̄| ≤ c0, (c0/|ΔV̄|)·((c1 − |ΔV̄|)/(c1 − c0))² between,
    /// 0 above c1. The paper gives 1.0 ≤ c0 ≤ 1.5 and 3.0 ≤ c1 ≤ 8.5.
    ThreeSegment {
        /// Lower threshold c0 (dimensionless).
        c0: f64,
        /// Upper threshold c1 (dimensionless), c1 > c0.
        c1: f64,
    },
}

impl AdaptiveFactorFunction {
    /// The paper's two-segment function with its experimental c = 1.0.
    pub const PAPER_TWO_SEGMENT: Self = Self::TwoSegment { c: 1.0 };
    /// The three-segment function with c0 = 1.0, c1 = 3.0. Choice: the paper gives only the
    /// ranges 1.0–1.5 and 3.0–8.5; c0 = 1.0 matches the experimental c of eq. (9), and
    /// c1 = 3.0 is the usual three-sigma rejection bound.
    pub const PAPER_THREE_SEGMENT: Self = Self::ThreeSegment { c0: 1.0, c1: 3.0 };

    /// Checks the thresholds are finite, positive and ordered.
    pub fn validate(&self) -> Result<(), AdaptiveMathError> {
        match *self {
            Self::TwoSegment { c } => check_option("c", c, c > 0.0, "must be > 0"),
            Self::ThreeSegment { c0, c1 } => {
                check_option("c0", c0, c0 > 0.0, "must be > 0")?;
                check_option("c1", c1, c1 > c0, "must be > c0")
            }
        }
    }

    /// The unfloored factor α(ΔV̄) in [0, 1]; a non-finite statistic gives NaN.
    pub fn evaluate(&self, statistic: f64) -> f64 {
        let s = statistic.abs();
        match *self {
            Self::TwoSegment { c } => {
                if s <= c {
                    1.0
                } else {
                    c / s
                }
            }
            Self::ThreeSegment { c0, c1 } => {
                if s <= c0 {
                    1.0
                } else if s <= c1 {
                    let t = (c1 - s) / (c1 - c0);
                    c0 / s * t * t
                } else {
                    0.0
                }
            }
        }
    }
}

/// Options of the IARF adaptive factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveFactorOptions {
    /// Which function maps ΔV̄ to α. Default: [`AdaptiveFactorFunction::PAPER_TWO_SEGMENT`].
    pub function: AdaptiveFactorFunction,
    /// Lower bound α_min on α (dimensionless, 0 < α_min ≤ 1). Default 0.01.
    ///
    /// Choice: the paper lets α reach 0 (eq. (10) above c1), which in eq. (14) means an
    /// infinite P⁻: the update becomes a single-epoch least-squares fix, undefined for a
    /// 20-state error vector observed by a few pseudo-ranges. α_min = 0.01 inflates the
    /// predicted standard deviations at most 10×, already letting the measurements dominate,
    /// while keeping P⁻/α finite and well conditioned.
    pub alpha_floor: f64,
}

impl Default for AdaptiveFactorOptions {
    fn default() -> Self {
        Self {
            function: AdaptiveFactorFunction::PAPER_TWO_SEGMENT,
            alpha_floor: 0.01,
        }
    }
}

impl AdaptiveFactorOptions {
    /// Checks the function's thresholds and the floor.
    pub fn validate(&self) -> Result<(), AdaptiveMathError> {
        self.function.validate()?;
        check_option(
            "alpha_floor",
            self.alpha_floor,
            self.alpha_floor > 0.0 && self.alpha_floor <= 1.0,
            "must be in (0, 1]",
        )
    }

    /// α = max(α(ΔV̄), α_min), in [α_min, 1].
    pub fn adaptive_factor(&self, statistic: f64) -> Result<f64, AdaptiveMathError> {
        if !statistic.is_finite() {
            return Err(AdaptiveMathError::NotFinite {
                what: "adaptive-factor statistic",
            });
        }
        Ok(self.function.evaluate(statistic).max(self.alpha_floor))
    }
}

/// P⁻/α, symmetrised. Math note: a positive scalar multiple of a symmetric positive-definite
/// matrix stays so; symmetrising removes the rounding asymmetry the caller's P⁻ may carry.
pub fn inflate_prior_covariance(
    prior_covariance: &DMatrix<f64>,
    alpha: f64,
) -> Result<DMatrix<f64>, AdaptiveMathError> {
    if !(alpha.is_finite() && alpha > 0.0) {
        return Err(AdaptiveMathError::NotPositive {
            what: "adaptive factor",
            value: alpha,
        });
    }
    let n = prior_covariance.nrows();
    check_matrix("prior covariance", prior_covariance, n, n)?;
    Ok(symmetrize(prior_covariance) / alpha)
}

/// Result of the adaptive (-robust) linear measurement update.
#[derive(Debug, Clone)]
pub struct AdaptiveUpdate {
    /// Equivalent gain K̄ = (P⁻/α) Hᵀ (H (P⁻/α) Hᵀ + R̄)⁻¹, eq. (19) (n×r).
    pub gain: DMatrix<f64>,
    /// Innovation covariance S̄ = H (P⁻/α) Hᵀ + R̄ (r×r), symmetrised.
    pub innovation_covariance: DMatrix<f64>,
    /// Posterior covariance (n×n), Joseph form on the inflated prior, symmetrised.
    pub posterior_covariance: DMatrix<f64>,
    /// State correction K̄ ν for the innovation ν = z − H x⁻ (n).
    pub correction: DVector<f64>,
    /// How S̄ was factored.
    pub factorization: Factorization,
}

/// The adaptively-robust measurement update of eqs. (17)–(19) for a linear(ised) H.
///
/// `innovation` is ν = z − H x⁻ (r), `prior_covariance` P⁻ (n×n), `h` (r×n),
/// `equivalent_covariance` R̄ (r×r; the nominal R when no robust step is applied),
/// `alpha` the adaptive factor (> 0).
///
/// Choice: the posterior is the Joseph form (I − K̄H)(P⁻/α)(I − K̄H)ᵀ + K̄R̄K̄ᵀ. The paper's
/// eq. (16), P = P⁻ − K̄HP⁻, keeps the *uninflated* P⁻; the adaptive filter it cites
/// (Yang et al. 2001, its ref. \[14\]) uses (I − K̄H)P⁻/α, the covariance of the estimate
/// the gain actually produces when the prior covariance is P⁻/α. With α = 1 both coincide.
pub fn adaptive_update(
    innovation: &DVector<f64>,
    prior_covariance: &DMatrix<f64>,
    h: &DMatrix<f64>,
    equivalent_covariance: &DMatrix<f64>,
    alpha: f64,
) -> Result<AdaptiveUpdate, AdaptiveMathError> {
    let n = prior_covariance.nrows();
    let r = innovation.len();
    if r == 0 {
        return Err(AdaptiveMathError::Empty { what: "innovation" });
    }
    if innovation.iter().any(|v| !v.is_finite()) {
        return Err(AdaptiveMathError::NotFinite { what: "innovation" });
    }
    check_matrix("measurement matrix H", h, r, n)?;
    check_matrix(
        "equivalent measurement covariance",
        equivalent_covariance,
        r,
        r,
    )?;
    let p_bar = inflate_prior_covariance(prior_covariance, alpha)?;
    let ph_t = &p_bar * h.transpose();
    let s = symmetrize(&(h * &ph_t + equivalent_covariance));
    let factor = SpdFactor::new("innovation covariance", &s)?;
    // K̄ = P̄Hᵀ S̄⁻¹ = (S̄⁻¹ H P̄)ᵀ since S̄ and P̄ are symmetric.
    let gain = factor.solve(&ph_t.transpose()).transpose();
    let i_kh = DMatrix::identity(n, n) - &gain * h;
    let posterior = symmetrize(
        &(&i_kh * &p_bar * i_kh.transpose()
            + &gain * symmetrize(equivalent_covariance) * gain.transpose()),
    );
    Ok(AdaptiveUpdate {
        correction: &gain * innovation,
        gain,
        innovation_covariance: s,
        posterior_covariance: posterior,
        factorization: factor.method(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_options_are_valid_and_paper_values() {
        let o = AdaptiveFactorOptions::default();
        o.validate().unwrap();
        assert_eq!(o.function, AdaptiveFactorFunction::TwoSegment { c: 1.0 });
        assert!(AdaptiveFactorOptions {
            function: AdaptiveFactorFunction::ThreeSegment { c0: 2.0, c1: 1.0 },
            alpha_floor: 0.1
        }
        .validate()
        .is_err());
        assert!(AdaptiveFactorOptions {
            alpha_floor: 0.0,
            ..o
        }
        .validate()
        .is_err());
    }

    #[test]
    fn update_with_alpha_one_is_the_kalman_update() {
        let p = DMatrix::from_row_slice(2, 2, &[2.0, 0.3, 0.3, 1.0]);
        let h = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
        let r = DMatrix::from_element(1, 1, 0.5);
        let nu = DVector::from_element(1, 1.0);
        let u = adaptive_update(&nu, &p, &h, &r, 1.0).unwrap();
        let s = 2.0 + 1.0 + 0.6 + 0.5;
        let k = DVector::from_vec(vec![2.3 / s, 1.3 / s]);
        assert!((&u.correction - &k).amax() < 1e-15);
        let expected = &p - &k * k.transpose() * s;
        assert!((&u.posterior_covariance - expected).amax() < 1e-14);
    }

    #[test]
    fn small_alpha_trusts_the_measurement_more() {
        // Scalar: P = 1, R = 1, α = 0.1: K̄ = 10/11, posterior (1 − K̄)·10 = 10/11.
        let p = DMatrix::from_element(1, 1, 1.0);
        let h = DMatrix::from_element(1, 1, 1.0);
        let r = DMatrix::from_element(1, 1, 1.0);
        let nu = DVector::from_element(1, 1.0);
        let u = adaptive_update(&nu, &p, &h, &r, 0.1).unwrap();
        assert!((u.gain[(0, 0)] - 10.0 / 11.0).abs() < 1e-15);
        assert!((u.posterior_covariance[(0, 0)] - 10.0 / 11.0).abs() < 1e-14);
        assert!(adaptive_update(&nu, &p, &h, &r, 0.0).is_err());
    }
}
