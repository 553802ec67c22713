//! Issue 11, item 5: every variant, loosely coupled, on a consumer-MEMS drive with a GNSS
//! outage and a street canyon whose receiver fixes are tens to hundreds of metres off at
//! times (tests/data/consumer_mems_drive.yaml, the short version of
//! tests/data/consumer_mems_hour.yaml), with the IMU noise of its class
//! (params/imu_consumer_mems.yaml). Before the fix, residual_akf learned the filter's own
//! drift as measurement noise after one bad fix and ran off (RMSE 181 m against the EKF's
//! 56 m on seed 1, largest error 421 m). The variants follow the canyon's bad fixes as the fixed-
//! noise EKF does; none may be much worse than it, none may give a non-finite solution.

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::FilterVariant;
use adaptive_gnss_ins::ros::node::params::config_from_files;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::compare::{compare_bag, NamedConfig};
use adaptive_gnss_ins::tools::simulate::{simulate, TRUTH_TOPIC};

/// Seed of the simulation.
const SEED: u64 = 1;
/// Largest ratio of a variant's 3D position RMSE to the fixed-noise EKF's on the drive.
/// Choice: an adaptive variant exists to do better than the EKF where the noise model is
/// wrong; 1.25 leaves room for the schemes that follow single bad fixes (akf_all by design
/// of the IARF paper's scheme 2) and fails on a divergence (residual_akf was 3.2×).
const MAX_RMSE_RATIO_TO_EKF: f64 = 1.25;
/// Largest ratio of a variant's largest 3D error to the EKF's: a bound against a run-off,
/// not a target. Every variant's largest error follows the canyon's worst fixes; akf_all,
/// whose adaptive factor takes a fix far from the prediction nearly whole, reaches 2.4×.
const MAX_ERROR_RATIO_TO_EKF: f64 = 3.0;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

#[test]
fn every_variant_loosely_coupled_stays_near_the_ekf_on_a_consumer_mems_drive() {
    let yaml = std::fs::read_to_string(repo("tests/data/consumer_mems_drive.yaml")).unwrap();
    let scenario = Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), SEED).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("drive.mcap");
    simulate(&scenario, &bag).unwrap();
    let base = config_from_files(&[
        repo("params/defaults.yaml"),
        repo("params/ekf_loose.yaml"),
        repo("params/imu_consumer_mems.yaml"),
    ])
    .unwrap();
    let variants = [
        FilterVariant::Ekf,
        FilterVariant::AkfAll,
        FilterVariant::AkfPartial,
        FilterVariant::Iarf,
        FilterVariant::ResidualAkf,
    ];
    let configs: Vec<NamedConfig> = variants
        .iter()
        .map(|&variant| NamedConfig::of_variant(&base, variant))
        .collect();
    let runs = compare_bag(&bag, &configs, TRUTH_TOPIC).unwrap();
    let scored: Vec<(String, f64, f64)> = runs
        .iter()
        .map(|(row, report)| {
            let max_error_m = report
                .errors
                .iter()
                .map(|(_, e)| e.position_enu_m.norm())
                .fold(
                    0.0,
                    |a: f64, e| if e.is_nan() { f64::NAN } else { a.max(e) },
                );
            println!(
                "{:<13} 3D RMSE {:8.3} m, largest 3D error {:8.2} m over {} epochs",
                row.filter,
                row.pos_rmse_3d_m,
                max_error_m,
                report.errors.len()
            );
            (row.filter.clone(), row.pos_rmse_3d_m, max_error_m)
        })
        .collect();
    let (_, ekf_rmse_m, ekf_max_m) = scored[0].clone();
    assert!(ekf_rmse_m.is_finite() && ekf_max_m.is_finite());
    for (name, rmse_m, max_m) in &scored {
        assert!(
            rmse_m.is_finite() && max_m.is_finite(),
            "{name}: a non-finite solution"
        );
        assert!(
            *rmse_m <= MAX_RMSE_RATIO_TO_EKF * ekf_rmse_m,
            "{name}: 3D RMSE {rmse_m:.3} m against the EKF's {ekf_rmse_m:.3} m"
        );
        assert!(
            *max_m <= MAX_ERROR_RATIO_TO_EKF * ekf_max_m,
            "{name}: largest 3D error {max_m:.2} m against the EKF's {ekf_max_m:.2} m"
        );
    }
}
