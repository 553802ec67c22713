//! Robust equivalent measurement covariance R̄ of the IARF paper (Jiang & Zhang 2018,
//! Sensors 18:695), section 3, eqs. (33)–(35): per-row variance inflation factors λ_ii
//! from the standardized predicted residuals, λ_ij = √(λ_ii λ_jj), R̄ = λ_ij ⊙ R
//! (element-wise); plus Yang's IGG-III equivalent-weight function as an alternative.
//!
//! Math note: λ_ij ⊙ R = D R D with D = diag(√λ_ii) — a congruence, so R̄ is symmetric
//! positive definite whenever R is and every λ_ii is finite and positive, and the
//! correlation coefficients of R are unchanged (the "bifactor" property).

use super::math_error::{check_matrix, check_option, check_vector, AdaptiveMathError};
use crate::linalg::{symmetrize, SpdFactor};
use nalgebra::{DMatrix, DVector};

/// The equivalent-weight function of a standardized residual |Ṽ| (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EquivalentWeightFunction {
    /// The paper's double factor, eq. (34): λ_ii = 1 for |Ṽ| ≤ c, |Ṽ|/c above
    /// (weight c/|Ṽ|, Huber-type). The paper gives 1.0 ≤ c ≤ 1.5.
    DoubleFactor {
        /// Threshold c (dimensionless).
        c: f64,
    },
    /// Yang's IGG-III: weight 1 for |Ṽ| ≤ k0, (k0/|Ṽ|)·((k1 − |Ṽ|)/(k1 − k0))² between,
    /// 0 (rejection) above k1. Usual ranges k0 ∈ [1.0, 1.5], k1 ∈ [2.5, 8.0].
    Igg3 {
        /// Lower threshold k0 (dimensionless).
        k0: f64,
        /// Upper (rejection) threshold k1 (dimensionless), k1 > k0.
        k1: f64,
    },
}

impl EquivalentWeightFunction {
    /// The paper's double factor with c = 1.5. Choice: the paper gives only 1.0 ≤ c ≤ 1.5;
    /// for Gaussian standardized residuals P(|Ṽ| > 1.0) = 32 % but P(|Ṽ| > 1.5) = 13 %, so
    /// the upper end inflates far fewer healthy measurements.
    pub const PAPER_DOUBLE_FACTOR: Self = Self::DoubleFactor { c: 1.5 };
    /// IGG-III with k0 = 1.5, k1 = 3.0, the values most used with Yang's scheme (the paper's
    /// three-segment adaptive factor, "similar to IGG-III", has the same break points).
    pub const YANG_IGG3: Self = Self::Igg3 { k0: 1.5, k1: 3.0 };

    /// Checks the thresholds are finite, positive and ordered.
    pub fn validate(&self) -> Result<(), AdaptiveMathError> {
        match *self {
            Self::DoubleFactor { c } => check_option("c", c, c > 0.0, "must be > 0"),
            Self::Igg3 { k0, k1 } => {
                check_option("k0", k0, k0 > 0.0, "must be > 0")?;
                check_option("k1", k1, k1 > k0, "must be > k0")
            }
        }
    }

    /// Equivalent-weight factor w(|Ṽ|) in [0, 1] (1 = full weight, 0 = rejected).
    pub fn weight_factor(&self, standardized_residual: f64) -> f64 {
        let s = standardized_residual.abs();
        match *self {
            Self::DoubleFactor { c } => {
                if s <= c {
                    1.0
                } else {
                    c / s
                }
            }
            Self::Igg3 { k0, k1 } => {
                if s <= k0 {
                    1.0
                } else if s <= k1 {
                    let t = (k1 - s) / (k1 - k0);
                    k0 / s * t * t
                } else {
                    0.0
                }
            }
        }
    }
}

