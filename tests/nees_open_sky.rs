//! Is the covariance of the noise-estimating variants honest in open sky? Over the whole
//! simulated open-sky drive (400 s; white thermal range noise of 0.5-2 m and a slow
//! error: the 20 % of the ionosphere the broadcast model misses, 0.9-2.4 m per satellite
//! and constant over minutes), the NEES (position, velocity, attitude: 9 dof) on the
//! simulator's truth must lie inside its two-sided 95 % χ² bounds on at least 90 % of the
//! epochs for eiakf, srmakf, ermakf and residual_akf with the default parameters.
//!
//! Also asserted: with `adaptive.pseudorange_slow_sigma_m: 0` and `gnss.error_correlation:
//! false` (the papers' estimates used as they are) the same variants are over-confident,
//! inside on fewer than half of the epochs — the estimators learn the white part from
//! epoch differences and innovations, which do not see the slow part — and the defaults'
//! honesty costs at most 10 % of their 3D position RMSE. (With the judge left on, its
//! common scale makes up for part of the missing slow variance: eiakf's over-confident
//! run gained 1.558 → 1.540 m, 9.6 → 10.8 % below the defaults'.)

use adaptive_gnss_ins::config::{Config, FilterVariant};
use adaptive_gnss_ins::eval::ErrorSummary;
use adaptive_gnss_ins::sim::Scenario;
use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
use adaptive_gnss_ins::tools::session::Session;

/// The scenario's seed (the one docs/results.md reports).
const SEED: u64 = 1;

/// Scored from here: after the 20 s standing start and the estimators' 30-epoch warm-up.
const SCORED_FROM_S: f64 = 60.0;

/// Runs `variant` with the defaults, or as the papers have it (`papers`: no slow part, no
/// error-correlation judge).
fn run(variant: FilterVariant, papers: bool) -> ErrorSummary {
    let scenario = Scenario::builtin("open_sky", SEED).unwrap();
    let mut config = Config::default();
    config.filter.variant = variant;
    if papers {
        config.adaptive.pseudorange_slow_sigma_m = 0.0;
        config.gnss.error_correlation = false;
    }
    let mut session = Session::new(config, 0.0, None);
    for input in scenario_inputs(&scenario) {
        session.push(input.unwrap());
    }
    let summary = session.finish().summary(SCORED_FROM_S);
    println!(
        "{:<13} {:<9} pos3d {:.3} m  vertical {:.3} m  NEES mean {:6.2}  inside 95 % {:.3} of {} epochs",
        variant.as_str(),
        if papers { "papers'" } else { "defaults" },
        summary.pos_rmse_3d_m,
        summary.pos_rmse_u_m,
        summary.nees_mean,
        summary.nees_in_bounds_95,
        summary.epochs
    );
    summary
}

#[test]
fn estimating_variants_are_honest_in_open_sky() {
    let ekf = run(FilterVariant::Ekf, false);
    assert!(ekf.epochs > 1000, "{} epochs", ekf.epochs);
    assert!(ekf.nees_in_bounds_95 >= 0.9);
    for variant in [
        FilterVariant::Eiakf,
        FilterVariant::Srmakf,
        FilterVariant::Ermakf,
        FilterVariant::ResidualAkf,
    ] {
        let honest = run(variant, false);
        let papers = run(variant, true);
        let name = variant.as_str();
        assert!(
            honest.nees_in_bounds_95 >= 0.9,
            "{name}: NEES inside its 95 % bounds on {:.3} of the epochs",
            honest.nees_in_bounds_95
        );
        assert!(
            papers.nees_in_bounds_95 < 0.5,
            "{name} as the papers have it: {:.3}",
            papers.nees_in_bounds_95
        );
        assert!(
            honest.pos_rmse_3d_m <= 1.1 * papers.pos_rmse_3d_m,
            "{name}: 3D RMSE {:.3} m against {:.3} m",
            honest.pos_rmse_3d_m,
            papers.pos_rmse_3d_m
        );
    }
}
