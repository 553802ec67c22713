//! Gaussian-kernel density estimate and the credibility test of the ERMAKF paper,
//! section 3.2, eqs. (20)–(23).

use super::error::{check_finite, AdaptiveError};

/// 1/√(2π).
const INV_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

/// Standard normal density φ(u) = e^{−u²/2}/√(2π), the Gaussian kernel K of eq. (22).
pub fn gaussian_kernel(u: f64) -> f64 {
    INV_SQRT_2PI * (-0.5 * u * u).exp()
}

/// Sample standard deviation about the sample mean, with the N − 1 divisor.
///
/// Errors: fewer than 2 samples or a non-finite sample.
pub fn sample_std(samples: &[f64]) -> Result<f64, AdaptiveError> {
    const WHAT: &str = "sample standard deviation";
    let n = samples.len();
    if n < 2 {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: n,
            needed: 2,
        });
    }
    check_finite(WHAT, samples)?;
    let mean = samples.iter().sum::<f64>() / n as f64;
    let ss: f64 = samples.iter().map(|v| (v - mean) * (v - mean)).sum();
    Ok((ss / (n - 1) as f64).sqrt())
}

/// Silverman's rule-of-thumb bandwidth, eq. (23): h = 1.06 σ N^(−1/5).
///
/// Choice: σ is the sample *standard deviation* (N − 1 divisor) of `samples`. The paper
/// calls it "the variance", which cannot be right dimensionally: h is added to and
/// divided into values of the sample's own unit, so it must scale like a standard deviation.
///
/// Errors: fewer than 2 samples, a non-finite sample, or zero spread.
pub fn silverman_bandwidth(samples: &[f64]) -> Result<f64, AdaptiveError> {
    let sigma = sample_std(samples)?;
    if sigma <= 0.0 {
        return Err(AdaptiveError::ZeroVariance {
            what: "Silverman bandwidth",
        });
    }
    Ok(1.06 * sigma * (samples.len() as f64).powf(-0.2))
}

/// Kernel density estimate at `z`, eq. (20): f̂(z) = (1/(N h)) Σ K((z − x_i)/h).
///
/// Errors: no samples, a non-finite sample or `z`, or a bandwidth that is not positive and
/// finite.
pub fn kde_density(samples: &[f64], bandwidth: f64, z: f64) -> Result<f64, AdaptiveError> {
    const WHAT: &str = "kernel density estimate";
    if samples.is_empty() {
        return Err(AdaptiveError::NotEnoughSamples {
            what: WHAT,
            got: 0,
            needed: 1,
        });
    }
    if !(bandwidth > 0.0 && bandwidth.is_finite()) {
        return Err(AdaptiveError::InvalidParameter {
            name: "bandwidth",
            value: bandwidth,
            reason: "must be positive and finite",
        });
    }
    check_finite(WHAT, samples)?;
    check_finite(WHAT, &[z])?;
    let sum: f64 = samples
        .iter()
        .map(|x| gaussian_kernel((z - x) / bandwidth))
        .sum();
    Ok(sum / (samples.len() as f64 * bandwidth))
}

/// The verdict of the credibility test on one new sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Credibility {
    /// f̂(z_t): the window's kernel density at the new sample (1/unit of the sample).
    pub density: f64,
    /// The density threshold φ(`kde_threshold`)/σ (1/unit of the sample).
    pub threshold: f64,
    /// Silverman bandwidth h used for the window.
    pub bandwidth: f64,
    /// Sample standard deviation σ of the window.
    pub window_std: f64,
    /// True when `density > threshold`: the sample is plausibly from the window's law.
    pub credible: bool,
}

/// Credibility of a new sample `z` against a `window` of earlier samples (section 3.2).
///
/// Choice: the paper accepts z when f̂(z) > K(3σ), which mixes a density (1/unit) with a
/// kernel value of a dimensional argument. Here the threshold is the density that a
/// normal law N(·, σ²) with the window's standard deviation has `kde_threshold` standard
/// deviations from its centre: φ(`kde_threshold`)/σ (φ the standard normal density). For
/// a Gaussian window and `kde_threshold` = 3 this flags samples beyond roughly 3.2σ from
/// the bulk (the kernel smoothing widens the estimate a little), i.e. a few per thousand.
///
/// Errors: fewer than 2 window samples, non-finite input, zero spread in the window, or a
/// `kde_threshold` that is not positive and finite.
pub fn credibility(
    window: &[f64],
    z: f64,
    kde_threshold: f64,
) -> Result<Credibility, AdaptiveError> {
    if !(kde_threshold > 0.0 && kde_threshold.is_finite()) {
        return Err(AdaptiveError::InvalidParameter {
            name: "kde_threshold",
            value: kde_threshold,
            reason: "must be positive and finite",
        });
    }
    let window_std = sample_std(window)?;
    let bandwidth = silverman_bandwidth(window)?;
    let density = kde_density(window, bandwidth, z)?;
    let threshold = gaussian_kernel(kde_threshold) / window_std;
    Ok(Credibility {
        density,
        threshold,
        bandwidth,
        window_std,
        credible: density > threshold,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_sample_density_is_the_kernel() {
        let d = kde_density(&[1.0], 2.0, 3.0).unwrap();
        assert!((d - gaussian_kernel(1.0) / 2.0).abs() < 1e-16);
    }

    #[test]
    fn silverman_by_hand() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let sigma = (5.0f64 / 3.0).sqrt();
        let h = silverman_bandwidth(&x).unwrap();
        assert!((h - 1.06 * sigma * 4f64.powf(-0.2)).abs() < 1e-15);
    }

    #[test]
    fn constant_window_has_no_bandwidth() {
        assert!(matches!(
            silverman_bandwidth(&[2.0, 2.0, 2.0]),
            Err(AdaptiveError::ZeroVariance { .. })
        ));
    }

    #[test]
    fn centre_is_credible_and_far_tail_is_not() {
        let window: Vec<f64> = (0..50).map(|i| (i as f64 - 24.5) / 14.0).collect();
        assert!(credibility(&window, 0.0, 3.0).unwrap().credible);
        let sigma = sample_std(&window).unwrap();
        assert!(!credibility(&window, 10.0 * sigma, 3.0).unwrap().credible);
    }
}
