//! Issue 11's one-hour figure: every variant, loosely and tightly coupled, on the
//! consumer-MEMS hour (tests/data/consumer_mems_hour.yaml: three GNSS outages of 30–60 s,
//! foliage, a street canyon whose fixes carry single outliers of 70–360 m, 1 % pseudo-range
//! outliers over an open street), a car with the IMU noise of its class
//! (params/imu_consumer_mems.yaml) and `constraints.platform: car`, must stay within the
//! issue's bounds: 3D RMSE below 2.7 m (KF-GINS's figure on such a drive), the largest 3D
//! error below 30 m wherever a fix came within the last 30 s, no non-finite solution.
//! Checked on seed 1, tightly coupled on seeds 3 and 4, loosely coupled on seeds 2, 3 and
//! 4 and on seed 2 with the receiver's velocities (seed 2 tightly coupled meets them too,
//! 1.2–1.7 m by hand). Seed 3 with the receiver's velocities and no constraint checks
//! that a restart in the foliage is no less honest than no restart.
//!
//! Before `loose.fix_outlier_sigma` akf_all reached 8.6 m RMSE here (it took the canyon's
//! outliers nearly whole) and, without the platform's constraint, the divergence monitor
//! reset ekf, akf_partial and residual_akf six times in the canyon (12 m RMSE); numbers
//! in docs/results.md ("Consumer-MEMS hour").

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::{FilterVariant, VARIANTS};
use adaptive_gnss_ins::ros::node::params::config_from_files;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::compare::{compare_bag, ComparisonRow, NamedConfig};
use adaptive_gnss_ins::tools::scoring::SessionReport;
use adaptive_gnss_ins::tools::simulate::{simulate_with, SimulateOptions, TRUTH_TOPIC};

/// The bounds.
const MAX_RMSE_3D_M: f64 = 2.7;
const MAX_ERROR_3D_M: f64 = 30.0;
/// How long after the last fix an error still counts against [`MAX_ERROR_3D_M`] (s).
const FIX_WITHIN_S: f64 = 30.0;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The largest 3D error (m) among the solutions with a fix within [`FIX_WITHIN_S`]: an
/// outage's solutions count from its start for that long (the simulator names the
/// environment of each solution); NaN when any error is not finite.
fn largest_error_with_a_fix_m(report: &SessionReport) -> f64 {
    let mut outage_since_s: Option<f64> = None;
    let mut largest_m: f64 = 0.0;
    for (environment, error) in &report.errors {
        let norm_m = error.position_enu_m.norm();
        if !norm_m.is_finite() {
            return f64::NAN;
        }
        outage_since_s = match (environment.as_str(), outage_since_s) {
            ("outage", Some(start_s)) => Some(start_s),
            ("outage", None) => Some(error.t_s),
            _ => None,
        };
        if outage_since_s.is_none_or(|start_s| error.t_s - start_s <= FIX_WITHIN_S) {
            largest_m = largest_m.max(norm_m);
        }
    }
    largest_m
}

/// The hour simulated with `seed` into a bag in a temporary folder (kept alive by the
/// first).
fn hour_bag(seed: u64, options: SimulateOptions) -> (tempfile::TempDir, PathBuf) {
    let yaml = std::fs::read_to_string(repo("tests/data/consumer_mems_hour.yaml")).unwrap();
    let scenario = Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), seed).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("hour.mcap");
    simulate_with(&scenario, &bag, options).unwrap();
    (dir, bag)
}

/// Runs each of `variants` with `files` and the car's constraint over the hour simulated
/// with `seed` and asserts the bounds.
fn assert_the_hours_bounds(seed: u64, files: &[&str], variants: &[FilterVariant]) {
    assert_the_bounds(hour_bag(seed, SimulateOptions::default()), files, variants);
}

/// [`assert_the_hours_bounds`] on the hour `bag` (its folder kept alive with it).
fn assert_the_bounds(
    (_dir, bag): (tempfile::TempDir, PathBuf),
    files: &[&str],
    variants: &[FilterVariant],
) {
    for (row, report) in compare_in_a_car(&bag, files, variants) {
        let largest_m = largest_error_with_a_fix_m(&report);
        println!(
            "{:<13} 3D RMSE {:6.3} m, largest 3D error with a fix within {FIX_WITHIN_S} s {:6.2} m over {} epochs",
            row.filter,
            row.pos_rmse_3d_m,
            largest_m,
            report.errors.len()
        );
        assert!(report.errors.len() > 30_000, "{}", row.filter);
        assert!(
            row.pos_rmse_3d_m < MAX_RMSE_3D_M,
            "{}: 3D RMSE {:.3} m",
            row.filter,
            row.pos_rmse_3d_m
        );
        assert!(
            largest_m < MAX_ERROR_3D_M,
            "{}: largest 3D error {largest_m:.2} m",
            row.filter
        );
    }
}

