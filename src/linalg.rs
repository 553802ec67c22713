//! Numerically safe factorization of symmetric positive-definite matrices (covariances):
//! a square root `S` with `S Sᵀ = P` for the cubature rule, and solves `P⁻¹ B` for gains and
//! Mahalanobis distances.
//!
//! Math note: covariances in this crate mix units whose variances differ by 20 orders of
//! magnitude (position error in radians, ~1e-14 rad², next to the clock offset in metres,
//! ~1e4 m²). Any tolerance relative to the largest eigenvalue would wipe out the small
//! states. Every repair below therefore works on the correlation matrix
//! `C = D⁻¹ A D⁻¹`, `D = diag(√A_ii)`, which is unit-free with a unit diagonal, and maps
//! back with `D`. A diagonal rescaling changes neither the definiteness nor, up to
//! rounding, the Cholesky factor (`chol(A) = D chol(C)`).
//!
//! The ladder (first success wins, reported as [`Factorization`]):
//! 1. symmetrise `A = (P + Pᵀ)/2` and take its Cholesky factor;
//! 2. Cholesky of `C + ε_j I` with `ε_j =` [`CHOLESKY_JITTER`] (the factor of
//!    `A + ε_j D²`, i.e. every variance inflated by the relative amount `ε_j`);
//! 3. symmetric eigen-decomposition `C = V Λ Vᵀ`; eigenvalues below
//!    `−`[`INDEFINITE_TOLERANCE`] are an error (the matrix is not a covariance, not a
//!    rounding casualty), the others are clamped up to [`EIGEN_FLOOR`]; the square root is
//!    the non-triangular `D V Λ^{1/2}`.

use nalgebra::{Cholesky, DMatrix, DVector, Dyn, SymmetricEigen};
use thiserror::Error;

/// Relative diagonal jitter of the second attempt (dimensionless, on the correlation scale).
/// Choice: 1e-10 is ~10⁶ times the rounding of a unit-diagonal matrix, enough to absorb the
/// loss of definiteness of a covariance update, and far below any statistical meaning.
pub const CHOLESKY_JITTER: f64 = 1e-10;

/// Eigenvalues of the correlation matrix below `−INDEFINITE_TOLERANCE` reject the matrix.
/// Choice: rounding in a covariance update produces negative correlation eigenvalues of
/// order 1e-13 for the dimensions used here (≤ 40); 1e-6 leaves a wide margin while
/// refusing matrices that are genuinely not covariances.
pub const INDEFINITE_TOLERANCE: f64 = 1e-6;

/// Floor of the clamped correlation eigenvalues (dimensionless). Keeps the inverse finite
/// (condition number ≤ n / 1e-12) while changing variances by at most this relative amount.
pub const EIGEN_FLOOR: f64 = 1e-12;

/// Maximum number of Jacobi sweeps granted to the symmetric eigen-solver.
const EIGEN_MAX_ITERATIONS: usize = 10_000;

/// Why a matrix could not be factored as a covariance.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LinalgError {
    /// The matrix is not square.
    #[error("{what}: matrix is {rows}x{cols}, expected square")]
    NotSquare {
        /// Which matrix.
        what: &'static str,
        /// Number of rows.
        rows: usize,
        /// Number of columns.
        cols: usize,
    },
    /// The matrix has no rows.
    #[error("{what}: matrix is empty")]
    Empty {
        /// Which matrix.
        what: &'static str,
    },
    /// The matrix holds a NaN or an infinity.
    #[error("{what}: matrix holds a non-finite element")]
    NotFinite {
        /// Which matrix.
        what: &'static str,
    },
    /// A variance (diagonal element) is zero or negative.
    #[error("{what}: diagonal element {index} is {value}, expected > 0")]
    NonPositiveVariance {
        /// Which matrix.
        what: &'static str,
        /// Index of the offending diagonal element.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The correlation matrix has an eigenvalue below `−INDEFINITE_TOLERANCE`.
    #[error("{what}: correlation eigenvalue {min_eigenvalue} < -{INDEFINITE_TOLERANCE}, not a covariance")]
    Indefinite {
        /// Which matrix.
        what: &'static str,
        /// Smallest eigenvalue of the correlation matrix.
        min_eigenvalue: f64,
    },
    /// The eigen-solver did not converge.
    #[error("{what}: symmetric eigen-decomposition did not converge")]
    EigenNoConvergence {
        /// Which matrix.
        what: &'static str,
    },
}

/// Which rung of the ladder produced the factor (for diagnostics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Factorization {
    /// Plain Cholesky of the symmetrised matrix: exact.
    Cholesky,
    /// Cholesky after inflating every variance by the relative amount [`CHOLESKY_JITTER`].
    CholeskyJitter,
    /// Eigen-decomposition of the correlation matrix; `clamped` eigenvalues were raised to
    /// [`EIGEN_FLOOR`].
    EigenClamped {
        /// Number of eigenvalues that were raised.
        clamped: usize,
    },
}

