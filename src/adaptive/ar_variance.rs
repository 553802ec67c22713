//! Variance of a correlated sequence corrected by its AR model, ERMAKF paper eq. (29)
//! (after Ghaleb et al., the paper's reference \[24\]):
//!
//! σ² = ((1/M) Σ_{m=0}^{M−1} x_{k−m}²) / (1 − Σ_{i=1}^{p} a_i β_i),
//!
//! with a_i the AR coefficients in the convention x_n = Σ a_i x_{n−i} + v (as returned by
//! [`super::burg`]) and β_i the sample autocorrelation coefficients at lag i.
//!
//! Math note: for a stationary AR(p) process the Yule–Walker relation gives
//! γ_0 (1 − Σ a_i ρ_i) = σ_v², so the denominator estimates σ_v²/γ_0 ∈ (0, 1] and the
//! correction multiplies the window's mean square by γ_0/σ_v² ≥ 1: the stronger the
//! correlation, the larger the inflation. (It is an inflation on top of γ_0, as the paper
//! intends, not an unbiased estimate of γ_0 itself.) Also note that ∇Z of white GNSS noise
//! is itself an MA(1) with lag-1 correlation −1/2, for which γ_0/σ_v² → 2 as the AR order
//! grows: applied to such a sequence the correction roughly doubles the variance.

use super::error::{check_finite, AdaptiveError};

/// Sample autocorrelation coefficients β_1..β_`max_lag` of `x` as given (not demeaned, in
/// line with the zero-mean difference sequence of eq. 15):
/// β_i = Σ_{n=i}^{N−1} x_n x_{n−i} / Σ_{n=0}^{N−1} x_n² (the biased, positive-semidefinite
/// estimator).
///
/// Errors: a non-finite sample, an all-zero sequence, or `max_lag ≥ N`.
pub fn autocorrelation_coefficients(x: &[f64], max_lag: usize) -> Result<Vec<f64>, AdaptiveError> {
    const WHAT: &str = "sample autocorrelation";
    if x.len() <= max_lag {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: x.len(),
            needed: max_lag + 1,
        });
    }
    check_finite(WHAT, x)?;
    let energy: f64 = x.iter().map(|v| v * v).sum();
    if energy <= 0.0 {
        return Err(AdaptiveError::ZeroVariance { what: WHAT });
    }
    Ok((1..=max_lag)
        .map(|lag| {
            let cross: f64 = x.iter().skip(lag).zip(x.iter()).map(|(a, b)| a * b).sum();
            cross / energy
        })
        .collect())
}

/// Mean square (1/M) Σ x² of a non-empty, finite window (eq. 18, scalar case).
pub fn mean_square(x: &[f64]) -> Result<f64, AdaptiveError> {
    const WHAT: &str = "mean square";
    if x.is_empty() {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: 0,
            needed: 1,
        });
    }
    check_finite(WHAT, x)?;
    Ok(x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64)
}

/// Result of the eq. (29) correction, with the intermediate numbers for diagnostics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArCorrectedVariance {
    /// The corrected variance σ² (numerator / applied denominator).
    pub variance: f64,
    /// The window's mean square (1/M) Σ x².
    pub mean_square: f64,
    /// 1 − Σ a_i β_i as computed, before clamping.
    pub raw_denominator: f64,
    /// The denominator actually used, clamped into [floor, 1].
    pub applied_denominator: f64,
}

impl ArCorrectedVariance {
    /// True when the computed denominator lay outside [floor, 1] and was clamped.
    pub fn clamped(&self) -> bool {
        self.raw_denominator != self.applied_denominator
    }
}

