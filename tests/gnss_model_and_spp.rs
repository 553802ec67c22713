//! The GNSS measurement model and the single-point solution against the simulated
//! constellation: the model's prediction at the true state must reproduce the simulated
//! (noise-free) observations, and SPP must recover the true state from them.

use adaptive_gnss_ins::earth::{llh_to_ecef, rot_ecef_to_enu, Llh};
use adaptive_gnss_ins::gnss::geometry::predict;
use adaptive_gnss_ins::gnss::spp::{solve_spp, Exclusion, SppConfig, SppError};
use adaptive_gnss_ins::gnss::{GnssEpoch, Klobuchar};
use adaptive_gnss_ins::sim::constellation::{
    AtmosphereTruth, GpsConstellation, ObservationNoise, ReceiverTruth,
};
use nalgebra::Vector3;

/// Error budgets of the noise-free checks.
const MAX_LOOP_PSEUDORANGE_ERR_M: f64 = 1e-3;
const MAX_LOOP_RATE_ERR_MPS: f64 = 1e-3;
const MAX_SPP_POS_ERR_M: f64 = 1e-3;
const MAX_SPP_CLOCK_ERR_M: f64 = 1e-3;
const MAX_SPP_VEL_ERR_MPS: f64 = 1e-3;
const MAX_SPP_DRIFT_ERR_MPS: f64 = 1e-3;

fn klobuchar() -> Klobuchar {
    Klobuchar {
        alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -1.1921e-7],
        beta: [1.1469e5, 0.0, -1.9661e5, -6.5536e4],
    }
}

/// A moving receiver with a drifting clock at a site.
fn truth(site: &Llh, k: usize) -> ReceiverTruth {
    let c = rot_ecef_to_enu(site).transpose();
    ReceiverTruth {
        pos_ecef_m: llh_to_ecef(site),
        vel_ecef_mps: c * Vector3::new(15.0 - 3.0 * k as f64, 22.0, -0.5 + 0.2 * k as f64),
        clock_bias_m: 85_000.0 - 12_345.0 * k as f64,
        clock_drift_mps: -40.0 + 17.0 * k as f64,
    }
}

fn sites() -> Vec<Llh> {
    vec![
        Llh::from_degrees(45.0, 10.0, 250.0),
        Llh::from_degrees(40.0, -105.3, 1650.0),
        Llh::from_degrees(-33.9, 151.2, 40.0),
        Llh::from_degrees(64.1, -21.9, 10.0),
        Llh::from_degrees(1.3, 103.8, 15.0),
    ]
}

const TIMES_S: [f64; 5] = [0.0, 3_600.0, 20_000.0, 43_200.0, 80_000.0];

fn noise_free_epoch(
    c: &GpsConstellation,
    t_s: f64,
    rx: &ReceiverTruth,
    atmosphere: &AtmosphereTruth,
) -> GnssEpoch {
    c.simulate_epoch(t_s, rx, atmosphere, 5f64.to_radians(), |_| {
        ObservationNoise::default()
    })
    .unwrap()
}

#[test]
fn prediction_at_the_true_state_reproduces_simulated_observations() {
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(klobuchar());
    let (mut worst_pr, mut worst_rate, mut count) = (0.0f64, 0.0f64, 0);
    for site in sites() {
        for (k, &t) in TIMES_S.iter().enumerate() {
            let rx = truth(&site, k);
            let epoch = noise_free_epoch(&c, t, &rx, &atmosphere);
            for obs in &epoch.satellites {
                let p = predict(
                    obs,
                    &rx.pos_ecef_m,
                    &rx.vel_ecef_mps,
                    rx.clock_bias_m,
                    rx.clock_drift_mps,
                    epoch.klobuchar.as_ref(),
                    epoch.gps_time_of_week_s,
                )
                .unwrap();
                assert!(p.iono_m > 0.0 && p.tropo_m > 1.5);
                worst_pr = worst_pr.max((obs.pseudorange_m.unwrap() - p.pseudorange_m).abs());
                let rate = obs.pseudorange_rate_mps.unwrap();
                worst_rate = worst_rate.max((rate - p.pseudorange_rate_mps).abs());
                count += 1;
            }
        }
    }
    println!("loop closure over {count} observations: pseudo-range {worst_pr:.3e} m, rate {worst_rate:.3e} m/s");
    assert!(count > 150);
    assert!(worst_pr < MAX_LOOP_PSEUDORANGE_ERR_M, "{worst_pr}");
    assert!(worst_rate < MAX_LOOP_RATE_ERR_MPS, "{worst_rate}");
}

