//! The error-correlation judge (`gnss.error_correlation`) on the default drive (seed 1,
//! tightly coupled): foliage with AR(2) multipath on the pseudo-ranges and rates, then
//! an urban canyon with NLOS biases. Without the judge every variant takes those errors
//! for white noise and is over-confident (docs/results.md, "Correlated errors judged per
//! satellite"); with it, asserted for the EKF and SRMAKF: the canyon's NEES inside its
//! 95 % bounds on at least 90 % of the epochs (none without), the open sky's on at least
//! 90 % (issue 11's bound) and higher by at least 0.3, the foliage's on at least 80 %
//! (0.965 and 0.890 since the published covariance is at least what the correlated
//! satellites' excess gives the position; 0.438 and 0.375 before, 11 % before the C/N0
//! deficit weighed each obstructed satellite from its first epoch, 5 % without the
//! judge), the mean NEES at most half, the 3D RMSE at most 10 % above (this seed's
//! figures: docs/results.md), and the inflations counted.

use std::collections::BTreeMap;

use adaptive_gnss_ins::config::{Config, FilterVariant};
use adaptive_gnss_ins::eval::ErrorSummary;
use adaptive_gnss_ins::sim::Scenario;
use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
use adaptive_gnss_ins::tools::session::Session;

/// The scenario's seed (the one docs/results.md reports).
const SEED: u64 = 1;

struct Run {
    whole: ErrorSummary,
    by_environment: BTreeMap<String, ErrorSummary>,
    correlated: u64,
}

fn run(variant: FilterVariant, judge: bool) -> Run {
    let scenario = Scenario::builtin("default", SEED).unwrap();
    let mut config = Config::default();
    config.filter.variant = variant;
    config.gnss.error_correlation = judge;
    let mut session = Session::new(config, 0.0, None);
    for input in scenario_inputs(&scenario) {
        session.push(input.unwrap());
    }
    let correlated = session.engine().deweighted().correlated;
    let report = session.finish();
    let run = Run {
        whole: report.summary(0.0),
        by_environment: report.summary_by_environment(0.0),
        correlated,
    };
    let inside = |env: &str| run.by_environment[env].nees_in_bounds_95;
    println!(
        "{:<7} judge {judge:<5} 3D {:.3} m  mean NEES {:6.2}  inside 95 %: open sky {:.3}, \
         urban canyon {:.3}, foliage {:.3}; {} inflated",
        variant.as_str(),
        run.whole.pos_rmse_3d_m,
        run.whole.nees_mean,
        inside("open_sky"),
        inside("urban_canyon"),
        inside("foliage"),
        run.correlated,
    );
    run
}

#[test]
fn judged_correlated_errors_make_the_covariance_honest_where_they_persist() {
    for variant in [FilterVariant::Ekf, FilterVariant::Srmakf] {
        let name = variant.as_str();
        let judged = run(variant, true);
        let white = run(variant, false);
        let inside = |r: &Run, env: &str| r.by_environment[env].nees_in_bounds_95;
        assert!(
            judged.whole.epochs > 3000,
            "{name}: {}",
            judged.whole.epochs
        );
        assert!(judged.correlated > 0 && white.correlated == 0, "{name}");
        assert!(
            inside(&judged, "urban_canyon") >= 0.9 && inside(&white, "urban_canyon") < 0.1,
            "{name}: urban canyon {:.3} judged, {:.3} not",
            inside(&judged, "urban_canyon"),
            inside(&white, "urban_canyon")
        );
        assert!(
            inside(&judged, "open_sky") >= 0.9 && inside(&judged, "foliage") >= 0.8,
            "{name}: open sky {:.3}, foliage {:.3} inside",
            inside(&judged, "open_sky"),
            inside(&judged, "foliage")
        );
        assert!(
            inside(&judged, "open_sky") >= inside(&white, "open_sky") + 0.3,
            "{name}: open sky {:.3} judged, {:.3} not",
            inside(&judged, "open_sky"),
            inside(&white, "open_sky")
        );
        assert!(
            judged.whole.nees_mean <= 0.5 * white.whole.nees_mean,
            "{name}: mean NEES {:.2} judged, {:.2} not",
            judged.whole.nees_mean,
            white.whole.nees_mean
        );
        assert!(
            judged.whole.pos_rmse_3d_m <= 1.1 * white.whole.pos_rmse_3d_m,
            "{name}: 3D RMSE {:.3} m judged, {:.3} m not",
            judged.whole.pos_rmse_3d_m,
            white.whole.pos_rmse_3d_m
        );
    }
}
