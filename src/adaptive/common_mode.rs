//! The part of one epoch's per-satellite values that no common error can explain: the
//! residuals of a weighted least-squares fit of a few parameters shared by every satellite
//! (for the redundant-measurement differences: the INS's position or velocity increment
//! error and the receiver clock's unpredicted change), scaled by their redundancy numbers.
//!
//! Math note: with values z = G c + e, weights W = diag(wᵢ) and the fit
//! ĉ = (GᵀWG)⁻¹GᵀWz, the residuals ε = (I − G(GᵀWG)⁻¹GᵀW) z contain nothing of G c. When
//! the weights are the inverse variances of e, E[εᵢ²] = rᵢ σᵢ² with the redundancy number
//! rᵢ = 1 − wᵢ gᵢᵀ(GᵀWG)⁻¹gᵢ ∈ [0, 1] (Σ rᵢ = n − columns), so εᵢ/√rᵢ has the variance of
//! eᵢ again. A satellite with a small rᵢ pins the fit down alone; its residual says little
//! and is left out.

use nalgebra::{DMatrix, DVector};

/// Smallest redundancy number whose residual is returned.
pub const MIN_REDUNDANCY: f64 = 0.2;

/// The residuals of `values` (one per satellite) after the weighted least-squares fit of
/// the shared parameters whose coefficients per satellite are the rows of `geometry`,
/// each divided by √(its redundancy number); None for a satellite below
/// [`MIN_REDUNDANCY`]. Returns None as a whole when fewer than two more satellites than
/// parameters are given, a weight is not positive and finite, or the fit is singular.
pub fn scaled_residuals<const P: usize>(
    values: &[f64],
    geometry: &[[f64; P]],
    weights: &[f64],
) -> Option<Vec<Option<f64>>> {
    let n = values.len();
    if n < P + 2 || geometry.len() != n || weights.len() != n {
        return None;
    }
    if !weights.iter().all(|w| w.is_finite() && *w > 0.0) || !values.iter().all(|v| v.is_finite()) {
        return None;
    }
    let g = DMatrix::from_fn(n, P, |i, j| geometry[i][j]);
    // Columns of very different scale (radians and metres) are equilibrated first.
    let scale: Vec<f64> = (0..P)
        .map(|j| {
            let norm = g.column(j).norm();
            if norm > 0.0 {
                1.0 / norm
            } else {
                1.0
            }
        })
        .collect();
    let g = DMatrix::from_fn(n, P, |i, j| g[(i, j)] * scale[j]);
    let w = DVector::from_column_slice(weights);
    let mut normal = DMatrix::zeros(P, P);
    for i in 0..n {
        let row = g.row(i);
        normal += row.transpose() * row * w[i];
    }
    let inverse = normal.cholesky()?.inverse();
    let z = DVector::from_column_slice(values);
    let gwz = g.transpose() * z.component_mul(&w);
    let fitted = &g * (&inverse * gwz);
    Some(
        (0..n)
            .map(|i| {
                let row = g.row(i);
                let leverage = w[i] * (row * &inverse * row.transpose())[(0, 0)];
                let redundancy = 1.0 - leverage;
                (redundancy >= MIN_REDUNDANCY).then(|| (z[i] - fitted[i]) / redundancy.sqrt())
            })
            .collect(),
    )
}

/// The median of χ²(1): that of a squared scaled residual of the claimed variance.
pub const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// The asymptotic standard deviation of the median of n χ²(1) values over
/// [`CHI2_1_MEDIAN`], times √n: 1 / (2 f(m) m), with f the χ²(1) density at its median m.
pub const MEDIAN_RATIO_SD: f64 = 2.332_774_574_888_844;

