//! The third-degree spherical-radial cubature Kalman filter (Arasaratnam & Haykin 2009), as
//! used by the IARF paper (Jiang & Zhang 2018, Sensors 18:695, eqs. (36)–(41)): 2n points
//! x ± √n·sᵢ, sᵢ the columns of a square root S of P (S Sᵀ = P), equal weights 1/(2n).
//!
//! Math notes:
//! - The rule integrates every polynomial of degree ≤ 3 exactly against N(x, P) for any
//!   square root S, so the paper's SVD root may be replaced by the cheaper, numerically
//!   safe factor of [`SpdFactor`] (Cholesky, then jitter, then clamped eigen-decomposition).
//!   On a linear model the CKF therefore reproduces the Kalman filter to rounding.
//! - Covariances are accumulated from centred deviations, Σ (Xᵢ − x̄)(Xᵢ − x̄)ᵀ / 2n, which
//!   equals the paper's Σ XᵢXᵢᵀ/2n − x̄x̄ᵀ but does not cancel catastrophically when
//!   |x̄| ≫ the spread.
//! - The posterior covariance uses the Joseph-equivalent form
//!   P⁺ = P − K P_xzᵀ − P_xz Kᵀ + K P_zz Kᵀ, symmetrised. It equals the paper's
//!   P − K P_zz Kᵀ for the optimal gain, and an error δK in the gain (rounding in the solve)
//!   enters only at second order, O(δK P_zz δKᵀ), instead of first order.

use crate::linalg::{symmetrize, Factorization, LinalgError, SpdFactor};
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

/// Why a cubature step could not be done.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CubatureError {
    /// An operand or a model output has the wrong dimension.
    #[error("{what}: dimension {actual}, expected {expected}")]
    DimensionMismatch {
        /// Which operand.
        what: &'static str,
        /// Expected dimension.
        expected: usize,
        /// Dimension received.
        actual: usize,
    },
    /// An operand or a model output holds a NaN or an infinity.
    #[error("{what}: non-finite value")]
    NotFinite {
        /// Which operand.
        what: &'static str,
    },
    /// A covariance could not be factored.
    #[error(transparent)]
    Linalg(#[from] LinalgError),
}

/// A Gaussian density: mean (n) and covariance (n×n).
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian {
    /// Mean.
    pub mean: DVector<f64>,
    /// Covariance, symmetric positive definite.
    pub covariance: DMatrix<f64>,
}

/// The 2n cubature points of a Gaussian.
#[derive(Debug, Clone)]
pub struct CubaturePoints {
    /// Points as columns (n×2n): columns i and n + i are x ± √n·sᵢ.
    pub points: DMatrix<f64>,
    /// How the square root of P was obtained.
    pub factorization: Factorization,
}

fn check_vector(what: &'static str, v: &DVector<f64>, n: usize) -> Result<(), CubatureError> {
    if v.len() != n {
        return Err(CubatureError::DimensionMismatch {
            what,
            expected: n,
            actual: v.len(),
        });
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err(CubatureError::NotFinite { what });
    }
    Ok(())
}

fn check_square(what: &'static str, m: &DMatrix<f64>, n: usize) -> Result<(), CubatureError> {
    for actual in [m.nrows(), m.ncols()] {
        if actual != n {
            return Err(CubatureError::DimensionMismatch {
                what,
                expected: n,
                actual,
            });
        }
    }
    if m.iter().any(|x| !x.is_finite()) {
        return Err(CubatureError::NotFinite { what });
    }
    Ok(())
}

/// The 2n cubature points x ± √n·sᵢ of N(mean, covariance).
pub fn cubature_points(prior: &Gaussian) -> Result<CubaturePoints, CubatureError> {
    let n = prior.mean.len();
    check_vector("mean", &prior.mean, n)?;
    check_square("covariance", &prior.covariance, n)?;
    let factor = SpdFactor::new("covariance", &prior.covariance)?;
    let spread = factor.sqrt() * (n as f64).sqrt();
    let mut points = DMatrix::zeros(n, 2 * n);
    for i in 0..n {
        let s = spread.column(i);
        points.set_column(i, &(&prior.mean + s));
        points.set_column(n + i, &(&prior.mean - s));
    }
    Ok(CubaturePoints {
        points,
        factorization: factor.method(),
    })
}

/// Propagates the points through `g`, checking each output has `dim` finite rows.
fn propagate<G>(
    what: &'static str,
    points: &DMatrix<f64>,
    dim: usize,
    mut g: G,
) -> Result<DMatrix<f64>, CubatureError>
where
    G: FnMut(&DVector<f64>) -> DVector<f64>,
{
    let mut out = DMatrix::zeros(dim, points.ncols());
    for (i, column) in points.column_iter().enumerate() {
        let y = g(&column.clone_owned());
        check_vector(what, &y, dim)?;
        out.set_column(i, &y);
    }
    Ok(out)
}

/// Mean and centred deviations of equally weighted columns.
fn mean_and_deviations(points: &DMatrix<f64>) -> (DVector<f64>, DMatrix<f64>) {
    let mean = points.column_mean();
    let mut deviations = points.clone();
    for mut column in deviations.column_iter_mut() {
        column -= &mean;
    }
    (mean, deviations)
}