#[derive(Debug, Clone)]
enum Inner {
    Plain(Cholesky<f64, Dyn>),
    ScaledCholesky {
        scale: DVector<f64>,
        chol: Cholesky<f64, Dyn>,
    },
    ScaledEigen {
        scale: DVector<f64>,
        vectors: DMatrix<f64>,
        values: DVector<f64>,
        clamped: usize,
    },
}

/// A factored covariance `A ≈ S Sᵀ` (exact for [`Factorization::Cholesky`]).
#[derive(Debug, Clone)]
pub struct SpdFactor {
    inner: Inner,
    dimension: usize,
}

/// `(M + Mᵀ)/2`.
pub fn symmetrize(m: &DMatrix<f64>) -> DMatrix<f64> {
    (m + m.transpose()) * 0.5
}

fn check_square_finite(what: &'static str, p: &DMatrix<f64>) -> Result<(), LinalgError> {
    if p.nrows() != p.ncols() {
        return Err(LinalgError::NotSquare {
            what,
            rows: p.nrows(),
            cols: p.ncols(),
        });
    }
    if p.nrows() == 0 {
        return Err(LinalgError::Empty { what });
    }
    if p.iter().any(|v| !v.is_finite()) {
        return Err(LinalgError::NotFinite { what });
    }
    Ok(())
}

impl SpdFactor {
    /// Factors the covariance `p` (named `what` in errors) by the ladder of the module docs.
    pub fn new(what: &'static str, p: &DMatrix<f64>) -> Result<Self, LinalgError> {
        check_square_finite(what, p)?;
        let a = symmetrize(p);
        let dimension = a.nrows();
        if let Some((index, &value)) = a.diagonal().iter().enumerate().find(|(_, v)| **v <= 0.0) {
            return Err(LinalgError::NonPositiveVariance { what, index, value });
        }
        if let Some(chol) = Cholesky::new(a.clone()) {
            return Ok(Self {
                inner: Inner::Plain(chol),
                dimension,
            });
        }
        let scale = a.diagonal().map(f64::sqrt);
        let correlation = DMatrix::from_fn(dimension, dimension, |i, j| {
            a[(i, j)] / (scale[i] * scale[j])
        });
        let jittered = &correlation + DMatrix::identity(dimension, dimension) * CHOLESKY_JITTER;
        if let Some(chol) = Cholesky::new(jittered) {
            return Ok(Self {
                inner: Inner::ScaledCholesky { scale, chol },
                dimension,
            });
        }
        let eigen = SymmetricEigen::try_new(correlation, f64::EPSILON, EIGEN_MAX_ITERATIONS)
            .ok_or(LinalgError::EigenNoConvergence { what })?;
        let min_eigenvalue = eigen.eigenvalues.min();
        if min_eigenvalue < -INDEFINITE_TOLERANCE {
            return Err(LinalgError::Indefinite {
                what,
                min_eigenvalue,
            });
        }
        let clamped = eigen
            .eigenvalues
            .iter()
            .filter(|v| **v < EIGEN_FLOOR)
            .count();
        let values = eigen.eigenvalues.map(|v| v.max(EIGEN_FLOOR));
        Ok(Self {
            inner: Inner::ScaledEigen {
                scale,
                vectors: eigen.eigenvectors,
                values,
                clamped,
            },
            dimension,
        })
    }

    /// Which rung of the ladder was used.
    pub fn method(&self) -> Factorization {
        match &self.inner {
            Inner::Plain(_) => Factorization::Cholesky,
            Inner::ScaledCholesky { .. } => Factorization::CholeskyJitter,
            Inner::ScaledEigen { clamped, .. } => Factorization::EigenClamped { clamped: *clamped },
        }
    }

    /// Dimension of the factored matrix.
    pub fn dimension(&self) -> usize {
        self.dimension
    }

    /// A square root `S` with `S Sᵀ` equal to the (repaired) matrix: lower triangular for
    /// the Cholesky rungs, `D V Λ^{1/2}` for the eigen rung.
    pub fn sqrt(&self) -> DMatrix<f64> {
        match &self.inner {
            Inner::Plain(chol) => chol.l(),
            Inner::ScaledCholesky { scale, chol } => {
                let mut l = chol.l();
                scale_rows(&mut l, scale);
                l
            }
            Inner::ScaledEigen {
                scale,
                vectors,
                values,
                ..
            } => {
                let mut s = vectors.clone();
                for (mut column, value) in s.column_iter_mut().zip(values.iter()) {
                    column *= value.sqrt();
                }
                scale_rows(&mut s, scale);
                s
            }
        }
    }

