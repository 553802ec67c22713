//! Errors of the IARF and Ding building blocks (robust statistics, adaptive factors,
//! residual-based R, process-noise scaling).

use crate::linalg::LinalgError;
use thiserror::Error;

/// Why an IARF / Ding computation could not be done on the data it was handed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AdaptiveMathError {
    /// Two operands do not have matching dimensions.
    #[error("{what}: dimension {actual}, expected {expected}")]
    DimensionMismatch {
        /// Which operand.
        what: &'static str,
        /// Expected dimension.
        expected: usize,
        /// Dimension received.
        actual: usize,
    },
    /// An operand holds a NaN or an infinity.
    #[error("{what}: non-finite value")]
    NotFinite {
        /// Which operand.
        what: &'static str,
    },
    /// An operand is empty (dimension zero).
    #[error("{what}: empty")]
    Empty {
        /// Which operand.
        what: &'static str,
    },
    /// A quantity that must be strictly positive is not.
    #[error("{what} = {value}, expected > 0")]
    NotPositive {
        /// Which quantity.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// An option is outside its valid range.
    #[error("option {name} = {value}: {requirement}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// A covariance could not be factored.
    #[error(transparent)]
    Linalg(#[from] LinalgError),
}

/// Checks a vector is non-empty and finite.
pub(crate) fn check_vector(
    what: &'static str,
    v: &nalgebra::DVector<f64>,
) -> Result<(), AdaptiveMathError> {
    if v.is_empty() {
        return Err(AdaptiveMathError::Empty { what });
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err(AdaptiveMathError::NotFinite { what });
    }
    Ok(())
}

/// Checks a matrix is `rows`×`cols` and finite.
pub(crate) fn check_matrix(
    what: &'static str,
    m: &nalgebra::DMatrix<f64>,
    rows: usize,
    cols: usize,
) -> Result<(), AdaptiveMathError> {
    if m.nrows() != rows {
        return Err(AdaptiveMathError::DimensionMismatch {
            what,
            expected: rows,
            actual: m.nrows(),
        });
    }
    if m.ncols() != cols {
        return Err(AdaptiveMathError::DimensionMismatch {
            what,
            expected: cols,
            actual: m.ncols(),
        });
    }
    if m.iter().any(|x| !x.is_finite()) {
        return Err(AdaptiveMathError::NotFinite { what });
    }
    Ok(())
}

/// Checks an option is finite and satisfies `ok`.
pub(crate) fn check_option(
    name: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), AdaptiveMathError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(AdaptiveMathError::InvalidOption {
            name,
            value,
            requirement,
        })
    }
}
