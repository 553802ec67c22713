//! The IARF-paper schemes (ckf, akf_all, akf_partial, iarf) and Ding, Wang and Rizos'
//! residual R and Q scaling, run through the engine on a simulated drive (the open-sky
//! drive of tests/engine_drive.rs, repeated): loosely coupled as the IARF paper's two
//! cases, and tightly coupled.
//!
//! Case 1 is the clean simulation. Case 2 adds scattered outliers to the fixes: 5 % of the
//! fixes (drawn with a fixed seed) get an error on every ENU axis of random sign and a size
//! uniform in [3, 10] m, 6 to 20 times the fixes' σ of 0.5 m.
//!
//! Every run prints its numbers; the assertions are the claims of the papers that the
//! issue asks for, as they were measured (see the report of the branch for what did not
//! reproduce).

use adaptive_gnss_ins::config::{Config, Coupling, FilterVariant};
use adaptive_gnss_ins::earth;
use adaptive_gnss_ins::engine::{Engine, EpochReport, GnssFix, Output, StatusEvent};
use adaptive_gnss_ins::sim::constellation::GpsConstellation;
use adaptive_gnss_ins::sim::{ImuErrorModel, ImuErrorSpec, Trajectory};

mod support;
use nalgebra::Vector3;
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, Uniform};
use support::drive::{drive, drive_epoch};

/// Scoring starts this long after the start-up (s).
const SETTLING_S: f64 = 60.0;
/// The IARF paper's fix σ (section 5): (0.5 m)² and (0.05 m/s)².
const FIX_SIGMA_M: f64 = 0.5;
const FIX_VELOCITY_SIGMA_MPS: f64 = 0.05;
/// Case 2: the share of fixes with an outlier and the range of its size per axis (m).
const OUTLIER_RATE: f64 = 0.05;
const OUTLIER_MIN_M: f64 = 3.0;
const OUTLIER_MAX_M: f64 = 10.0;

/// What one run measured.
#[derive(Debug, Default)]
struct Run {
    /// 3D position RMSE after settling (m).
    rmse_3d_m: f64,
    /// Per-axis (E, N, U) RMSE (m).
    rmse_enu_m: [f64; 3],
    epochs: usize,
    reports: Vec<EpochReport>,
    /// (time, Q scale) at every epoch.
    q_scales: Vec<(f64, f64)>,
}

impl Run {
    fn adaptive_factor_below_one(&self) -> f64 {
        let n = self
            .reports
            .iter()
            .filter(|r| r.adaptive_factor < 1.0)
            .count();
        n as f64 / self.reports.len().max(1) as f64
    }

    fn mahalanobis_alarms(&self) -> f64 {
        let tested: Vec<&EpochReport> = self
            .reports
            .iter()
            .filter(|r| r.mahalanobis_d2.is_finite())
            .collect();
        let n = tested
            .iter()
            .filter(|r| r.mahalanobis_d2 > r.chi2_threshold)
            .count();
        n as f64 / tested.len().max(1) as f64
    }
}

/// How the GNSS side of a run is simulated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Feed {
    /// Receiver fixes (loose coupling); `outliers`: case 2.
    Fixes { outliers: bool },
    /// Pseudo-ranges and rates (tight coupling).
    Ranges,
}