/// Each of `variants` with `files` and the car's constraint over `bag`.
fn compare_in_a_car(
    bag: &Path,
    files: &[&str],
    variants: &[FilterVariant],
) -> Vec<(ComparisonRow, SessionReport)> {
    let files: Vec<PathBuf> = files.iter().map(|f| repo(f)).collect();
    let mut base = config_from_files(&files).unwrap();
    base.set_parameter("constraints.platform", "car").unwrap();
    let configs: Vec<NamedConfig> = variants
        .iter()
        .map(|&variant| NamedConfig::of_variant(&base, variant))
        .collect();
    compare_bag(bag, &configs, TRUTH_TOPIC).unwrap()
}

/// Seed 2 with the receiver's velocities (`/gnss/velocity`, as u-blox drivers publish
/// them): in the street canyon their NLOS Doppler put them 2–5σ (about 1 m/s) from a sound
/// filter's at every epoch, and the monitor took an epoch beyond 5σ for the filter's
/// velocity error and the fixes' 46 m leap for the filter's: every variant followed the
/// fixes, 18–20 m 3D RMSE at a mean NEES of 620–1100. A velocity error that cannot have
/// carried the filter half the leap in the time does not clear the fixes
/// (`divergence::VELOCITY_CARRY_SHARE`): 1.1–1.5 m (docs/results.md).
#[test]
fn every_variant_loosely_coupled_with_receiver_velocities_meets_the_hours_bounds_on_seed_2() {
    let velocity = SimulateOptions { velocity: true };
    assert_the_bounds(hour_bag(2, velocity), &LOOSE_FILES, &LOOSE_VARIANTS);
}

/// The χ²(9) 99.9 % quantile: a NEES of position, velocity and attitude beyond it is
/// confidently wrong.
const CHI2_9_Q999: f64 = 27.877;

/// Seed 3 with the receiver's velocities and no motion constraint: the monitor resets
/// akf_all at the foliage's start (910 s; its fixes 5–15 m off at a claimed 0.7 m), and
/// the restart and the heading bank that splits after it weighed the foliage's
/// velocities, metres per second off at a claimed 0.1 m/s, with fresh fix judges: the yaw
/// was then 30–177° off at a σ of 0.5–9° for 400 s, with two more resets (8.15 m 3D
/// RMSE, mean NEES 865). With the judges' verdicts kept across the reset and handed to
/// the bank's hypotheses, 4.16 m and 10.1 (docs/results.md). Asserted: the restarted
/// filter is confidently wrong (a NEES beyond the χ²(9) 99.9 % quantile) on no larger a
/// share of the epochs than the ekf, which the monitor does not reset there (akf_all
/// 3.5 %, 11.5 % before; ekf 4.4 %, nearly all of it the foliage's misclaimed fixes;
/// 0.72 % and 0.79 % since the published covariance holds what the fix judge finds
/// beyond the claims),
/// and that akf_all was reset: the reset is marginal (5.06σ on the monitor's fourth
/// epoch, where ekf stays at 4.82σ), and without one this test would not try a restart.
/// With the fixes deweighted beyond χ²(3)'s 95 % quantile (`loose.fix_outlier_sigma` 2.8,
/// the default since) akf_all is not reset here at all, which leaves no restart to judge:
/// the test keeps the former 5.
#[test]
fn a_restart_in_foliage_is_no_less_honest_than_no_restart_with_receiver_velocities_on_seed_3() {
    let (_dir, bag) = hour_bag(3, SimulateOptions { velocity: true });
    let files: Vec<PathBuf> = LOOSE_FILES.iter().map(|f| repo(f)).collect();
    let mut base = config_from_files(&files).unwrap();
    base.set_parameter("loose.fix_outlier_sigma", "5.0")
        .unwrap();
    let configs: Vec<NamedConfig> = [FilterVariant::AkfAll, FilterVariant::Ekf]
        .iter()
        .map(|&variant| NamedConfig::of_variant(&base, variant))
        .collect();
    let runs: Vec<(f64, u64)> = compare_bag(&bag, &configs, TRUTH_TOPIC)
        .unwrap()
        .iter()
        .map(|(row, report)| {
            let epochs = report.errors.len();
            let beyond = report.errors.iter().filter(|(_, e)| e.nees > CHI2_9_Q999);
            let share = beyond.count() as f64 / epochs as f64;
            println!(
                "{:<8} 3D RMSE {:.3} m, mean NEES {:.1}, {:.2} % of {epochs} epochs beyond \
                 {CHI2_9_Q999}, {} resets",
                row.filter,
                row.pos_rmse_3d_m,
                row.nees_mean,
                100.0 * share,
                row.divergence_resets
            );
            assert!(epochs > 30_000, "{}", row.filter);
            (share, row.divergence_resets)
        })
        .collect();
    let (shares, resets): (Vec<f64>, Vec<u64>) = runs.into_iter().unzip();
    assert!(resets[0] > 0, "akf_all was not reset: no restart was tried");
    assert!(
        shares[0] <= shares[1],
        "akf_all {:.2} % against ekf {:.2} %",
        100.0 * shares[0],
        100.0 * shares[1]
    );
}

