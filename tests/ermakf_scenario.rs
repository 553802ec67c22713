//! The ERMAKF paper's field comparison on the default simulated scenario (a drive with
//! foliage over 40–120 s and dense buildings over 260–320 s): EKF, EIAKF, SRMAKF and
//! ERMAKF on the same data. The paper's Table 1 reports 3D errors of 5.52/6.24/6.12/4.60 m
//! (position) and 0.38/0.29/0.38/0.17 m/s (velocity) for EKF/EIAKF/SRMAKF/ERMAKF.
//!
//! Asserted, as the paper claims: ERMAKF beats the standard EKF on 3D position and
//! velocity RMSE (measured 2026-12-03: 4.180 against 5.611 m, 0.2154 against 0.2219 m/s;
//! 4.816 against 6.151 m before the start measured the vertical accelerometer bias).
//!
//! Not reproduced (the ignored test keeps the paper's claim as an executable check): in
//! the foliage segment ERMAKF's estimated pseudo-range σ is NOT closer to the simulator's
//! true σ than SRMAKF's (RMS error 2.293 m against 2.172 m; EKF's fixed σ 2.875 m). The
//! simulated multipath is AR(2) with lag-1 correlation about 0.94: the mutual difference
//! ∇Z keeps only 1 − ρ₁ of its variance, and eq. (29) applied to ∇Z restores little of it
//! (its factor 1 − Σ aᵢβᵢ is the one-step predictability of ∇Z, not of the noise itself).
//! SRMAKF also has the lower position error here (4.558 m).
//!
//! Beyond the paper, the correlation-aware option of the redundant estimators
//! (`adaptive.correlation_aware`: differences over lags 1–20 fitted by a white + AR(1)
//! variogram, the errors common to all satellites left out) finds the foliage σ: median
//! ratio of estimated to true σ 1.062, RMS error 1.486 m. Its position error is larger
//! (5.562 m 3D: the true σ makes the filter lean on an IMU whose accelerometer biases are
//! 1250 µg, where under-estimated σ made it follow the ranges), which is why it is off by
//! default.

use adaptive_gnss_ins::config::{Config, FilterVariant};
use adaptive_gnss_ins::sim::Scenario;
use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
use adaptive_gnss_ins::tools::scoring::SessionReport;
use adaptive_gnss_ins::tools::session::Session;

/// The scenario's seed (fixed: the comparison is one realization, as the paper's).
const SEED: u64 = 1;

fn run(variant: FilterVariant) -> SessionReport {
    run_with(variant, false)
}

fn run_with(variant: FilterVariant, correlation_aware: bool) -> SessionReport {
    let scenario = Scenario::builtin("default", SEED).unwrap();
    let mut config = Config::default();
    config.filter.variant = variant;
    config.adaptive.correlation_aware = correlation_aware;
    // The papers' estimators as they are: the σ compared is the estimate against the
    // environment's σ, which leaves out the slow atmosphere error that
    // adaptive.pseudorange_slow_sigma_m adds to R (tests/nees_open_sky.rs tests that).
    config.adaptive.pseudorange_slow_sigma_m = 0.0;
    // And their R as the estimators give it, not inflated for correlated errors
    // (gnss.error_correlation, tests/error_correlation.rs).
    config.gnss.error_correlation = false;
    let mut session = Session::new(config, 0.0, None);
    for input in scenario_inputs(&scenario) {
        session.push(input.unwrap());
    }
    assert_eq!(
        session.engine().divergence_resets(),
        0,
        "{variant:?}: a divergence reset on the default scenario"
    );
    session.finish()
}

#[test]
fn ermakf_family_on_the_default_scenario() {
    let variants = [
        FilterVariant::Ekf,
        FilterVariant::Eiakf,
        FilterVariant::Srmakf,
        FilterVariant::Ermakf,
    ];
    let mut rows = Vec::new();
    for v in variants {
        let report = run(v);
        let s = report.summary(f64::NEG_INFINITY);
        let foliage_sigma = report.sigma_rms_error_m("foliage");
        println!(
            "{:<7} pos3d {:.3} m  vel3d {:.4} m/s  yaw {:.3} deg  NEES {:.1}  \
             foliage sigma RMS error {:.3} m",
            v.as_str(),
            s.pos_rmse_3d_m,
            s.vel_rmse_3d_mps,
            s.att_rmse_yaw_deg,
            s.nees_mean,
            foliage_sigma
        );
        assert!(s.epochs > 3000, "{} scored epochs", s.epochs);
        rows.push((v, s, foliage_sigma));
    }
    let get = |v: FilterVariant| rows.iter().find(|r| r.0 == v).unwrap();
    let (ekf, ermakf, srmakf) = (
        get(FilterVariant::Ekf),
        get(FilterVariant::Ermakf),
        get(FilterVariant::Srmakf),
    );
    assert!(ermakf.1.pos_rmse_3d_m < ekf.1.pos_rmse_3d_m);
    assert!(ermakf.1.vel_rmse_3d_mps < ekf.1.vel_rmse_3d_mps);
    // Every adaptive estimate tracks the foliage noise better than the fixed model.
    assert!(srmakf.2 < ekf.2 && ermakf.2 < ekf.2);

    // The correlation-aware option: the foliage multipath (AR(2), ρ₁ ≈ 0.94) within a
    // fifth of its true σ, and closer to it than every estimator of the paper.
    let aware = run_with(FilterVariant::Srmakf, true);
    let mut ratios: Vec<f64> = aware
        .sigmas
        .iter()
        .filter(|s| s.environment == "foliage")
        .map(|s| s.estimated_sigma_m / s.true_sigma_m)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    let aware_error = aware.sigma_rms_error_m("foliage");
    println!(
        "srmakf, correlation-aware: pos3d {:.3} m, foliage σ/true median {median:.3}, RMS \
         error {aware_error:.3} m",
        aware.summary(f64::NEG_INFINITY).pos_rmse_3d_m
    );
    assert!(ratios.len() > 300, "{} foliage samples", ratios.len());
    assert!((median - 1.0).abs() < 0.2, "median σ ratio {median}");
    assert!(aware_error < srmakf.2 && aware_error < ermakf.2 && aware_error < ekf.2);
}

#[test]
#[ignore = "the paper's claim does not reproduce here; see the module documentation"]
fn ermakf_sigma_is_closer_to_the_truth_in_foliage_than_srmakf() {
    let ermakf = run(FilterVariant::Ermakf).sigma_rms_error_m("foliage");
    let srmakf = run(FilterVariant::Srmakf).sigma_rms_error_m("foliage");
    assert!(
        ermakf < srmakf,
        "foliage σ error: ermakf {ermakf} m, srmakf {srmakf} m"
    );
}