fn run(config: Config, laps: usize, feed: Feed) -> Run {
    let trajectory = Trajectory::new(&drive(laps)).unwrap();
    let imu_rate_hz = 100.0;
    let mut imu_errors = ImuErrorModel::new(&ImuErrorSpec::default(), imu_rate_hz, 42).unwrap();
    let constellation = GpsConstellation::augmented(1);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut outlier_rng = ChaCha8Rng::seed_from_u64(11);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let uniform = Uniform::new(0.0, 1.0).unwrap();
    let _ = env_logger::builder().is_test(true).try_init();
    let mut engine = Engine::new(config);
    let mut errors = Vec::new();
    let mut result = Run::default();
    let mut t_init = None;
    for truth in trajectory.samples(imu_rate_hz).unwrap() {
        let t = truth.nav.t_s;
        let measured = imu_errors.corrupt(&truth.imu);
        let mut outputs = engine.push_imu(&measured).unwrap();
        if (t - t.round()).abs() < 1e-9 {
            match feed {
                Feed::Fixes { outliers } => {
                    let mut d_enu = Vector3::from_fn(|_, _| FIX_SIGMA_M * unit.sample(&mut rng));
                    let v = truth.nav.v_n
                        + Vector3::from_fn(|_, _| FIX_VELOCITY_SIGMA_MPS * unit.sample(&mut rng));
                    if outliers && uniform.sample(&mut outlier_rng) < OUTLIER_RATE {
                        for x in d_enu.iter_mut() {
                            let size = OUTLIER_MIN_M
                                + (OUTLIER_MAX_M - OUTLIER_MIN_M)
                                    * uniform.sample(&mut outlier_rng);
                            *x += if uniform.sample(&mut outlier_rng) < 0.5 {
                                size
                            } else {
                                -size
                            };
                        }
                    }
                    let fix = GnssFix {
                        t_s: t,
                        position: earth::enu_to_llh(&d_enu, &truth.nav.p).unwrap(),
                        position_covariance_enu_m2: None,
                        velocity_enu_mps: Some(v),
                        velocity_covariance_enu_m2_s2: None,
                    };
                    outputs.extend(engine.push_fix(fix).unwrap());
                }
                Feed::Ranges => {
                    let epoch = drive_epoch(&constellation, &mut rng, &truth.nav);
                    outputs.extend(engine.push_gnss(epoch).unwrap());
                }
            }
            if let Some(state) = engine.state() {
                if t_init.is_some_and(|t0: f64| t - t0 >= SETTLING_S) {
                    errors.push(earth::llh_to_enu(&state.nav.p, &truth.nav.p));
                    result.q_scales.push((t, engine.q_scale()));
                }
            }
        }
        for o in outputs {
            match o {
                Output::Status(StatusEvent::Initialized { t_s, .. }) => t_init = Some(t_s),
                Output::Epoch(report) if t_init.is_some_and(|t0| report.t_s - t0 >= SETTLING_S) => {
                    result.reports.push(report)
                }
                _ => {}
            }
        }
    }
    assert!(t_init.is_some_and(|t0| t0 < 30.0), "start-up at {t_init:?}");
    assert_eq!(
        engine.divergence_resets(),
        0,
        "{}: a divergence reset on a drive that did not diverge",
        engine.variant_name()
    );
    let rejected: Vec<_> = engine.counters().iter().collect();
    assert!(
        rejected.is_empty(),
        "{}: rejected {rejected:?}",
        engine.variant_name()
    );
    let n = errors.len().max(1) as f64;
    let ms = |f: &dyn Fn(&Vector3<f64>) -> f64| errors.iter().map(f).sum::<f64>() / n;
    result.rmse_3d_m = ms(&|e| e.norm_squared()).sqrt();
    result.rmse_enu_m = [0, 1, 2].map(|i| ms(&|e| e[i] * e[i]).sqrt());
    result.epochs = errors.len();
    result
}

/// The IARF paper's loose set-up (params/iarf_loose.yaml) with another variant.
fn loose_config(variant: FilterVariant) -> Config {
    let mut config = Config::default();
    config.filter.variant = variant;
    config.filter.coupling = Coupling::Loose;
    config.loose.fix_sigma_horizontal_m = FIX_SIGMA_M;
    config.loose.fix_sigma_vertical_m = FIX_SIGMA_M;
    config.loose.velocity_sigma_mps = FIX_VELOCITY_SIGMA_MPS;
    // The paper's filters: no deweighting of outlying fixes by the engine (with it, on by
    // default, the plain CKF of case 2 is already at IARF's 0.271 m), the fixes'
    // covariance taken as given, and no hold of fixes that leap (which leaves a lone
    // outlier out while its leap awaits confirmation).
    config.loose.fix_outlier_sigma = 0.0;
    config.loose.fix_consistency = false;
    config.loose.leap_hold_s = 0.0;
    config
}

const SCHEMES: [FilterVariant; 4] = [
    FilterVariant::Ckf,
    FilterVariant::AkfAll,
    FilterVariant::AkfPartial,
    FilterVariant::Iarf,
];

fn print_run(label: &str, r: &Run) {
    println!(
        "{label:>24}: 3D RMSE {:.3} m (E {:.3}, N {:.3}, U {:.3}) over {} epochs; α < 1 on {:.1} %, \
         M² alarms on {:.1} %",
        r.rmse_3d_m,
        r.rmse_enu_m[0],
        r.rmse_enu_m[1],
        r.rmse_enu_m[2],
        r.epochs,
        100.0 * r.adaptive_factor_below_one(),
        100.0 * r.mahalanobis_alarms(),
    );
}