/// The χ²(3) 99.9 % quantile, for the position's NEES alone.
const CHI2_3_Q999: f64 = 16.266;

/// The shares of the epochs in `environment` whose NEES, and whose position's NEES, are
/// beyond their χ² 99.9 % quantiles.
fn shares_beyond_q999(report: &SessionReport, environment: &str) -> (f64, f64) {
    let errors: Vec<_> = report
        .errors
        .iter()
        .filter(|(env, _)| env == environment)
        .map(|(_, e)| e)
        .collect();
    assert!(
        errors.len() > 1000,
        "{environment}: {} epochs",
        errors.len()
    );
    let share = |beyond: usize| beyond as f64 / errors.len() as f64;
    (
        share(errors.iter().filter(|e| e.nees > CHI2_9_Q999).count()),
        share(
            errors
                .iter()
                .filter(|e| e.position_nees > CHI2_3_Q999)
                .count(),
        ),
    )
}

/// Seed 3's foliage (900–1100 s), loosely coupled with the car: fixes 5–15 m off at a
/// claimed 0.7 m, their errors correlated over seconds. The filter weighed each at the
/// judge's scale as independent of the one before, followed their errors with typical
/// innovations, and published a covariance that the errors exceeded beyond the χ²(9)
/// 99.9 % quantile on 30–46 % of the foliage's epochs (the position alone beyond χ²(3)'s
/// on 29–34 %). With the covariance at least what the judge found beyond the claims
/// (`FixConsistency::unclaimed_covariance`), on 3–14 % (the position alone 0–1 %,
/// residual_akf's 7 %, whose judge weighs its own estimate of R rather than the claim);
/// the rest is the velocity and the attitude, which follow the fixes' correlated errors
/// too. With each fix deweighted beyond χ²(3)'s 95 % quantile (`loose.fix_outlier_sigma`
/// 2.8, was 5) they follow them less: 0–3 % (akf_all 2.65 %, iarf 3.00 %), the position
/// alone 0 %. Asserted: the measured shares, rounded up (an honest filter is near 0.1 %).
#[test]
fn every_variant_loosely_coupled_is_honest_in_the_foliage_on_seed_3() {
    let (_dir, bag) = hour_bag(3, SimulateOptions::default());
    for (row, report) in compare_in_a_car(&bag, &LOOSE_FILES, &LOOSE_VARIANTS) {
        let (all, position) = shares_beyond_q999(&report, "foliage");
        println!(
            "{:<13} of the foliage's epochs {:.2} % beyond {CHI2_9_Q999}, the position \
             {:.2} % beyond {CHI2_3_Q999}",
            row.filter,
            100.0 * all,
            100.0 * position
        );
        assert!(all < 0.05, "{}: {:.2} %", row.filter, 100.0 * all);
        assert!(position < 0.01, "{}: {:.2} %", row.filter, 100.0 * position);
    }
}

