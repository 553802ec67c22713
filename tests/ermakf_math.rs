//! ERMAKF math against independent references (statsmodels Burg, scipy gaussian_kde; the
//! fixture is made by tools/fixtures/make_ermakf_fixtures.py) and seeded statistical tests
//! of the redundant-measurement estimator.

use adaptive_gnss_ins::adaptive::ar_variance::ar_corrected_variance;
use adaptive_gnss_ins::adaptive::burg::{burg, select_order, select_order_aic, OrderCriterion};
use adaptive_gnss_ins::adaptive::innovation::{
    InnovationCovarianceEstimator, InnovationOptions, InnovationOutcome,
};
use adaptive_gnss_ins::adaptive::kde::{kde_density, silverman_bandwidth};
use adaptive_gnss_ins::adaptive::redundant::{
    NoiseRegime, RedundantEstimate, RedundantNoiseEstimator, RedundantNoiseOptions, VarianceMethod,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, StudentT};
use serde_json::Value;

/// Relative tolerance of Burg coefficients and variances against statsmodels (same
/// algorithm in double precision; differences are rounding only).
const BURG_REL_TOL: f64 = 1e-9;
/// Relative tolerance of KDE densities against scipy (same formula; rounding only).
const KDE_REL_TOL: f64 = 1e-10;
/// Relative tolerance of the Silverman bandwidth recomputed in Rust.
const BANDWIDTH_REL_TOL: f64 = 1e-12;

fn fixtures() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ermakf_fixtures.json"
    );
    let text = std::fs::read_to_string(path).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn assert_rel(actual: f64, expected: f64, tol: f64, what: &str) {
    let scale = expected.abs().max(1e-300);
    assert!(
        (actual - expected).abs() <= tol * scale,
        "{what}: {actual} vs {expected} (rel {:e})",
        (actual - expected).abs() / scale
    );
}

/// Coefficient vectors compared relative to their largest element (a small coefficient
/// next to a large one carries the large one's rounding).
fn assert_coefficients(actual: &[f64], expected: &[f64], what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}: order");
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert!(
            (a - e).abs() <= BURG_REL_TOL * scale,
            "{what} φ_{}: {a} vs {e}",
            i + 1
        );
    }
}

#[test]
fn burg_matches_statsmodels() {
    let fx = fixtures();
    for case in fx["burg"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let x = floats(&case["x"]);
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let demeaned: Vec<f64> = x.iter().map(|v| v - mean).collect();
        for (setting, seq) in [("raw", &x), ("demeaned", &demeaned)] {
            let orders = case[setting]["orders"].as_object().unwrap();
            for (order, reference) in orders {
                let order: usize = order.parse().unwrap();
                let model = burg(seq, order).unwrap();
                let what = format!("{name} {setting} AR({order})");
                assert_coefficients(
                    &model.coefficients,
                    &floats(&reference["coefficients"]),
                    &what,
                );
                assert_rel(
                    model.innovation_variance,
                    reference["sigma2"].as_f64().unwrap(),
                    BURG_REL_TOL,
                    &what,
                );
            }
        }
    }
}

#[test]
fn aic_order_matches_statsmodels_variances() {
    let fx = fixtures();
    for case in fx["burg"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let max_order = case["max_order"].as_u64().unwrap() as usize;
        let x = floats(&case["x"]);
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let demeaned: Vec<f64> = x.iter().map(|v| v - mean).collect();
        for (setting, seq) in [("raw", &x), ("demeaned", &demeaned)] {
            let expected = case[setting]["aic_order"].as_u64().unwrap() as usize;
            let model = select_order_aic(seq, max_order).unwrap();
            assert_eq!(model.order(), expected, "{name} {setting}: AIC order");
            // The selected model is the plain Burg fit of that order.
            let direct = burg(seq, expected).unwrap();
            assert_eq!(model, direct, "{name} {setting}");
        }
    }
}

