//! Statistics of the predicted residual (innovation) used by the IARF paper
//! (Jiang & Zhang 2018, Sensors 18:695): the error-detection statistic ΔV̄ of its
//! section 2.2, eqs. (6)–(8), and the standardized residuals of section 3 that drive the
//! robust double factors.
//!
//! Sign: the paper's predicted residual is V̄ = H x⁻ − z, the usual innovation is
//! z − H x⁻; every statistic here is even in V̄, so either sign may be passed.

use super::math_error::{check_matrix, check_vector, AdaptiveMathError};
use nalgebra::{DMatrix, DVector};

/// ΔV̄ = (V̄ᵀ V̄ / tr P_V̄)^{1/2}, eq. (7), with P_V̄ = H P⁻ Hᵀ + R, eq. (8).
///
/// Dimensionless; about 1 when the residual is consistent with its covariance.
/// Math note: the ratio of a sum of squares to a trace mixes the units of the rows (metres
/// and metres per second) exactly as the paper does; rows with large variances dominate.
pub fn predicted_residual_statistic(
    predicted_residual: &DVector<f64>,
    residual_covariance: &DMatrix<f64>,
) -> Result<f64, AdaptiveMathError> {
    check_vector("predicted residual", predicted_residual)?;
    let r = predicted_residual.len();
    check_matrix("predicted residual covariance", residual_covariance, r, r)?;
    let trace = residual_covariance.trace();
    if trace <= 0.0 {
        return Err(AdaptiveMathError::NotPositive {
            what: "trace of the predicted residual covariance",
            value: trace,
        });
    }
    Ok((predicted_residual.norm_squared() / trace).sqrt())
}

/// Standardized predicted residuals Ṽ_i = V̄_i / √(P_V̄)_ii (dimensionless), the inputs of
/// the double-factor and IGG-III functions.
///
/// Choice: each element is standardized by its own marginal σ (the diagonal of
/// P_V̄ = H P⁻ Hᵀ + R, R the nominal, not yet inflated, covariance), which is what the
/// bifactor literature the paper cites (\[24\]) uses; it needs no decorrelation.
pub fn standardized_residuals(
    predicted_residual: &DVector<f64>,
    residual_covariance: &DMatrix<f64>,
) -> Result<DVector<f64>, AdaptiveMathError> {
    check_vector("predicted residual", predicted_residual)?;
    let r = predicted_residual.len();
    check_matrix("predicted residual covariance", residual_covariance, r, r)?;
    if let Some(&value) = residual_covariance.diagonal().iter().find(|v| **v <= 0.0) {
        return Err(AdaptiveMathError::NotPositive {
            what: "variance of a predicted residual",
            value,
        });
    }
    Ok(predicted_residual.zip_map(&residual_covariance.diagonal(), |v, var| v / var.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistic_matches_hand_computation() {
        let v = DVector::from_vec(vec![3.0, 4.0]);
        let p = DMatrix::from_row_slice(2, 2, &[10.0, 1.0, 1.0, 15.0]);
        // sqrt(25 / 25) = 1
        assert!((predicted_residual_statistic(&v, &p).unwrap() - 1.0).abs() < 1e-15);
        let s = standardized_residuals(&v, &p).unwrap();
        assert!((s[0] - 3.0 / 10f64.sqrt()).abs() < 1e-15);
        assert!((s[1] - 4.0 / 15f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let v = DVector::from_vec(vec![1.0, 2.0]);
        let p = DMatrix::identity(3, 3);
        assert!(matches!(
            predicted_residual_statistic(&v, &p),
            Err(AdaptiveMathError::DimensionMismatch { .. })
        ));
        let p = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        assert!(matches!(
            standardized_residuals(&v, &p),
            Err(AdaptiveMathError::NotPositive { .. })
        ));
        let v = DVector::from_vec(vec![f64::NAN, 2.0]);
        assert!(matches!(
            predicted_residual_statistic(&v, &DMatrix::identity(2, 2)),
            Err(AdaptiveMathError::NotFinite { .. })
        ));
    }
}