/// Case 1 of the IARF paper: every scheme runs and stays close to the plain CKF on clean
/// data (the paper's gains in case 1 come from model deviations of a real vehicle, which
/// the simulation does not have).
#[test]
fn iarf_case_1_loosely_coupled_clean_fixes() {
    let runs: Vec<Run> = SCHEMES
        .iter()
        .map(|v| run(loose_config(*v), 2, Feed::Fixes { outliers: false }))
        .collect();
    for (v, r) in SCHEMES.iter().zip(&runs) {
        print_run(&format!("case 1 {}", v.as_str()), r);
        assert!(r.epochs > 500);
        // Within the fix noise: √3 · 0.5 m is the RMSE of the fixes themselves.
        assert!(r.rmse_3d_m < 3f64.sqrt() * FIX_SIGMA_M, "{}", v.as_str());
    }
    // The Mahalanobis test on clean data raises alarms near its false-alarm rate.
    let partial = &runs[2];
    assert!(partial.mahalanobis_alarms() < 0.10);
}

/// Case 2 of the IARF paper: IARF below AKF-PARTIAL below both CKF and AKF-ALL in 3D RMSE
/// (section 5, table 3).
#[test]
fn iarf_case_2_loosely_coupled_fixes_with_outliers() {
    let runs: Vec<Run> = SCHEMES
        .iter()
        .map(|v| run(loose_config(*v), 2, Feed::Fixes { outliers: true }))
        .collect();
    for (v, r) in SCHEMES.iter().zip(&runs) {
        print_run(&format!("case 2 {}", v.as_str()), r);
    }
    let [ckf, all, partial, iarf] = [0, 1, 2, 3].map(|i| runs[i].rmse_3d_m);
    assert!(iarf < partial, "iarf {iarf} vs akf_partial {partial}");
    assert!(partial < ckf, "akf_partial {partial} vs ckf {ckf}");
    assert!(partial < all, "akf_partial {partial} vs akf_all {all}");
}

/// The robust and adaptive parts on the EKF base behave as on the CKF base in case 2.
#[test]
fn iarf_on_the_ekf_base_resists_outliers() {
    let mut ekf_iarf = loose_config(FilterVariant::Iarf);
    ekf_iarf.filter.base = adaptive_gnss_ins::config::FilterBase::Ekf;
    let plain = run(
        loose_config(FilterVariant::Ekf),
        2,
        Feed::Fixes { outliers: true },
    );
    let robust = run(ekf_iarf, 2, Feed::Fixes { outliers: true });
    print_run("case 2 ekf", &plain);
    print_run("case 2 iarf on ekf", &robust);
    assert!(robust.rmse_3d_m < plain.rmse_3d_m);
}

/// The process noise multiplied by `factor` (all spectral densities).
fn with_q_factor(mut config: Config, factor: f64) -> Config {
    let k = factor.sqrt();
    config.imu.gyro_arw_rad_per_sqrt_s *= k;
    config.imu.gyro_markov_sigma_rad_s *= k;
    config.imu.accel_vrw_m_s_per_sqrt_s *= k;
    config.imu.accel_bias_sigma_m_s2 *= k;
    config.clock.bias_noise_m_per_sqrt_s *= k;
    config.clock.drift_noise_m_s_per_sqrt_s *= k;
    config
}

/// Ding, Wang and Rizos' claims on `feed` from the tuned configuration `tuned_config`:
/// with Q 10× too small or too large the Q-scaled EKF stays within 20 % of the tuned EKF's
/// position RMSE while the untuned EKF does not (at least once); with Q right the scale
/// settles near 1 (their figure 3). Prints every number before asserting.
fn ding_claims(tuned_config: Config, feed: Feed, laps: usize) {
    let label = match feed {
        Feed::Ranges => "tight",
        Feed::Fixes { .. } => "loose",
    };
    let tuned = run(tuned_config.clone(), laps, feed);
    print_run(&format!("{label} tuned ekf"), &tuned);
    let mut scaled_right = tuned_config.clone();
    scaled_right.filter.q_scaling = true;
    let right = run(scaled_right.clone(), laps, feed);
    print_run(&format!("{label} q_scaling, Q right"), &right);
    let scales: Vec<f64> = right.q_scales.iter().map(|(_, s)| *s).collect();
    let last = *scales.last().unwrap();
    println!(
        "{label} Q right: scale at the end {last:.3}, min {:.3}, max {:.3}",
        scales.iter().cloned().fold(f64::INFINITY, f64::min),
        scales.iter().cloned().fold(0.0, f64::max)
    );
    let mut untuned_outside = 0;
    let mut scaled_ratios = Vec::new();
    for factor in [0.1, 10.0] {
        let untuned = run(with_q_factor(tuned_config.clone(), factor), laps, feed);
        let scaled = run(with_q_factor(scaled_right.clone(), factor), laps, feed);
        print_run(&format!("{label} ekf, Q × {factor}"), &untuned);
        print_run(&format!("{label} q_scaling, Q × {factor}"), &scaled);
        let ratio = |r: &Run| r.rmse_3d_m / tuned.rmse_3d_m;
        println!(
            "{label} Q × {factor}: final scale {:.3} (ideal {:.3}); RMSE ratio to the tuned EKF: \
             untuned {:.3}, q_scaling {:.3}",
            scaled.q_scales.last().unwrap().1,
            1.0 / factor,
            ratio(&untuned),
            ratio(&scaled)
        );
        scaled_ratios.push((factor, ratio(&scaled)));
        if (ratio(&untuned) - 1.0).abs() > 0.2 {
            untuned_outside += 1;
        }
    }
    println!("{label}: untuned EKF outside ±20 % in {untuned_outside} of 2 cases");
    for (factor, r) in scaled_ratios {
        assert!(
            (r - 1.0).abs() <= 0.2,
            "{label} q_scaling, Q × {factor}: {r}"
        );
    }
    assert!(
        untuned_outside > 0,
        "{label}: the untuned EKF is within 20 % both times"
    );
    assert!(
        (0.5..=2.0).contains(&last),
        "{label} Q right: final scale {last}"
    );
}