/// Options of the robust equivalent covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquivalentWeightOptions {
    /// Which function. Default: [`EquivalentWeightFunction::PAPER_DOUBLE_FACTOR`].
    pub function: EquivalentWeightFunction,
    /// Largest variance inflation λ_ii (dimensionless, ≥ 1). Default 1e6.
    ///
    /// Choice: a zero weight (IGG-III above k1) would mean an infinite variance. Capping
    /// λ_ii at 1e6 (σ × 1000) removes the row's influence for any practical purpose while
    /// keeping R̄ finite, positive definite and the measurement dimension unchanged.
    pub max_variance_inflation: f64,
}

impl Default for EquivalentWeightOptions {
    fn default() -> Self {
        Self {
            function: EquivalentWeightFunction::PAPER_DOUBLE_FACTOR,
            max_variance_inflation: 1e6,
        }
    }
}

impl EquivalentWeightOptions {
    /// Checks the function and the cap.
    pub fn validate(&self) -> Result<(), AdaptiveMathError> {
        self.function.validate()?;
        check_option(
            "max_variance_inflation",
            self.max_variance_inflation,
            self.max_variance_inflation >= 1.0,
            "must be >= 1",
        )
    }

    /// λ_ii = 1 / max(w, 1/λ_max), in [1, λ_max].
    pub fn variance_inflation(&self, standardized_residual: f64) -> f64 {
        1.0 / self
            .function
            .weight_factor(standardized_residual)
            .max(1.0 / self.max_variance_inflation)
    }
}

/// The equivalent covariance and the per-row inflation factors that built it.
#[derive(Debug, Clone)]
pub struct EquivalentCovariance {
    /// R̄ = λ_ij ⊙ R (r×r), symmetric positive definite.
    pub covariance: DMatrix<f64>,
    /// λ_ii per row (r), each in [1, max_variance_inflation].
    pub inflation: DVector<f64>,
}

/// R̄ = λ_ij ⊙ R from the standardized predicted residuals Ṽ (see
/// [`super::predicted_residual::standardized_residuals`]) and the nominal R.
///
/// R must be symmetric positive definite (checked by factoring it); R̄ is returned
/// symmetrised.
pub fn equivalent_measurement_covariance(
    nominal_covariance: &DMatrix<f64>,
    standardized_residuals: &DVector<f64>,
    options: &EquivalentWeightOptions,
) -> Result<EquivalentCovariance, AdaptiveMathError> {
    options.validate()?;
    check_vector("standardized residuals", standardized_residuals)?;
    let r = standardized_residuals.len();
    check_matrix("nominal measurement covariance", nominal_covariance, r, r)?;
    SpdFactor::new("nominal measurement covariance", nominal_covariance)?;
    let inflation = standardized_residuals.map(|v| options.variance_inflation(v));
    let root = inflation.map(f64::sqrt);
    let nominal = symmetrize(nominal_covariance);
    let covariance = DMatrix::from_fn(r, r, |i, j| root[i] * nominal[(i, j)] * root[j]);
    Ok(EquivalentCovariance {
        covariance,
        inflation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_formula_on_a_hand_example() {
        let r = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 9.0]);
        let v = DVector::from_vec(vec![0.5, -3.0]);
        let e =
            equivalent_measurement_covariance(&r, &v, &EquivalentWeightOptions::default()).unwrap();
        // λ = (1, 3/1.5 = 2); λ_12 = √2.
        assert_eq!(e.inflation, DVector::from_vec(vec![1.0, 2.0]));
        let expected = DMatrix::from_row_slice(2, 2, &[4.0, 2f64.sqrt(), 2f64.sqrt(), 18.0]);
        assert!((e.covariance - expected).amax() < 1e-14);
    }

    #[test]
    fn indefinite_nominal_covariance_is_an_error() {
        let r = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let v = DVector::from_vec(vec![0.0, 0.0]);
        assert!(
            equivalent_measurement_covariance(&r, &v, &EquivalentWeightOptions::default()).is_err()
        );
    }
}
