use thiserror::Error;

/// Errors of the adaptive-noise math (Burg/AIC, AR variance correction, KDE, random
/// weighting, windowed estimators). Every variant names what was wrong and the values
/// involved, so a caller can log it and fall back without guessing.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AdaptiveError {
    /// Fewer samples than the computation needs (`needed` is the minimum count).
    #[error("{what}: {got} samples, at least {needed} needed")]
    NotEnoughSamples {
        what: &'static str,
        got: usize,
        needed: usize,
    },
    /// A sample or parameter is NaN or infinite.
    #[error("{what}: non-finite value {value} at index {index}")]
    NonFinite {
        what: &'static str,
        index: usize,
        value: f64,
    },
    /// The sequence has no energy or no spread, so a variance-normalised quantity
    /// (reflection coefficient, bandwidth, autocorrelation) is undefined.
    #[error("{what}: zero variance")]
    ZeroVariance { what: &'static str },
    /// Two slices that must pair element by element differ in length.
    #[error("{what}: length mismatch ({left} vs {right})")]
    LengthMismatch {
        what: &'static str,
        left: usize,
        right: usize,
    },
    /// A configuration value or argument is outside its valid range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
}

/// Checks that every sample is finite; `what` names the caller for the error context.
pub(crate) fn check_finite(what: &'static str, x: &[f64]) -> Result<(), AdaptiveError> {
    match x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((index, &value)) => Err(AdaptiveError::NonFinite { what, index, value }),
        None => Ok(()),
    }
}