#[test]
fn spp_recovers_the_true_state_from_noise_free_observations() {
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(klobuchar());
    let config = SppConfig::default();
    let (mut pos_err, mut clk_err, mut vel_err, mut drift_err) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut max_iterations = 0;
    for site in sites() {
        for (k, &t) in TIMES_S.iter().enumerate() {
            let rx = truth(&site, k);
            let epoch = noise_free_epoch(&c, t, &rx, &atmosphere);
            let sol = solve_spp(&epoch, &config).unwrap();
            assert!(sol.num_used >= 4);
            assert!(sol
                .excluded
                .iter()
                .all(|e| matches!(e.reason, Exclusion::BelowMask { .. })));
            assert!(sol.dop.pdop > 0.5 && sol.dop.pdop < 10.0, "{:?}", sol.dop);
            assert!(sol.dop.gdop > sol.dop.pdop);
            pos_err = pos_err.max((sol.pos_ecef_m - rx.pos_ecef_m).norm());
            clk_err = clk_err.max((sol.clock_bias_m - rx.clock_bias_m).abs());
            assert!((sol.pos_llh.height_m - site.height_m).abs() < MAX_SPP_POS_ERR_M);
            let v = sol.velocity.as_ref().unwrap();
            assert_eq!(v.num_used, sol.num_used);
            vel_err = vel_err.max((v.vel_ecef_mps - rx.vel_ecef_mps).norm());
            drift_err = drift_err.max((v.clock_drift_mps - rx.clock_drift_mps).abs());
            max_iterations = max_iterations.max(sol.iterations);
        }
    }
    println!(
        "SPP noise-free worst: position {pos_err:.3e} m, clock {clk_err:.3e} m, velocity \
         {vel_err:.3e} m/s, drift {drift_err:.3e} m/s, iterations ≤ {max_iterations}"
    );
    assert!(pos_err < MAX_SPP_POS_ERR_M, "{pos_err}");
    assert!(clk_err < MAX_SPP_CLOCK_ERR_M, "{clk_err}");
    assert!(vel_err < MAX_SPP_VEL_ERR_MPS, "{vel_err}");
    assert!(drift_err < MAX_SPP_DRIFT_ERR_MPS, "{drift_err}");
}

/// Deterministic standard normal draws (64-bit LCG + Box-Muller), for the noisy tests.
struct Gaussian(u64);