/// Ding's claims tightly coupled. Do not reproduce (measured, see the branch report): with
/// Q right the scale falls to the floor 0.001 and the RMSE grows 1.46× (1.672 → 2.434 m);
/// with Q × 0.1 the scale ends at 0.022 and the RMSE is 3.0× the tuned one, while the
/// untuned EKF is 3 % better. With about nine pseudo-ranges of 3–17 m σ, tr R dominates
/// tr(d dᵀ) so much that the numerator of eq. (19) over 64 epochs is negative in a sizeable
/// share of the windows, where α is clamped to its floor: the scale random-walks downwards.
/// Kept as the claim, ignored so that the suite stays green; run with `--ignored`.
#[test]
#[ignore = "Ding's Q-scaling claims do not reproduce tightly coupled (see the doc comment)"]
fn ding_q_scaling_with_mis_set_process_noise() {
    ding_claims(Config::default(), Feed::Ranges, 4);
}

/// Ding's claims loosely coupled (their paper's set-up: position and velocity fixes), with
/// the fixes' σ of 0.5 m and 0.05 m/s modelled exactly.
///
/// Does not reproduce either (measured, 4 laps, 1135 scored epochs): tuned EKF 0.259 m;
/// with Q right the scale again ends at the floor 0.001 (RMSE 0.251 m); Q × 0.1: untuned
/// EKF 0.934× the tuned RMSE, q_scaling 1.169× with its scale at 0.040 (ideal 10); Q × 10:
/// untuned 1.048×, q_scaling 1.002× with its scale at 0.001 (ideal 0.1). q_scaling does
/// stay within 20 %, but so does the untuned EKF: with 1 Hz fixes of 0.5 m and this IMU,
/// the position error hardly depends on Q over two decades, and the eq. (19) ratio, whose
/// numerator subtracts tr R from the innovation power, falls below the predicted power
/// in most windows, so the scale keeps falling. Ignored like the tight test.
#[test]
#[ignore = "Ding's Q-scaling claims do not reproduce loosely coupled either (see the doc comment)"]
fn ding_q_scaling_loosely_coupled() {
    ding_claims(
        loose_config(FilterVariant::Ekf),
        Feed::Fixes { outliers: false },
        4,
    );
}

/// Every variant runs tightly coupled on the drive and stays within the open-sky budget of
/// tests/engine_drive.rs (horizontal 1.5 m, vertical 2.5 m).
#[test]
fn every_variant_tightly_coupled() {
    for variant in [
        FilterVariant::Ckf,
        FilterVariant::AkfAll,
        FilterVariant::AkfPartial,
        FilterVariant::Iarf,
        FilterVariant::ResidualAkf,
    ] {
        let mut config = Config::default();
        config.filter.variant = variant;
        let r = run(config, 1, Feed::Ranges);
        print_run(&format!("tight {}", variant.as_str()), &r);
        let horizontal = r.rmse_enu_m[0].hypot(r.rmse_enu_m[1]);
        assert!(horizontal < 1.5, "{}: {horizontal}", variant.as_str());
        assert!(r.rmse_enu_m[2] < 2.5, "{}", variant.as_str());
        let report = r.reports.last().unwrap();
        match variant {
            FilterVariant::Iarf => {
                assert!(report
                    .satellites
                    .iter()
                    .any(|s| s.robust_weight.is_finite()));
                assert!(report.mahalanobis_d2.is_finite() && report.chi2_threshold > 0.0);
            }
            FilterVariant::AkfAll => assert!(report.adaptive_factor > 0.0),
            _ => {}
        }
    }
}

