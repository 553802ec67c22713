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
    bandwidth_from_scale(sample_std(samples)?, samples.len())
}

/// Eq. (23) for a given scale σ and sample count N: h = 1.06 σ N^(−1/5).
fn bandwidth_from_scale(sigma: f64, n: usize) -> Result<f64, AdaptiveError> {
    if sigma <= 0.0 {
        return Err(AdaptiveError::ZeroVariance {
            what: "Silverman bandwidth",
        });
    }
    Ok(1.06 * sigma * (n as f64).powf(-0.2))
}

/// Quantile `q` ∈ [0, 1] of already sorted, non-empty data, linear between order
/// statistics (numpy's default "linear" method).
fn sorted_quantile(sorted: &[f64], q: f64) -> f64 {
    let position = q * (sorted.len().saturating_sub(1)) as f64;
    let lower = position.floor() as usize;
    let fraction = position - lower as f64;
    match (sorted.get(lower), sorted.get(lower + 1)) {
        (Some(a), Some(b)) => a + fraction * (b - a),
        (Some(a), None) => *a,
        _ => f64::NAN,
    }
}

/// Robust scale of a sample: min(sample standard deviation, IQR/1.349), Silverman's own
/// guard against heavy tails (IQR/1.349 equals σ for a normal law).
///
/// Errors: fewer than 2 samples or a non-finite sample.
pub fn robust_scale(samples: &[f64]) -> Result<f64, AdaptiveError> {
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    robust_scale_presorted(samples, &sorted)
}

/// [`robust_scale`] with the sorting done by the caller: `sorted` must hold the same values
/// as `samples` in ascending order ([`f64::total_cmp`]). A caller that keeps a sliding
/// window sorted as samples come and go saves a sort per sample; the result is the same to
/// the bit, since the standard deviation is still summed in the order of `samples`.
///
/// Errors: fewer than 2 samples, a non-finite sample, or `sorted` of another length.
pub fn robust_scale_presorted(samples: &[f64], sorted: &[f64]) -> Result<f64, AdaptiveError> {
    let std = sample_std(samples)?;
    if sorted.len() != samples.len() {
        return Err(AdaptiveError::LengthMismatch {
            what: "robust scale (sorted copy)",
            left: samples.len(),
            right: sorted.len(),
        });
    }
    debug_assert!(sorted.windows(2).all(|w| w[0].total_cmp(&w[1]).is_le()));
    let iqr = sorted_quantile(sorted, 0.75) - sorted_quantile(sorted, 0.25);
    let iqr_scale = iqr / 1.349;
    // A window whose middle half is one repeated value has IQR 0 but may still spread:
    // then the standard deviation is the only usable scale.
    Ok(if iqr_scale > 0.0 {
        std.min(iqr_scale)
    } else {
        std
    })
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
    /// Bandwidth h = 1.06 σ N^(−1/5) used for the window.
    pub bandwidth: f64,
    /// Robust scale σ of the window ([`robust_scale`]).
    pub window_scale: f64,
    /// True when `density > threshold`: the sample is plausibly from the window's law.
    pub credible: bool,
}

/// Credibility of a new sample `z` against a `window` of earlier samples (section 3.2).
///
/// Choice (threshold): the paper accepts z when f̂(z) > K(3σ), which mixes a density
/// (1/unit) with a kernel value of a dimensional argument. Here the threshold is the
/// density that a normal law with the window's scale σ has `kde_threshold` scales from its
/// centre: φ(`kde_threshold`)/σ (φ the standard normal density). For a Gaussian window and
/// `kde_threshold` = 3 this flags samples beyond roughly 3.2σ from the bulk (the kernel
/// smoothing widens the estimate a little), i.e. a few per thousand.
///
/// Choice (scale): σ, both in the threshold and in the bandwidth of eq. (23), is the
/// robust scale min(standard deviation, IQR/1.349) of the window, not the plain standard
/// deviation. The test exists to catch outliers, and with the plain standard deviation one
/// large outlier in the window inflates σ, hence h and the acceptance region, and masks the
/// outliers after it (seeded runs: a heavy-tailed burst went unflagged in 30 % of draws).
/// For Gaussian data both scales agree.
///
/// Errors: fewer than 2 window samples, non-finite input, zero spread in the window, or a
/// `kde_threshold` that is not positive and finite.
pub fn credibility(
    window: &[f64],
    z: f64,
    kde_threshold: f64,
) -> Result<Credibility, AdaptiveError> {
    let mut sorted = window.to_vec();
    sorted.sort_by(f64::total_cmp);
    credibility_presorted(window, &sorted, z, kde_threshold)
}

/// [`credibility`] with the window's sorted copy kept by the caller (see
/// [`robust_scale_presorted`]); the same result to the bit.
///
/// Errors: those of [`credibility`], and `sorted_window` of another length than `window`.
pub fn credibility_presorted(
    window: &[f64],
    sorted_window: &[f64],
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
    let window_scale = robust_scale_presorted(window, sorted_window)?;
    let bandwidth = bandwidth_from_scale(window_scale, window.len())?;
    let density = kde_density(window, bandwidth, z)?;
    let threshold = gaussian_kernel(kde_threshold) / window_scale;
    Ok(Credibility {
        density,
        threshold,
        bandwidth,
        window_scale,
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

    #[test]
    fn presorted_credibility_is_the_same_to_the_bit() {
        let window: Vec<f64> = (0..40)
            .map(|i| ((i * 17) % 11) as f64 * 0.37 - 1.9)
            .collect();
        let mut sorted = window.clone();
        sorted.sort_by(f64::total_cmp);
        for z in [-5.0, -0.3, 0.0, 1.7, 9.0] {
            assert_eq!(
                credibility(&window, z, 3.0).unwrap(),
                credibility_presorted(&window, &sorted, z, 3.0).unwrap()
            );
        }
        assert!(matches!(
            credibility_presorted(&window, &sorted[1..], 0.0, 3.0),
            Err(AdaptiveError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn robust_scale_by_hand() {
        // Quartiles of 1..=5 are 2 and 4 (linear): IQR/1.349 = 1.4826 < std = 1.5811.
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert!((robust_scale(&x).unwrap() - 2.0 / 1.349).abs() < 1e-15);
        // One huge outlier: the IQR scale ignores it, the standard deviation does not.
        let y = [1.0, 2.0, 3.0, 4.0, 500.0];
        assert!((robust_scale(&y).unwrap() - 2.0 / 1.349).abs() < 1e-15);
        // Middle half constant: fall back to the standard deviation.
        let z = [0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0];
        assert!((robust_scale(&z).unwrap() - sample_std(&z).unwrap()).abs() < 1e-15);
    }
}