#[test]
fn kde_matches_scipy_gaussian_kde() {
    let fx = fixtures();
    for case in fx["kde"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let samples = floats(&case["samples"]);
        let h = silverman_bandwidth(&samples).unwrap();
        assert_rel(
            h,
            case["bandwidth"].as_f64().unwrap(),
            BANDWIDTH_REL_TOL,
            name,
        );
        let points = floats(&case["points"]);
        let density = floats(&case["density"]);
        let peak = density.iter().fold(0.0f64, |m, v| m.max(*v));
        for (z, expected) in points.iter().zip(&density) {
            let actual = kde_density(&samples, h, *z).unwrap();
            // Relative to the point's own density, but far-tail values (below 1e-12 of
            // the peak) are compared against the peak: there both are rounding noise.
            let scale = expected.max(1e-12 * peak);
            assert!(
                (actual - expected).abs() <= KDE_REL_TOL * scale,
                "{name} at {z}: {actual} vs {expected}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Seeded statistical tests.

fn white(rng: &mut ChaCha8Rng, sigma: f64, n: usize) -> Vec<f64> {
    let normal = Normal::new(0.0, sigma).unwrap();
    (0..n).map(|_| normal.sample(rng)).collect()
}

fn ar_sequence(rng: &mut ChaCha8Rng, coeffs: &[f64], n: usize) -> Vec<f64> {
    let burn_in = 300;
    let e = white(rng, 1.0, n + burn_in);
    let mut x: Vec<f64> = Vec::with_capacity(n + burn_in);
    for (k, ek) in e.iter().enumerate() {
        let mut acc = *ek;
        for (i, a) in coeffs.iter().enumerate() {
            if k > i {
                acc += a * x[k - 1 - i];
            }
        }
        x.push(acc);
    }
    x.split_off(burn_in)
}

/// Runs ∇Z(k) = V(k) − V(k−1) of white V (σ_V = `sigma`) through the estimator and returns
/// the R̂ of `windows` non-overlapping windows (one estimate every M epochs).
fn rmae_window_estimates(
    options: RedundantNoiseOptions,
    sigma: f64,
    windows: usize,
    seed: u64,
) -> Vec<f64> {
    let m = options.window_size_m;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let v = white(&mut rng, sigma, m * windows + 1);
    let mut est = RedundantNoiseEstimator::new(options).unwrap();
    let mut out = Vec::new();
    for (k, pair) in v.windows(2).enumerate() {
        let outcome = est.push(pair[1] - pair[0]).unwrap();
        if (k + 1) % m == 0 {
            match outcome {
                RedundantEstimate::Ready(e) => out.push(e.r_variance),
                RedundantEstimate::NotEnoughData { .. } => panic!("window full but not ready"),
            }
        }
    }
    out
}

fn mean_and_rel_sd(values: &[f64], truth: f64) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt() / truth)
}

/// Math note: for white V of variance σ², ∇Z is MA(1) with γ_0 = 2σ², γ_1 = −σ²; for
/// Gaussian ∇Z, Var(∇Z²) = 2γ_0² and Cov(∇Z_k², ∇Z_{k−1}²) = 2γ_1², so the window mean
/// over M samples has variance ≈ (8 + 4)σ⁴/M and R̂ = mean/2 a relative standard deviation
/// √(12/M)/2 ≈ 0.173 for M = 100. A single window is therefore within ±10 % of σ² only
/// about 44 % of the time; the ±10 % check applies to the estimator's mean (its bias).
const RMAE_REL_SD_M100: f64 = 0.173;

#[test]
fn rmae_on_white_noise_recovers_sigma_squared() {
    let sigma = 3.0;
    let truth = sigma * sigma;
    let options = RedundantNoiseOptions::default();
    assert_eq!(options.window_size_m, 100);
    let estimates = rmae_window_estimates(options, sigma, 200, 1);
    let (mean, rel_sd) = mean_and_rel_sd(&estimates, truth);
    let within_10 = estimates
        .iter()
        .filter(|r| (*r / truth - 1.0).abs() <= 0.10)
        .count() as f64
        / estimates.len() as f64;
    println!(
        "RMAE M=100, σ²={truth}: mean R̂ {mean:.4} ({:+.2} %), rel sd {rel_sd:.3} (theory {RMAE_REL_SD_M100}), single windows within ±10 %: {:.1} %",
        100.0 * (mean / truth - 1.0),
        100.0 * within_10
    );
    assert!(
        (mean / truth - 1.0).abs() <= 0.10,
        "mean R̂ {mean} vs {truth}"
    );
    assert!(
        (rel_sd / RMAE_REL_SD_M100 - 1.0).abs() <= 0.25,
        "relative spread {rel_sd} vs theory {RMAE_REL_SD_M100}"
    );
}

#[test]
fn random_weighted_rmae_on_white_noise_is_unbiased() {
    let sigma = 0.2;
    let truth = sigma * sigma;
    let options = RedundantNoiseOptions {
        random_weighting: true,
        seed: 99,
        ..RedundantNoiseOptions::default()
    };
    let estimates = rmae_window_estimates(options, sigma, 200, 2);
    let (mean, rel_sd) = mean_and_rel_sd(&estimates, truth);
    println!(
        "random-weighted RMAE M=100, σ²={truth}: mean R̂ {mean:.5} ({:+.2} %), rel sd {rel_sd:.3}",
        100.0 * (mean / truth - 1.0)
    );
    assert!(
        (mean / truth - 1.0).abs() <= 0.10,
        "mean R̂ {mean} vs {truth}"
    );
}

/// Fraction of `draws` sequences of AR(`coeffs`) whose selected order equals the true
/// order, and the fractions under- and over-fitted.
fn order_hit_rate(
    coeffs: &[f64],
    n: usize,
    max_order: usize,
    criterion: OrderCriterion,
    draws: usize,
    seed: u64,
) -> (f64, f64, f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let p = coeffs.len();
    let (mut hit, mut under, mut over) = (0, 0, 0);
    for _ in 0..draws {
        let x = ar_sequence(&mut rng, coeffs, n);
        let order = select_order(&x, max_order, criterion).unwrap().order();
        match order.cmp(&p) {
            std::cmp::Ordering::Equal => hit += 1,
            std::cmp::Ordering::Less => under += 1,
            std::cmp::Ordering::Greater => over += 1,
        }
    }
    let d = draws as f64;
    (hit as f64 / d, under as f64 / d, over as f64 / d)
}

/// AR(2) and AR(3) test models: stationary, last coefficient well away from zero so that
/// N = 500 samples resolve the order.
const AR2: [f64; 2] = [0.75, -0.5];
const AR3: [f64; 3] = [0.6, -0.4, 0.3];
const ORDER_TEST_N: usize = 500;
const ORDER_TEST_MAX_ORDER: usize = 5;
const ORDER_TEST_DRAWS: usize = 200;
/// The issue's target rate of the exact order.
const ORDER_HIT_TARGET: f64 = 0.90;

fn print_rates(label: &str, coeffs: &[f64], max_order: usize, rates: (f64, f64, f64)) {
    println!(
        "{label} AR{coeffs:?}, N={ORDER_TEST_N}, max_order {max_order}: exact {:.1} %, under {:.1} %, over {:.1} %",
        100.0 * rates.0,
        100.0 * rates.1,
        100.0 * rates.2
    );
}

/// The issue's target with the paper's criterion. It fails for a real reason: AIC is not a
/// consistent order estimator and over-fits in roughly 16–30 % of draws however long the
/// sequence (Shibata 1976). Measured with these seeds: AR(2) 66.5 %, AR(3) 69.0 % exact at
/// max_order 5, never under-fitted. Run with `--ignored` to see it; BIC meets the target
/// (next test).
#[test]
#[ignore = "AIC cannot reach 90 % exact order (over-fits ~16-30 %); see the doc comment"]
fn aic_order_hit_rate_reaches_issue_target() {
    for (coeffs, seed) in [(&AR2[..], 10), (&AR3[..], 11)] {
        let rates = order_hit_rate(
            coeffs,
            ORDER_TEST_N,
            ORDER_TEST_MAX_ORDER,
            OrderCriterion::Aic,
            ORDER_TEST_DRAWS,
            seed,
        );
        print_rates("AIC", coeffs, ORDER_TEST_MAX_ORDER, rates);
        assert!(
            rates.0 >= ORDER_HIT_TARGET,
            "AIC exact-order rate {}",
            rates.0
        );
    }
}

/// What AIC does deliver: it (almost) never under-fits, so the AR correction is not missed;
/// its over-fitting only adds spare near-zero coefficients.
#[test]
fn aic_order_does_not_underfit() {
    for (coeffs, seed) in [(&AR2[..], 10), (&AR3[..], 11)] {
        for max_order in [coeffs.len() + 1, ORDER_TEST_MAX_ORDER, 8] {
            let rates = order_hit_rate(
                coeffs,
                ORDER_TEST_N,
                max_order,
                OrderCriterion::Aic,
                ORDER_TEST_DRAWS,
                seed,
            );
            print_rates("AIC", coeffs, max_order, rates);
            assert!(rates.1 <= 0.02, "AIC under-fit rate {}", rates.1);
        }
    }
}

#[test]
fn bic_order_hit_rate_reaches_issue_target() {
    for (coeffs, seed) in [(&AR2[..], 10), (&AR3[..], 11)] {
        for max_order in [ORDER_TEST_MAX_ORDER, 8] {
            let rates = order_hit_rate(
                coeffs,
                ORDER_TEST_N,
                max_order,
                OrderCriterion::Bic,
                ORDER_TEST_DRAWS,
                seed,
            );
            print_rates("BIC", coeffs, max_order, rates);
            assert!(
                rates.0 >= ORDER_HIT_TARGET,
                "BIC exact-order rate {}",
                rates.0
            );
        }
    }
}

/// Math note of ar_variance.rs: ∇Z of white V is MA(1) with ρ_1 = −1/2, so the eq. (29)
/// factor 1/(1 − Σ a_i β_i) lies between 1 and about 2 (1.33 for AR(1), → 2 as p grows).
#[test]
fn eq29_factor_on_differenced_white_noise() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut factors = Vec::new();
    for _ in 0..200 {
        let v = white(&mut rng, 1.0, 101);
        let dz: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
        let model = select_order_aic(&dz, 5).unwrap();
        let c = ar_corrected_variance(&dz, &model.coefficients, 0.1).unwrap();
        factors.push(c.variance / c.mean_square);
    }
    let mean = factors.iter().sum::<f64>() / factors.len() as f64;
    let max = factors.iter().fold(0.0f64, |m, f| m.max(*f));
    println!("eq. (29) factor on ∇Z of white noise, M=100, AIC ≤ 5: mean {mean:.3}, max {max:.3}");
    assert!(factors.iter().all(|f| *f >= 1.0));
    assert!(mean > 1.2 && mean < 2.0, "mean factor {mean}");
}

/// Gaussian (σ = 1) for `n_before`, heavy-tailed for `n_heavy`, Gaussian again for
/// `n_after` epochs. The heavy-tailed part is Student-t with 2 degrees of freedom scaled
/// by `heavy_scale`.
fn switching_sequence(
    rng: &mut ChaCha8Rng,
    n_before: usize,
    n_heavy: usize,
    n_after: usize,
    heavy_scale: f64,
) -> Vec<f64> {
    let t = StudentT::new(2.0).unwrap();
    let mut x = white(rng, 1.0, n_before);
    x.extend((0..n_heavy).map(|_| heavy_scale * t.sample(rng)));
    x.extend(white(rng, 1.0, n_after));
    x
}

#[test]
fn kde_detector_flags_heavy_tails_and_clears() {
    let options = RedundantNoiseOptions::default();
    let k = options.kde_consecutive_epochs;
    let (n_before, n_heavy, n_after) = (300, 40, 300);
    let draws = 200;
    let mut detect_latency = Vec::new();
    let mut clear_latency = Vec::new();
    let mut false_alarms = 0;
    let mut burst_non_gaussian = 0usize;
    for seed in 0..draws {
        let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
        let x = switching_sequence(&mut rng, n_before, n_heavy, n_after, 10.0);
        let mut est = RedundantNoiseEstimator::new(options.clone()).unwrap();
        let regimes: Vec<NoiseRegime> = x
            .iter()
            .map(|z| {
                est.push(*z).unwrap();
                est.regime()
            })
            .collect();
        burst_non_gaussian += regimes[n_before..n_before + n_heavy]
            .iter()
            .filter(|r| **r == NoiseRegime::NonGaussian)
            .count();
        if regimes[..n_before].contains(&NoiseRegime::NonGaussian) {
            false_alarms += 1;
        }
        let detect = regimes[n_before..]
            .iter()
            .position(|r| *r == NoiseRegime::NonGaussian)
            .map(|i| i + 1);
        let back = n_before + n_heavy;
        let clear = regimes[back..]
            .iter()
            .position(|r| *r == NoiseRegime::Gaussian)
            .map(|i| i + 1);
        let stays_clear = clear.is_some_and(|c| {
            regimes[back + c..]
                .iter()
                .all(|r| *r == NoiseRegime::Gaussian)
        });
        detect_latency.push(detect);
        clear_latency.push(if stays_clear { clear } else { None });
    }
    let hist = |v: &[Option<usize>]| {
        let mut h = std::collections::BTreeMap::new();
        for l in v {
            *h.entry(*l).or_insert(0) += 1;
        }
        h
    };
    println!("KDE detector, K = {k}, {draws} draws: false alarms {false_alarms}");
    println!(
        "detection latency (epochs after switch: count) {:?}",
        hist(&detect_latency)
    );
    println!(
        "clearing latency (epochs after return: count) {:?}",
        hist(&clear_latency)
    );
    println!(
        "non-Gaussian share of the burst epochs: {:.1} %",
        100.0 * burst_non_gaussian as f64 / (draws as usize * n_heavy) as f64
    );

    // Math note: a burst sample 10·t₂ is credible when |t₂| ≲ 0.32 (P ≈ 0.23), so the
    // earliest possible flag, after exactly K burst samples, has probability ≈ 0.77³ ≈ 0.46;
    // a later flag comes from a credible sample breaking the streak.
    let at_k = detect_latency.iter().filter(|l| **l == Some(k)).count() as f64 / draws as f64;
    let within_burst = detect_latency
        .iter()
        .filter(|l| l.is_some_and(|l| l <= n_heavy))
        .count() as f64
        / draws as f64;
    assert_eq!(false_alarms, 0, "false alarms in the Gaussian prefix");
    assert!(at_k >= 0.40, "flagged after exactly K epochs in {at_k}");
    assert!(
        within_burst >= 0.95,
        "flagged during the burst in {within_burst}"
    );
    // Cleared within K epochs of the return, and never flagged again in 300 epochs.
    assert!(
        clear_latency.iter().all(|l| l.is_some_and(|l| l <= k)),
        "clearing latencies {:?}",
        hist(&clear_latency)
    );
}

/// In the non-Gaussian regime the estimate is the eq. (29) variance of the window, halved,
/// with the order of the configured criterion: recomputed here from the same window.
#[test]
fn non_gaussian_estimate_is_half_the_eq29_variance() {
    let options = RedundantNoiseOptions::default();
    let m = options.window_size_m;
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let mut x = white(&mut rng, 1.0, 200);
    // A sustained multipath-like disturbance: a correlated AR(1) excursion of scale 20.
    x.extend(ar_sequence(&mut rng, &[0.9], 30).iter().map(|v| 20.0 * v));
    let mut est = RedundantNoiseEstimator::new(options.clone()).unwrap();
    let mut last = None;
    for z in &x {
        last = Some(est.push(*z).unwrap());
    }
    let Some(RedundantEstimate::Ready(e)) = last else {
        panic!("no estimate")
    };
    assert_eq!(e.regime, NoiseRegime::NonGaussian);
    let window = &x[x.len() - m..];
    let model = select_order_aic(window, options.ar_max_order).unwrap();
    let corrected =
        ar_corrected_variance(window, &model.coefficients, options.ar_denominator_floor).unwrap();
    match e.method {
        VarianceMethod::BurgAr { order, .. } => assert_eq!(order, model.order()),
        other => panic!("expected the Burg AR method, got {other:?}"),
    }
    assert!((e.r_variance - corrected.variance / 2.0).abs() <= 1e-12 * corrected.variance);
}

/// The lag-1 whiteness test of the innovation estimator: size on white innovations close
/// to its nominal 5 %, power on AR(1) innovations.
#[test]
fn innovation_whiteness_test_size_and_power() {
    let options = InnovationOptions::default();
    let n = options.window_size;
    let windows = 400;
    let rejection_rate = |x: &[f64]| {
        let mut est = InnovationCovarianceEstimator::new(options.clone()).unwrap();
        let mut rejected = 0;
        for (k, v) in x.iter().enumerate() {
            let out = est.push(*v, 0.0).unwrap();
            if (k + 1) % n == 0 {
                if let InnovationOutcome::Ready(e) = out {
                    rejected += usize::from(e.correlated);
                }
            }
        }
        rejected as f64 / windows as f64
    };
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let size = rejection_rate(&white(&mut rng, 2.0, n * windows));
    let power = rejection_rate(&ar_sequence(&mut rng, &[0.6], n * windows));
    println!(
        "lag-1 z-test, N = {n}, α = 5 %: size {:.1} %, power on AR(1) 0.6 {:.1} %",
        100.0 * size,
        100.0 * power
    );
    // Binomial 3σ band around the nominal 5 % for 400 windows.
    assert!((0.017..=0.083).contains(&size), "size {size}");
    assert!(power >= 0.95, "power {power}");
}
