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
/// consistent order estimator. Shibata (1976): with L orders above the true one, its
/// probability of the exact order tends to P(every partial sum of L terms 2 − χ²₁ is
/// positive): 84.3 % for L = 1, 76.0 % for L = 3 (AR(2), max_order 5), 78.7 % for L = 2
/// (AR(3)), 72.9–73.5 % at max_order 8, whatever N; AICc and FPE share that limit (their
/// penalties differ from 2k by O(k²/N)). Measured with 200 draws (test
/// `order_criteria_investigation`, `--ignored --nocapture`):
/// - crate AIC (statsmodels' Burg variances, as the fixture) at max_order 5: AR(2) 67.5 /
///   66.5 / 70.0 %, AR(3) 63.0 / 69.0 / 71.5 % for N = 100 / 500 / 5000; at max_order p + 1
///   77.0–81.5 % (AR(2)), 70.5–79.0 % (AR(3));
/// - AIC on the Levinson-recursive variances σ²_k = (1 − κ_k²) σ²_{k−1}: 7–9 points higher
///   (AR(2) 74.5 / 77.5 / 78.0 %, AR(3) 70.0 / 76.5 / 77.5 %), i.e. at Shibata's limit —
///   statsmodels' per-stage normalisation D_k / (2 (N − k)) adds O(1) noise to N ln σ²;
/// - AICc and FPE within 2.5 points of AIC at N ≥ 500 (AICc up to 5 points better at
///   N = 100); BIC 93–99.5 % except AR(3) at N = 100 (62–65 %, the AR(3) term too small
///   for BIC's penalty on 100 samples).
///
/// So no length, maximum order (above p) or AIC variant reaches 90 %; the default stays
/// the paper's AIC, and BIC (`ar_order_criterion: bic`) is the option that meets the target
/// at N = 500 (next tests). Run with `--ignored` to see this test fail.
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

// ---------------------------------------------------------------------------------------
// Why AIC cannot reach the 90 % target: its asymptotic law (Shibata 1976).

/// Shibata's (1976) limit of the probability that AIC picks the true order p when
/// `spare_orders` L = max_order − p higher orders are tried.
///
/// Math note: for a true AR(p) and N → ∞, N ln(σ²_{p+j−1}/σ²_{p+j}) for j = 1..L tend to
/// independent χ²₁ variables (the squared, √N-scaled spare reflection coefficients), so
/// AIC(p + j) − AIC(p) → Σ_{i ≤ j} (2 − χ²₁,i), a random walk; the true order wins when
/// every partial sum is positive (orders below p lose with probability → 1). For L = 1
/// this is P(χ²₁ < 2) = erf(1) = 0.8427; it falls with L towards 0.71. No N and no
/// variant of AIC that shares its asymptotics (AICc, FPE: their penalties differ from 2k
/// by O(k²/N)) gets above erf(1) < 0.90 with even one spare order. Computed by simulating
/// the random walk.
fn shibata_exact_order_probability(spare_orders: usize, draws: usize, seed: u64) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let hits = (0..draws)
        .filter(|_| {
            let mut walk = 0.0;
            let mut positive = true;
            for _ in 0..spare_orders {
                let z: f64 = unit.sample(&mut rng);
                walk += 2.0 - z * z;
                positive &= walk > 0.0;
            }
            positive
        })
        .count();
    hits as f64 / draws as f64
}

/// The order-selection criteria compared in the investigation, each computed from the
/// Burg innovation variances σ²_k (k = 0..max_order) of one sequence of N samples.
#[derive(Debug, Clone, Copy)]
enum Criterion {
    /// N ln σ²_k + 2k (the crate's and the fixture's AIC).
    Aic,
    /// Hurvich and Tsai's corrected AIC: AIC + 2(k + 1)(k + 2)/(N − k − 2).
    Aicc,
    /// Akaike's final prediction error in log form, N ln(σ²_k (N + k)/(N − k)) (zero mean).
    Fpe,
    /// N ln σ²_k + k ln N.
    Bic,
}

impl Criterion {
    fn score(self, n: usize, sigma2: f64, k: usize) -> f64 {
        let (n_f, k_f) = (n as f64, k as f64);
        let base = n_f * sigma2.ln();
        match self {
            Self::Aic => base + 2.0 * k_f,
            Self::Aicc => base + 2.0 * k_f + 2.0 * (k_f + 1.0) * (k_f + 2.0) / (n_f - k_f - 2.0),
            Self::Fpe => base + n_f * ((n_f + k_f) / (n_f - k_f)).ln(),
            Self::Bic => base + k_f * n_f.ln(),
        }
    }
}

/// How the innovation variances σ²_k of the order path are computed from one Burg run.
#[derive(Debug, Clone, Copy)]
enum VariancePath {
    /// statsmodels' (and the crate's) σ²_k = (1 − κ_k²) D_k / (2 (N − k)), D_k the summed
    /// forward and backward error power of stage k.
    Statsmodels,
    /// The Levinson recursion σ²_k = (1 − κ_k²) σ²_{k−1} from σ²_0 = the mean square (as in
    /// Matlab's arburg): each spare order changes N ln σ² only by N ln(1 − κ²).
    Recursive,
}