/// The residual-based R loosely coupled: runs and learns (estimates in use).
#[test]
fn residual_akf_loosely_coupled() {
    let r = run(
        loose_config(FilterVariant::ResidualAkf),
        1,
        Feed::Fixes { outliers: false },
    );
    print_run("loose residual_akf", &r);
    assert!(r.rmse_3d_m < 3f64.sqrt() * FIX_SIGMA_M);
}

/// The IARF paper's two cases loosely coupled on the default simulated scenario (the
/// ERMAKF-like drive with foliage and buildings; the receiver-like fixes of `/gnss/fix`
/// with their own covariance): case 1 as simulated, case 2 with the same scattered
/// outliers as above (5 % of the fixes, 3–10 m per ENU axis, drawn with a fixed seed).
/// Returns the 3D position RMSE of ckf, akf_all, akf_partial and iarf.
fn default_scenario_loose(outliers: bool) -> [f64; 4] {
    use adaptive_gnss_ins::sim::Scenario;
    use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
    use adaptive_gnss_ins::tools::session::{Session, SessionInput};
    SCHEMES.map(|variant| {
        let scenario = Scenario::builtin("default", 1).unwrap();
        let mut config = Config::default();
        config.filter.variant = variant;
        config.filter.coupling = Coupling::Loose;
        let mut session = Session::new(config, 0.0, None);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let uniform = Uniform::new(0.0, 1.0).unwrap();
        for input in scenario_inputs(&scenario) {
            let input = match input.unwrap() {
                SessionInput::Fix(mut fix) if outliers => {
                    if uniform.sample(&mut rng) < OUTLIER_RATE {
                        let d_enu = Vector3::from_fn(|_, _| {
                            let size = OUTLIER_MIN_M
                                + (OUTLIER_MAX_M - OUTLIER_MIN_M) * uniform.sample(&mut rng);
                            if uniform.sample(&mut rng) < 0.5 {
                                size
                            } else {
                                -size
                            }
                        });
                        fix.position = earth::enu_to_llh(&d_enu, &fix.position).unwrap();
                    }
                    SessionInput::Fix(fix)
                }
                other => other,
            };
            session.push(input);
        }
        let s = session.finish().summary(f64::NEG_INFINITY);
        println!(
            "default scenario, loose, case {}: {:<12} 3D RMSE {:.3} m over {} epochs",
            if outliers { 2 } else { 1 },
            variant.as_str(),
            s.pos_rmse_3d_m,
            s.epochs
        );
        assert!(s.epochs > 3000, "{} scored epochs", s.epochs);
        s.pos_rmse_3d_m
    })
}

/// The IARF paper's case-2 ordering loosely coupled on the default scenario: IARF below
/// AKF-PARTIAL below both CKF and AKF-ALL in 3D RMSE; case 1 is printed beside it.
///
/// Does not reproduce (measured, seed 1): case 1 CKF 5.497, AKF-ALL 14.521, AKF-PARTIAL
/// 5.449, IARF 5.952 m; case 2 CKF 5.480, AKF-ALL 14.262, AKF-PARTIAL 5.439, IARF 6.048 m.
/// AKF-PARTIAL is below CKF and AKF-ALL as claimed, but IARF is above AKF-PARTIAL and CKF.
/// The scenario's fixes are single-point solutions whose error is metres of slowly varying
/// bias (foliage, NLOS, the unmodelled 1.2× ionosphere), not white noise of the configured
/// σ: the 3–10 m outliers hardly change anything (CKF 5.497 → 5.480 m), the double factor
/// down-weights fixes for their biases, and AKF-ALL's α < 1 on those biased fixes inflates
/// the prior at almost every epoch. On the test drive with white fix noise the ordering
/// holds (`iarf_case_2_loosely_coupled_fixes_with_outliers`). Kept as the claim, ignored so
/// that the suite stays green; run with `--ignored --nocapture`.
#[test]
#[ignore = "the IARF ordering does not reproduce on the default scenario (see the doc comment)"]
fn iarf_cases_on_the_default_scenario_loosely_coupled() {
    default_scenario_loose(false);
    let [ckf, all, partial, iarf] = default_scenario_loose(true);
    assert!(iarf < partial, "iarf {iarf} vs akf_partial {partial}");
    assert!(partial < ckf, "akf_partial {partial} vs ckf {ckf}");
    assert!(partial < all, "akf_partial {partial} vs akf_all {all}");
}