    /// `A⁻¹ B` for the (repaired) matrix `A`. `B` must have [`Self::dimension`] rows.
    pub fn solve(&self, b: &DMatrix<f64>) -> DMatrix<f64> {
        match &self.inner {
            Inner::Plain(chol) => chol.solve(b),
            Inner::ScaledCholesky { scale, chol } => {
                let mut x = b.clone();
                unscale_rows(&mut x, scale);
                let mut x = chol.solve(&x);
                unscale_rows(&mut x, scale);
                x
            }
            Inner::ScaledEigen {
                scale,
                vectors,
                values,
                ..
            } => {
                let mut x = b.clone();
                unscale_rows(&mut x, scale);
                let mut y = vectors.transpose() * x;
                for (mut row, value) in y.row_iter_mut().zip(values.iter()) {
                    row /= *value;
                }
                let mut x = vectors * y;
                unscale_rows(&mut x, scale);
                x
            }
        }
    }

    /// ln det of the (repaired) matrix.
    pub fn log_det(&self) -> f64 {
        let log_diagonal = |m: &DMatrix<f64>| m.diagonal().iter().map(|v| v.ln()).sum::<f64>();
        let log_scale = |scale: &DVector<f64>| 2.0 * scale.iter().map(|s| s.ln()).sum::<f64>();
        match &self.inner {
            Inner::Plain(chol) => 2.0 * log_diagonal(&chol.l()),
            Inner::ScaledCholesky { scale, chol } => {
                log_scale(scale) + 2.0 * log_diagonal(&chol.l())
            }
            Inner::ScaledEigen { scale, values, .. } => {
                log_scale(scale) + values.iter().map(|v| v.ln()).sum::<f64>()
            }
        }
    }

    /// `A⁻¹ b` for a vector `b` with [`Self::dimension`] rows.
    pub fn solve_vector(&self, b: &DVector<f64>) -> DVector<f64> {
        let x = self.solve(&DMatrix::from_column_slice(b.len(), 1, b.as_slice()));
        DVector::from_column_slice(x.as_slice())
    }
}

fn scale_rows(m: &mut DMatrix<f64>, scale: &DVector<f64>) {
    for (mut row, s) in m.row_iter_mut().zip(scale.iter()) {
        row *= *s;
    }
}

fn unscale_rows(m: &mut DMatrix<f64>, scale: &DVector<f64>) {
    for (mut row, s) in m.row_iter_mut().zip(scale.iter()) {
        row /= *s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reconstruct(f: &SpdFactor) -> DMatrix<f64> {
        let s = f.sqrt();
        &s * s.transpose()
    }

    #[test]
    fn cholesky_rung_is_exact_and_solves() {
        let p = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0]);
        let f = SpdFactor::new("p", &p).unwrap();
        assert_eq!(f.method(), Factorization::Cholesky);
        assert!((reconstruct(&f) - &p).amax() < 1e-14);
        let b = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        assert!((&p * f.solve_vector(&b) - b).amax() < 1e-14);
    }

    #[test]
    fn singular_matrix_takes_the_jitter_rung_with_mixed_scales() {
        // Correlation 1 + 1e-12 (indefinite by rounding size), variances 1e-14 and 1e4
        // (radians next to metres).
        let sd = [1e-7, 1e2];
        let p = DMatrix::from_fn(2, 2, |i, j| {
            sd[i] * sd[j] * if i == j { 1.0 } else { 1.0 + 1e-12 }
        });
        let f = SpdFactor::new("p", &p).unwrap();
        assert_eq!(f.method(), Factorization::CholeskyJitter);
        let back = reconstruct(&f);
        for i in 0..2 {
            for j in 0..2 {
                let rel = (back[(i, j)] - p[(i, j)]).abs() / (sd[i] * sd[j]);
                assert!(rel < 1e-9, "relative error {rel} at ({i},{j})");
            }
        }
    }

    #[test]
    fn slightly_indefinite_matrix_takes_the_eigen_rung() {
        // Correlation 1 + 1e-9: eigenvalues 2 and -1e-9 (rounding-size indefiniteness).
        let p = DMatrix::from_row_slice(2, 2, &[1.0, 1.0 + 1e-9, 1.0 + 1e-9, 1.0]);
        let f = SpdFactor::new("p", &p).unwrap();
        assert_eq!(f.method(), Factorization::EigenClamped { clamped: 1 });
        assert!((reconstruct(&f) - &p).amax() < 1e-8);
        let b = DVector::from_vec(vec![1.0, 1.0]);
        // Along the well-determined direction the solve is accurate.
        assert!((&p * f.solve_vector(&b) - &b).amax() < 1e-6);
    }

    #[test]
    fn genuinely_indefinite_or_bad_matrices_are_errors() {
        let p = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(matches!(
            SpdFactor::new("p", &p),
            Err(LinalgError::Indefinite { .. })
        ));
        let p = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        assert!(matches!(
            SpdFactor::new("p", &p),
            Err(LinalgError::NonPositiveVariance { index: 1, .. })
        ));
        let p = DMatrix::from_row_slice(1, 1, &[f64::NAN]);
        assert!(matches!(
            SpdFactor::new("p", &p),
            Err(LinalgError::NotFinite { .. })
        ));
        let p = DMatrix::<f64>::zeros(2, 3);
        assert!(matches!(
            SpdFactor::new("p", &p),
            Err(LinalgError::NotSquare { .. })
        ));
    }
}