impl Gaussian {
    fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

#[test]
fn spp_covariance_matches_the_error_spread_under_modelled_noise() {
    // Noise drawn with exactly the σ model of the solver: the normalized squared error
    // e' P⁻¹ e of (position, clock) is χ²(4) distributed, mean 4.
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(klobuchar());
    let config = SppConfig {
        outlier_threshold: None,
        ..SppConfig::default()
    };
    let site = Llh::from_degrees(45.0, 10.0, 250.0);
    let rx = truth(&site, 0);
    let mut gauss = Gaussian(42);
    let runs = 300;
    let mut nees_sum = 0.0;
    for i in 0..runs {
        let t = 300.0 * i as f64;
        // Elevations of this epoch, for the σ of each satellite.
        let clean = noise_free_epoch(&c, t, &rx, &atmosphere);
        let mut noisy = clean.clone();
        for obs in &mut noisy.satellites {
            let p = predict(
                obs,
                &rx.pos_ecef_m,
                &rx.vel_ecef_mps,
                rx.clock_bias_m,
                rx.clock_drift_mps,
                None,
                0.0,
            )
            .unwrap();
            let sigma = config.sigma.pseudorange_sigma_m(obs, Some(p.elevation_rad));
            obs.pseudorange_m = obs.pseudorange_m.map(|p| p + sigma * gauss.next());
        }
        let sol = solve_spp(&noisy, &config).unwrap();
        let e = nalgebra::Vector4::new(
            sol.pos_ecef_m[0] - rx.pos_ecef_m[0],
            sol.pos_ecef_m[1] - rx.pos_ecef_m[1],
            sol.pos_ecef_m[2] - rx.pos_ecef_m[2],
            sol.clock_bias_m - rx.clock_bias_m,
        );
        let p_inv = sol.covariance.try_inverse().unwrap();
        nees_sum += (e.transpose() * p_inv * e)[0];
    }
    let mean_nees = nees_sum / runs as f64;
    println!("mean NEES over {runs} epochs: {mean_nees:.3} (χ²(4) mean 4)");
    // Mean of 300 χ²(4) draws: σ = sqrt(8/300) ≈ 0.16; ±4σ.
    assert!((mean_nees - 4.0).abs() < 0.65, "{mean_nees}");
}

#[test]
fn spp_rejects_a_gross_outlier_and_keeps_the_truth() {
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(klobuchar());
    let site = Llh::from_degrees(45.0, 10.0, 250.0);
    let rx = truth(&site, 1);
    let mut epoch = noise_free_epoch(&c, 3_600.0, &rx, &atmosphere);
    let config = SppConfig::default();
    // Only satellites above the mask count for the outlier test; corrupt one of them.
    let clean = solve_spp(&epoch, &config).unwrap();
    assert!(clean.num_used >= 7, "{}", clean.num_used);
    let target = clean.residuals[2].sat;
    let obs = epoch
        .satellites
        .iter_mut()
        .find(|o| o.sat == target)
        .unwrap();
    obs.pseudorange_m = obs.pseudorange_m.map(|p| p + 150.0);
    let sol = solve_spp(&epoch, &config).unwrap();
    assert!(sol.excluded.iter().any(|e| e.sat == target
        && matches!(e.reason, Exclusion::Outlier { standardized_residual } if standardized_residual > 4.0)));
    assert_eq!(sol.num_used, clean.num_used - 1);
    assert!((sol.pos_ecef_m - rx.pos_ecef_m).norm() < MAX_SPP_POS_ERR_M);
    // Without the test the outlier drags the solution by metres.
    let off = SppConfig {
        outlier_threshold: None,
        ..config
    };
    let dragged = solve_spp(&epoch, &off).unwrap();
    assert!((dragged.pos_ecef_m - rx.pos_ecef_m).norm() > 5.0);
}

/// One wrong rate (a satellite velocity off by 3 km/s along the line of sight does
/// this) is excluded by the same w-test; without it the velocity is off by metres per
/// second.
#[test]
fn spp_rejects_a_gross_rate_outlier_and_keeps_the_true_velocity() {
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(klobuchar());
    let site = Llh::from_degrees(45.0, 10.0, 250.0);
    let rx = truth(&site, 1);
    let mut epoch = noise_free_epoch(&c, 3_600.0, &rx, &atmosphere);
    let config = SppConfig::default();
    let clean = solve_spp(&epoch, &config).unwrap();
    let clean_velocity = clean.velocity.as_ref().unwrap();
    assert!(clean_velocity.num_used >= 7, "{}", clean_velocity.num_used);
    assert!(clean_velocity.outliers.is_empty());
    let target = clean_velocity.residuals[2].0;
    let obs = epoch
        .satellites
        .iter_mut()
        .find(|o| o.sat == target)
        .unwrap();
    *obs.pseudorange_rate_mps.as_mut().unwrap() += 50.0;
    let velocity = solve_spp(&epoch, &config).unwrap().velocity.unwrap();
    assert_eq!(velocity.outliers.len(), 1);
    assert_eq!(velocity.outliers[0].0, target);
    assert!(velocity.outliers[0].1.abs() > 4.0);
    assert_eq!(velocity.num_used, clean_velocity.num_used - 1);
    assert!((velocity.vel_ecef_mps - rx.vel_ecef_mps).norm() < MAX_SPP_VEL_ERR_MPS);
    let off = SppConfig {
        outlier_threshold: None,
        ..config
    };
    let dragged = solve_spp(&epoch, &off).unwrap().velocity.unwrap();
    assert!((dragged.vel_ecef_mps - rx.vel_ecef_mps).norm() > 5.0);
}

#[test]
fn spp_reports_too_few_satellites_and_missing_rates() {
    let c = GpsConstellation::augmented(1);
    // No atmosphere, and the observations say so (delays reported as zero).
    let atmosphere = AtmosphereTruth {
        report_delays: true,
        ..AtmosphereTruth::vacuum()
    };
    let site = Llh::from_degrees(45.0, 10.0, 250.0);
    let rx = truth(&site, 0);
    let mut epoch = noise_free_epoch(&c, 0.0, &rx, &atmosphere);
    let config = SppConfig {
        elevation_mask_rad: 0.0,
        ..SppConfig::default()
    };
    // Rates absent: position still solved, velocity reports why not.
    for obs in &mut epoch.satellites {
        obs.pseudorange_rate_mps = None;
    }
    let sol = solve_spp(&epoch, &config).unwrap();
    assert!((sol.pos_ecef_m - rx.pos_ecef_m).norm() < MAX_SPP_POS_ERR_M);
    assert_eq!(
        sol.velocity,
        Err(SppError::NotEnoughSatellites {
            usable: 0,
            required: 4
        })
    );
    // A corrupt satellite is excluded, not fatal.
    epoch.satellites[0].pseudorange_m = Some(f64::NAN);
    let sol = solve_spp(&epoch, &config).unwrap();
    assert!(matches!(sol.excluded[0].reason, Exclusion::Invalid(_)));
    assert!((sol.pos_ecef_m - rx.pos_ecef_m).norm() < MAX_SPP_POS_ERR_M);
    // Three satellites: typed error.
    epoch.satellites.truncate(4);
    assert_eq!(
        solve_spp(&epoch, &config),
        Err(SppError::NotEnoughSatellites {
            usable: 3,
            required: 4
        })
    );
}

#[test]
fn spp_applies_the_elevation_mask_and_uses_a_supplied_guess() {
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(klobuchar());
    let site = Llh::from_degrees(40.0, -105.3, 1650.0);
    let rx = truth(&site, 2);
    // Simulated down to 0°, solved with a 15° mask.
    let epoch = c
        .simulate_epoch(20_000.0, &rx, &atmosphere, 0.0, |_| {
            ObservationNoise::default()
        })
        .unwrap();
    let config = SppConfig {
        elevation_mask_rad: 15f64.to_radians(),
        ..SppConfig::default()
    };
    let sol = solve_spp(&epoch, &config).unwrap();
    let masked = sol
        .excluded
        .iter()
        .filter(|e| matches!(e.reason, Exclusion::BelowMask { elevation_rad } if elevation_rad < 15f64.to_radians()))
        .count();
    assert!(masked >= 1);
    assert_eq!(masked + sol.num_used, epoch.satellites.len());
    assert!(sol
        .residuals
        .iter()
        .all(|r| r.elevation_rad.unwrap() >= 15f64.to_radians()));
    assert!((sol.pos_ecef_m - rx.pos_ecef_m).norm() < MAX_SPP_POS_ERR_M);
    // From a guess 1 km away it converges in fewer iterations than from the centre.
    let guessed = SppConfig {
        initial_position_ecef_m: Some(rx.pos_ecef_m + Vector3::new(700.0, -500.0, 500.0)),
        ..config
    };
    let from_guess = solve_spp(&epoch, &guessed).unwrap();
    assert!(from_guess.iterations < sol.iterations);
    assert!((from_guess.pos_ecef_m - rx.pos_ecef_m).norm() < MAX_SPP_POS_ERR_M);
    // Invalid configuration is a typed error.
    let bad = SppConfig {
        convergence_m: 0.0,
        ..config
    };
    assert!(matches!(
        solve_spp(&epoch, &bad),
        Err(SppError::InvalidConfig { .. })
    ));
}