/// The median of `values` (sorted in place); None when empty.
pub fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// The factor by which the variances claimed for `squares` (squared scaled residuals
/// divided by their claimed variance, sorted in place) are too small, estimated robustly as
/// their median over [`CHI2_1_MEDIAN`]: Some only when it exceeds 1 by more than `z` of its
/// standard deviations (a one-sided test; `z` 2.33 for 99 %) with `independent` values
/// behind them, at least `min_independent`. The residuals of one fit are correlated: n of
/// them after fitting P parameters hold about n − P independent ones, which the caller
/// says. A minority of outliers moves the median little, where it would dominate the mean.
pub fn robust_variance_ratio(
    squares: &mut [f64],
    independent: f64,
    min_independent: f64,
    z: f64,
) -> Option<f64> {
    if independent < min_independent.max(1.0) {
        return None;
    }
    let ratio = median(squares)? / CHI2_1_MEDIAN;
    (ratio > 1.0 + z * MEDIAN_RATIO_SD / independent.sqrt()).then_some(ratio)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn geometry(n: usize) -> Vec<[f64; 4]> {
        (0..n)
            .map(|i| {
                let az = i as f64 * 2.4;
                let el = 0.3 + 0.1 * (i % 5) as f64;
                // Position in radians-scale units beside a clock in metres.
                [
                    -el.cos() * az.sin() * 6.4e6,
                    -el.cos() * az.cos() * 6.4e6,
                    -el.sin(),
                    1.0,
                ]
            })
            .collect()
    }

    #[test]
    fn a_common_error_is_removed_and_the_variance_restored() {
        let n = 9;
        let g = geometry(n);
        let sigmas: Vec<f64> = (0..n).map(|i| 0.5 + 0.2 * i as f64).collect();
        let weights: Vec<f64> = sigmas.iter().map(|s| 1.0 / (s * s)).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let trials = 4000;
        let mut sum_sq = vec![0.0; n];
        let mut count = vec![0usize; n];
        for t in 0..trials {
            let common = [1e-6 * t as f64, -2e-6, 40.0, 1e3 * (t as f64).sin()];
            let values: Vec<f64> = (0..n)
                .map(|i| {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    g[i].iter().zip(&common).map(|(a, c)| a * c).sum::<f64>() + sigmas[i] * e
                })
                .collect();
            for (i, r) in scaled_residuals(&values, &g, &weights)
                .unwrap()
                .into_iter()
                .enumerate()
            {
                if let Some(r) = r {
                    sum_sq[i] += r * r;
                    count[i] += 1;
                }
            }
        }
        for i in 0..n {
            if count[i] > 0 {
                let sigma = (sum_sq[i] / count[i] as f64).sqrt();
                assert!(
                    (sigma / sigmas[i] - 1.0).abs() < 0.06,
                    "satellite {i}: {sigma} against {}",
                    sigmas[i]
                );
            }
        }
        assert!(
            count.iter().filter(|&&c| c == trials).count() >= n - 2,
            "{count:?}"
        );
    }

    #[test]
    fn too_few_satellites_or_bad_weights_give_none() {
        let g = geometry(5);
        assert!(scaled_residuals(&[0.0; 5], &g, &[1.0; 5]).is_none());
        let g = geometry(7);
        let mut w = vec![1.0; 7];
        w[2] = 0.0;
        assert!(scaled_residuals(&[0.0; 7], &g, &w).is_none());
        assert!(scaled_residuals(&[f64::NAN; 7], &g, &[1.0; 7]).is_none());
        let same = vec![[1.0, 0.0, 0.0, 1.0]; 7];
        assert!(scaled_residuals(&[0.0; 7], &same, &[1.0; 7]).is_none());
    }

    #[test]
    fn the_robust_variance_ratio_finds_the_scale_of_the_majority() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut draw = |n: usize, variance: f64| -> Vec<f64> {
            (0..n)
                .map(|_| {
                    let x: f64 = StandardNormal.sample(&mut rng);
                    variance * x * x
                })
                .collect()
        };
        // Of the claimed variance: not significant (at 99 %) in nearly every trial.
        let significant = (0..200)
            .filter(|_| robust_variance_ratio(&mut draw(30, 1.0), 30.0, 8.0, 2.326).is_some())
            .count();
        assert!(significant <= 8, "{significant} of 200");
        // Four times the claim, a tenth of the values a hundred times it: the median
        // moves to the majority's 0.5/0.9 quantile, a ratio of 5.1, where the mean's
        // would be 13.6.
        let mut mixed = draw(450, 4.0);
        mixed.extend(draw(50, 100.0));
        let ratio = robust_variance_ratio(&mut mixed, 500.0, 8.0, 2.326).unwrap();
        assert!((4.0..6.0).contains(&ratio), "{ratio}");
        // Too few values: no verdict.
        assert_eq!(
            robust_variance_ratio(&mut draw(7, 50.0), 7.0, 8.0, 2.326),
            None
        );
    }
}