/// Seed 4's foliage (900–1100 s): fixes 10–15 m off in one direction for seconds, beyond
/// 5σ of their claimed 0.7 m but not of the 20–25-fold covariance the consistency judge
/// weighs them with. The monitor used to reset the sound filter there; the start in
/// motion took its heading from those fixes and the ekf ran off by kilometres (3D RMSE
/// 72.7 m, mean NEES 5737, docs/results.md). Then 7.6 m, most of it the street canyon's
/// biased fixes, which it followed; held back by their leap, 2.2–2.6 m, and with the
/// preset's accelerometer drift at a data sheet's rate 1.8–2.2 m.
#[test]
fn every_variant_loosely_coupled_meets_the_hours_bounds_on_seed_4() {
    assert_the_hours_bounds(4, &LOOSE_FILES, &LOOSE_VARIANTS);
}

/// Seed 4's street canyon (2000–2150 s) leaves five satellites or fewer, too few for the
/// error-correlation judge's parity fit; one of them, NLOS 10–16 m off, passed the gate
/// and pulled the tightly-coupled ekf 20–32 m off at a σ of 2 m (3D RMSE 5.60 m, mean
/// NEES 88, docs/results.md). Judged by its innovations it is deweighted: every variant
/// 1.4–1.8 m.
#[test]
fn every_variant_tightly_coupled_meets_the_hours_bounds_on_seed_4() {
    assert_the_hours_bounds(4, &TIGHT_FILES, &all_variants());
}

/// The loosely-coupled variants of the paper that are weighed in the hour.
const LOOSE_VARIANTS: [FilterVariant; 5] = [
    FilterVariant::Ekf,
    FilterVariant::AkfAll,
    FilterVariant::AkfPartial,
    FilterVariant::Iarf,
    FilterVariant::ResidualAkf,
];

const LOOSE_FILES: [&str; 3] = [
    "params/defaults.yaml",
    "params/ekf_loose.yaml",
    "params/imu_consumer_mems.yaml",
];

#[test]
fn every_variant_loosely_coupled_meets_the_hours_bounds() {
    assert_the_hours_bounds(1, &LOOSE_FILES, &LOOSE_VARIANTS);
}

/// Seed 2's street canyon (2000–2150 s): the fixes leap 46 m at once (NLOS reception) and
/// stay there, claiming 0.8 m. Every variant followed them and was then confidently wrong
/// by 30 m (16.8 m 3D RMS in the canyon, 7.3–7.6 m over the hour, mean NEES 79–93,
/// docs/results.md); held back by the leap (`loose.leap_hold_s`, src/engine/dispute.rs),
/// 1.9–2.0 m.
#[test]
fn every_variant_loosely_coupled_meets_the_hours_bounds_on_seed_2() {
    assert_the_hours_bounds(2, &LOOSE_FILES, &LOOSE_VARIANTS);
}

/// Seed 3's 60 s outage at 1500 s drifts the most. Its last fix before, 4.8σ off along
/// the track, passed `loose.fix_outlier_sigma` when it was 5 and set the velocity 0.13 m/s
/// and the pitch 0.05° off: 40 m at the outage's end, 2.2–3.8 m over the hour. Deweighted
/// beyond χ²(3)'s 95 % quantile (2.8), 2.2–2.7 m (docs/results.md).
#[test]
fn every_variant_loosely_coupled_meets_the_hours_bounds_on_seed_3() {
    assert_the_hours_bounds(3, &LOOSE_FILES, &LOOSE_VARIANTS);
}

#[test]
fn every_variant_tightly_coupled_meets_the_hours_bounds() {
    assert_the_hours_bounds(1, &TIGHT_FILES, &all_variants());
}

/// Seed 3's outages drift the most: a pitch that wandered with the accelerometer bias
/// made a "virtual slope" (59 m after the 60 s outage loosely coupled). With the preset's
/// drift at a data sheet's rate (100 h correlation time, not 10 h) every variant
/// tightly coupled is 1.9–2.2 m, where it was 2.3–2.7 m (docs/results.md).
#[test]
fn every_variant_tightly_coupled_meets_the_hours_bounds_on_seed_3() {
    assert_the_hours_bounds(3, &TIGHT_FILES, &all_variants());
}

const TIGHT_FILES: [&str; 2] = ["params/defaults.yaml", "params/imu_consumer_mems.yaml"];

fn all_variants() -> Vec<FilterVariant> {
    VARIANTS.iter().map(|spec| spec.variant).collect()
}