fn variance_path(x: &[f64], max_order: usize, path: VariancePath) -> Vec<f64> {
    match path {
        VariancePath::Statsmodels => (0..=max_order)
            .map(|k| burg(x, k).unwrap().innovation_variance)
            .collect(),
        VariancePath::Recursive => {
            let model = burg(x, max_order).unwrap();
            let mut sigma2 = vec![x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64];
            for kappa in &model.reflection_coefficients {
                let last = sigma2[sigma2.len() - 1];
                sigma2.push(last * (1.0 - kappa * kappa));
            }
            sigma2
        }
    }
}

/// Exact-order rate of `criterion` over `draws` AR(`coeffs`) sequences of `n` samples.
fn criterion_hit_rate(
    coeffs: &[f64],
    n: usize,
    max_order: usize,
    criterion: Criterion,
    path: VariancePath,
    draws: usize,
    seed: u64,
) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let hits = (0..draws)
        .filter(|_| {
            let x = ar_sequence(&mut rng, coeffs, n);
            let best = variance_path(&x, max_order, path)
                .iter()
                .enumerate()
                .map(|(k, &sigma2)| (k, criterion.score(n, sigma2, k)))
                .fold(
                    (0, f64::INFINITY),
                    |best, c| if c.1 < best.1 { c } else { best },
                );
            best.0 == coeffs.len()
        })
        .count();
    hits as f64 / draws as f64
}

/// AIC's exact-order rate against Shibata's limit. The limit is below the issue's 90 % for
/// any number of spare orders (84.3 % with one, 76.0 % with the three of AR(2) at
/// max_order 5, 78.7 % with the two of AR(3)), and AIC on the Levinson-recursive Burg
/// variances reaches it on long sequences (within 3.5 binomial standard errors, 1000 draws
/// of N = 5000), so the target is out of AIC's reach, not missed by a defect. The crate's
/// AIC (statsmodels' per-stage variances, as the fixture) lies below the limit: its
/// per-stage normalisation adds O(1) noise to N ln σ² (measured 7–9 points lower, see the
/// investigation below).
#[test]
fn aic_exact_order_rate_tends_to_shibatas_limit_below_the_target() {
    let l1 = shibata_exact_order_probability(1, 400_000, 3);
    // erf(1) = P(χ²₁ < 2).
    assert!((l1 - 0.842_700_79).abs() < 0.003, "Shibata L = 1: {l1}");
    assert!(l1 < ORDER_HIT_TARGET);
    for (coeffs, seed) in [(&AR2[..], 20), (&AR3[..], 21)] {
        let spare = ORDER_TEST_MAX_ORDER - coeffs.len();
        let limit = shibata_exact_order_probability(spare, 400_000, 4);
        let draws = 1000;
        let n = 5000;
        let recursive = criterion_hit_rate(
            coeffs,
            n,
            ORDER_TEST_MAX_ORDER,
            Criterion::Aic,
            VariancePath::Recursive,
            draws,
            seed,
        );
        let crate_aic = order_hit_rate(
            coeffs,
            n,
            ORDER_TEST_MAX_ORDER,
            OrderCriterion::Aic,
            draws,
            seed,
        )
        .0;
        let se = (limit * (1.0 - limit) / draws as f64).sqrt();
        println!(
            "AIC AR{coeffs:?}, N={n}, max_order {ORDER_TEST_MAX_ORDER} ({spare} spare): Shibata limit \
             {:.1} % (± {:.1} for {draws} draws); recursive variances {:.1} %, crate (statsmodels \
             variances) {:.1} %",
            100.0 * limit,
            100.0 * se,
            100.0 * recursive,
            100.0 * crate_aic
        );
        assert!(limit < ORDER_HIT_TARGET, "limit {limit}");
        assert!(
            (recursive - limit).abs() < 3.5 * se,
            "recursive AIC {recursive} vs limit {limit}"
        );
        assert!(crate_aic < limit + 3.5 * se, "crate AIC {crate_aic}");
    }
}

/// The investigation behind the doc comments above: exact-order rates of AIC, AICc, FPE and
/// BIC on the Burg variances for N = 100 (the estimator's window M), 500 and 5000 and
/// max_order p + 1, 5 and 8, beside Shibata's limit. Prints only; run with `--ignored
/// --nocapture`.
#[test]
#[ignore = "prints a table (the investigation of the AIC target); asserts nothing"]
fn order_criteria_investigation() {
    for (coeffs, seed) in [(&AR2[..], 10), (&AR3[..], 11)] {
        for max_order in [coeffs.len() + 1, ORDER_TEST_MAX_ORDER, 8] {
            let limit = shibata_exact_order_probability(max_order - coeffs.len(), 400_000, 4);
            for n in [100, 500, 5000] {
                for path in [VariancePath::Statsmodels, VariancePath::Recursive] {
                    let rate = |c| {
                        100.0
                            * criterion_hit_rate(
                                coeffs,
                                n,
                                max_order,
                                c,
                                path,
                                ORDER_TEST_DRAWS,
                                seed,
                            )
                    };
                    println!(
                        "AR{coeffs:?} max_order {max_order} N={n:>4} {path:?}: AIC {:5.1} %  \
                         AICc {:5.1} %  FPE {:5.1} %  BIC {:5.1} %   (AIC limit {:.1} %)",
                        rate(Criterion::Aic),
                        rate(Criterion::Aicc),
                        rate(Criterion::Fpe),
                        rate(Criterion::Bic),
                        100.0 * limit
                    );
                }
            }
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