/// Time update, eqs. (36)–(38): x⁻ = mean f(Xᵢ), P⁻ = cov f(Xᵢ) + Q.
/// `f` maps a state (n) to the predicted state (n); `q` is the process noise (n×n).
pub fn cubature_time_update<F>(
    posterior: &Gaussian,
    process_noise: &DMatrix<f64>,
    f: F,
) -> Result<Gaussian, CubatureError>
where
    F: FnMut(&DVector<f64>) -> DVector<f64>,
{
    let n = posterior.mean.len();
    check_square("process noise", process_noise, n)?;
    let points = cubature_points(posterior)?;
    let propagated = propagate("propagated state", &points.points, n, f)?;
    let (mean, dev) = mean_and_deviations(&propagated);
    let covariance = symmetrize(&(&dev * dev.transpose() / (2 * n) as f64 + process_noise));
    Ok(Gaussian { mean, covariance })
}

/// Everything a measurement update produced (diagnostics and the robust/adaptive layers
/// need the innovation and its covariance).
#[derive(Debug, Clone)]
pub struct CubatureUpdate {
    /// Posterior density.
    pub posterior: Gaussian,
    /// Predicted measurement z̄ = mean h(Xᵢ) (r).
    pub predicted_measurement: DVector<f64>,
    /// Innovation z − z̄ (r).
    pub innovation: DVector<f64>,
    /// Innovation covariance P_zz = cov h(Xᵢ) + R (r×r).
    pub innovation_covariance: DMatrix<f64>,
    /// Cross covariance P_xz (n×r).
    pub cross_covariance: DMatrix<f64>,
    /// Gain K = P_xz P_zz⁻¹ (n×r).
    pub gain: DMatrix<f64>,
    /// How the square root of the prior covariance was obtained.
    pub prior_factorization: Factorization,
    /// How P_zz was factored.
    pub innovation_factorization: Factorization,
}

/// Measurement update, eqs. (33)–(35), (39)–(41), with the Joseph-equivalent posterior.
/// `h` maps a state (n) to a predicted measurement (r = z.len()); `r` is R (r×r).
pub fn cubature_measurement_update<H>(
    prior: &Gaussian,
    measurement: &DVector<f64>,
    measurement_covariance: &DMatrix<f64>,
    h: H,
) -> Result<CubatureUpdate, CubatureError>
where
    H: FnMut(&DVector<f64>) -> DVector<f64>,
{
    let n = prior.mean.len();
    let r = measurement.len();
    check_vector("measurement", measurement, r)?;
    check_square("measurement covariance", measurement_covariance, r)?;
    let points = cubature_points(prior)?;
    let predicted = propagate("predicted measurement", &points.points, r, h)?;
    let (z_mean, z_dev) = mean_and_deviations(&predicted);
    let x_dev = {
        let mut d = points.points.clone();
        for mut column in d.column_iter_mut() {
            column -= &prior.mean;
        }
        d
    };
    let weight = 1.0 / (2 * n) as f64;
    let p_zz = symmetrize(&(&z_dev * z_dev.transpose() * weight + measurement_covariance));
    let p_xz = &x_dev * z_dev.transpose() * weight;
    let factor = SpdFactor::new("innovation covariance", &p_zz)?;
    // K = P_xz P_zz⁻¹ = (P_zz⁻¹ P_xzᵀ)ᵀ, P_zz symmetric.
    let gain = factor.solve(&p_xz.transpose()).transpose();
    let innovation = measurement - &z_mean;
    let k_pxz_t = &gain * p_xz.transpose();
    let covariance = symmetrize(
        &(&prior.covariance - &k_pxz_t - k_pxz_t.transpose() + &gain * &p_zz * gain.transpose()),
    );
    Ok(CubatureUpdate {
        posterior: Gaussian {
            mean: &prior.mean + &gain * &innovation,
            covariance,
        },
        predicted_measurement: z_mean,
        innovation,
        innovation_covariance: p_zz,
        cross_covariance: p_xz,
        gain,
        prior_factorization: points.factorization,
        innovation_factorization: factor.method(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_reproduce_mean_and_covariance() {
        let prior = Gaussian {
            mean: DVector::from_vec(vec![1.0, -2.0, 3.0]),
            covariance: DMatrix::from_row_slice(
                3,
                3,
                &[2.0, 0.3, 0.1, 0.3, 1.0, -0.2, 0.1, -0.2, 0.5],
            ),
        };
        let pts = cubature_points(&prior).unwrap();
        assert_eq!(pts.points.ncols(), 6);
        let (mean, dev) = mean_and_deviations(&pts.points);
        assert!((mean - &prior.mean).amax() < 1e-14);
        assert!((&dev * dev.transpose() / 6.0 - &prior.covariance).amax() < 1e-14);
    }

    #[test]
    fn model_output_of_wrong_dimension_is_an_error() {
        let prior = Gaussian {
            mean: DVector::zeros(2),
            covariance: DMatrix::identity(2, 2),
        };
        let r = cubature_time_update(&prior, &DMatrix::identity(2, 2), |x| {
            DVector::from_element(3, x[0])
        });
        assert!(matches!(r, Err(CubatureError::DimensionMismatch { .. })));
        let r = cubature_measurement_update(
            &prior,
            &DVector::zeros(1),
            &DMatrix::identity(1, 1),
            |_| DVector::from_element(1, f64::NAN),
        );
        assert!(matches!(r, Err(CubatureError::NotFinite { .. })));
    }
}
