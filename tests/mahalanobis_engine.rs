//! The Mahalanobis test of the IARF schemes through the whole engine on clean data: its
//! false-alarm rate must match the configured confidence within ±1 percentage point over
//! 10⁵ epochs (issue 6). tests/iarf_math.rs checks the gate alone on exact Gaussian
//! innovations; here the innovation covariance is the engine's own, so the test also
//! checks that the filter's covariance is consistent with its errors.
//!
//! Set-up, chosen to be cheap and correctly modelled: a receiver at rest, loosely coupled
//! (the fix is position and velocity, m = 6), the IMU corrupted by the simulator's default
//! error model (the paper-grade IMU the configuration describes; its constant biases and
//! Gauss-Markov drifts lie within the filter's model, which is somewhat conservative on the
//! drifts), fixes with white ENU noise of exactly the configured σ (1.5, 1.5, 3 m; 0.1 m/s).
//! The IMU runs at 20 Hz and the fixes at 10 Hz, so that 10⁵ epochs are 2.8 hours of data
//! and run in seconds; the heading is given, since it is not observable at rest.

mod support;

use adaptive_gnss_ins::config::{Config, Coupling, FilterVariant};
use adaptive_gnss_ins::earth;
use adaptive_gnss_ins::engine::{Engine, GnssFix, Output};
use adaptive_gnss_ins::sim::{ImuErrorModel, ImuErrorSpec};
use nalgebra::Vector3;
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use support::{static_config, StaticScenario};

const IMU_RATE_HZ: f64 = 20.0;
/// IMU samples per fix (fixes at 10 Hz).
const IMU_PER_FIX: usize = 2;
/// Epochs left out at the start, while the filter converges from its initial σ (s of data:
/// 60).
const SETTLING_EPOCHS: usize = 600;

/// Mahalanobis alarms among `epochs` tested epochs after settling, for `variant`.
fn alarm_rate(variant: FilterVariant, confidence: f64, epochs: usize, seed: u64) -> (f64, f64) {
    let mut scenario = StaticScenario::new(seed);
    scenario.imu_rate_hz = IMU_RATE_HZ;
    let mut config: Config = static_config(scenario.q_nb.euler_angles().2);
    config.filter.variant = variant;
    config.filter.coupling = Coupling::Loose;
    config.robust.chi2_confidence = confidence;
    // The paper's filters take each fix whole. With the product's deweighting of a fix
    // beyond χ²(3)'s 95 % quantile (`loose.fix_outlier_sigma`, 2.8) akf_partial's χ²₆ test
    // at 95 % sees those fixes at the bound and alarmed on 2.3 % of clean epochs (mean M²
    // 5.77): the rate then measures the deweighting, not the filter's consistency.
    config.loose.fix_outlier_sigma = 0.0;
    let sigma_enu_m = Vector3::new(
        config.loose.fix_sigma_horizontal_m,
        config.loose.fix_sigma_horizontal_m,
        config.loose.fix_sigma_vertical_m,
    );
    let sigma_v_mps = config.loose.velocity_sigma_mps;
    let mut imu_errors = ImuErrorModel::new(&ImuErrorSpec::default(), IMU_RATE_HZ, seed).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed + 1000);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let mut engine = Engine::new(config);
    let (mut tested, mut alarms, mut d2_sum) = (0usize, 0usize, 0.0);
    let mut fixes = 0usize;
    let mut k = 0usize;
    while tested < epochs {
        let t = k as f64 / IMU_RATE_HZ;
        let imu = imu_errors.corrupt(&scenario.imu(t));
        let mut outputs = engine.push_imu(&imu).unwrap();
        if k % IMU_PER_FIX == 0 {
            let d_enu = sigma_enu_m.component_mul(&Vector3::from_fn(|_, _| unit.sample(&mut rng)));
            let v = Vector3::from_fn(|_, _| sigma_v_mps * unit.sample(&mut rng));
            let fix = GnssFix {
                t_s: t,
                position: earth::enu_to_llh(&d_enu, &scenario.position).unwrap(),
                position_covariance_enu_m2: None,
                velocity_enu_mps: Some(v),
                velocity_covariance_enu_m2_s2: None,
            };
            outputs.extend(engine.push_fix(fix).unwrap());
        }
        for o in outputs {
            if let Output::Epoch(report) = o {
                fixes += 1;
                if fixes > SETTLING_EPOCHS && report.mahalanobis_d2.is_finite() {
                    tested += 1;
                    d2_sum += report.mahalanobis_d2;
                    if report.mahalanobis_d2 > report.chi2_threshold {
                        alarms += 1;
                    }
                }
            }
        }
        k += 1;
        assert!(
            k < 4 * IMU_PER_FIX * (epochs + SETTLING_EPOCHS),
            "epochs not tested"
        );
    }
    assert!(engine.counters().iter().next().is_none(), "inputs rejected");
    (alarms as f64 / tested as f64, d2_sum / tested as f64)
}

/// Math note (tolerance): over n epochs the binomial standard error of the rate is
/// √(p(1 − p)/n): 0.069 percentage points at p = 0.05 and n = 10⁵, 0.031 at p = 0.01; the
/// issue's ±1 point is therefore about the filter's consistency (a 5 % error in the scale of
/// the innovation covariance moves the 95 % rate of χ²₆ by about 1.1 points), not sampling.
#[test]
fn engine_mahalanobis_false_alarm_rate_matches_the_confidence_over_1e5_epochs() {
    for (variant, confidence, seed) in [
        (FilterVariant::AkfPartial, 0.95, 1),
        (FilterVariant::Iarf, 0.99, 2),
    ] {
        let (rate, mean_d2) = alarm_rate(variant, confidence, 100_000, seed);
        println!(
            "{} at {confidence}: false-alarm rate {:.3} % (configured {:.1} %), mean M² {mean_d2:.3} \
             (χ²₆ mean 6)",
            variant.as_str(),
            100.0 * rate,
            100.0 * (1.0 - confidence)
        );
        assert!(
            (rate - (1.0 - confidence)).abs() <= 0.01,
            "{}: rate {rate}",
            variant.as_str()
        );
    }
}