/// Eq. (29): the window's mean square divided by 1 − Σ a_i β_i, with `ar_coefficients`
/// a_1..a_p (x_n = Σ a_i x_{n−i} + v) and β_i from [`autocorrelation_coefficients`].
///
/// Choice (denominator guard): the denominator is clamped into [`denominator_floor`, 1].
/// - Below the floor (including zero or negative values, which a near-unit-root or
///   non-stationary fit can produce) the inflation is capped at 1/`denominator_floor`
///   instead of blowing up or changing sign.
/// - Above 1 it would *deflate* the variance. For a Yule–Walker fit the denominator is
///   σ_v²/γ_0 ≤ 1; a value above 1 only comes from the mismatch between Burg coefficients
///   and sample autocorrelations on a short window, so it is treated as "no correction".
///
/// `denominator_floor` must lie in (0, 1]. With p = 0 (no coefficients) the result is the
/// plain mean square. Errors: too few samples for the lags (N ≤ p), non-finite input, an
/// all-zero window, or an invalid floor.
pub fn ar_corrected_variance(
    x: &[f64],
    ar_coefficients: &[f64],
    denominator_floor: f64,
) -> Result<ArCorrectedVariance, AdaptiveError> {
    if !(denominator_floor > 0.0 && denominator_floor <= 1.0) {
        return Err(AdaptiveError::InvalidParameter {
            name: "denominator_floor",
            value: denominator_floor,
            reason: "must lie in (0, 1]",
        });
    }
    check_finite("AR coefficients", ar_coefficients)?;
    let mean_sq = mean_square(x)?;
    let beta = autocorrelation_coefficients(x, ar_coefficients.len())?;
    let raw_denominator = 1.0
        - ar_coefficients
            .iter()
            .zip(&beta)
            .map(|(a, b)| a * b)
            .sum::<f64>();
    let applied_denominator = raw_denominator.clamp(denominator_floor, 1.0);
    Ok(ArCorrectedVariance {
        variance: mean_sq / applied_denominator,
        mean_square: mean_sq,
        raw_denominator,
        applied_denominator,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn autocorrelation_by_hand() {
        let x = [1.0, 2.0, -1.0];
        let beta = autocorrelation_coefficients(&x, 2).unwrap();
        // energy 6; lag 1: 1·2 + 2·(−1) = 0; lag 2: 1·(−1) = −1.
        assert_eq!(beta, vec![0.0, -1.0 / 6.0]);
    }

    #[test]
    fn order_zero_is_the_mean_square() {
        let x = [1.0, -3.0, 2.0];
        let r = ar_corrected_variance(&x, &[], 0.1).unwrap();
        assert!((r.variance - 14.0 / 3.0).abs() < 1e-15);
        assert!(!r.clamped());
    }

    #[test]
    fn ar1_inflation_is_one_over_one_minus_a_beta() {
        let x = [1.0, 0.9, 0.7, 0.8, 0.4, 0.5, 0.1];
        let beta = autocorrelation_coefficients(&x, 1).unwrap()[0];
        let a = 0.6;
        let r = ar_corrected_variance(&x, &[a], 0.05).unwrap();
        let expected = mean_square(&x).unwrap() / (1.0 - a * beta);
        assert!((r.variance - expected).abs() < 1e-14 * expected);
    }

    #[test]
    fn denominator_is_floored_and_capped() {
        // A strongly positively correlated window with a coefficient above one: the raw
        // denominator goes negative and is floored.
        let x = [1.0, 1.0, 1.0, 1.0, 1.0];
        let r = ar_corrected_variance(&x, &[1.5], 0.1).unwrap();
        assert!(r.raw_denominator < 0.0);
        assert_eq!(r.applied_denominator, 0.1);
        assert!((r.variance - 10.0).abs() < 1e-12);
        assert!(r.clamped());
        // A negative coefficient on a positively correlated window: above one, capped.
        let r = ar_corrected_variance(&x, &[-0.5], 0.1).unwrap();
        assert!(r.raw_denominator > 1.0);
        assert_eq!(r.applied_denominator, 1.0);
        assert!((r.variance - 1.0).abs() < 1e-15);
    }

    #[test]
    fn bad_floor_is_rejected() {
        assert!(matches!(
            ar_corrected_variance(&[1.0, 2.0], &[0.1], 0.0),
            Err(AdaptiveError::InvalidParameter { .. })
        ));
    }
}
