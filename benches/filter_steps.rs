//! The filter's two hot steps: one IMU step (strapdown mechanization plus covariance
//! propagation) and one tightly-coupled update with 12 satellites (24 measurements); the
//! divergence monitor's step of a loosely-coupled epoch; and one IMU step of a running
//! filter whose heading is split into hypotheses.
//! Run with `cargo bench --bench filter_steps`; the README reports the numbers.

use adaptive_gnss_ins::config::{Config, FilterVariant};
use adaptive_gnss_ins::earth::{self, Llh};
use adaptive_gnss_ins::engine::divergence::{Disagreement, DivergenceMonitor};
use adaptive_gnss_ins::engine::heading_bank::HeadingBank;
use adaptive_gnss_ins::engine::update::{self, Pseudoranges};
use adaptive_gnss_ins::engine::{process_noise, Adaptation, FilterState};
use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::ins::error_state::{StateMatrix, StateVector, DP, PHI, WHEEL_SCALE};
use adaptive_gnss_ins::ins::{ImuSample, NavState};
use adaptive_gnss_ins::sim::constellation::{
    AtmosphereTruth, GpsConstellation, ObservationNoise, ReceiverTruth,
};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

fn running_state(p: Llh) -> FilterState {
    let q_nb = UnitQuaternion::from_euler_angles(0.01, -0.02, 0.8);
    let imu = ImuSample {
        t_s: 0.0,
        w_ib_b_rad_s: Vector3::new(0.001, -0.002, 0.05),
        f_ib_b_m_s2: Vector3::new(0.3, 0.1, 9.8),
    };
    FilterState {
        nav: NavState {
            t_s: 0.0,
            p,
            v_n: Vector3::new(10.0, 5.0, 0.0),
            q_nb,
        },
        gyro_bias_rad_s: Vector3::zeros(),
        gyro_markov_rad_s: Vector3::zeros(),
        accel_bias_m_s2: Vector3::zeros(),
        clock_bias_m: 100.0,
        clock_drift_mps: 1.0,
        wheel_scale_factor: 1.0,
        gyro_scale_error: Vector3::zeros(),
        accel_scale_error: Vector3::zeros(),
        // The default configuration: the optional scale-factor states inert.
        p: StateMatrix::from_diagonal(&StateVector::from_fn(|i, _| {
            if i < WHEEL_SCALE {
                1e-2
            } else {
                0.0
            }
        })),
        prev_increment: None,
        last_imu: imu,
        phase_anchor: None,
    }
}

/// A 12-satellite epoch seen from `p`: the first time (minute steps) with 12 or more
/// satellites above 5°, cut to 12.
fn epoch_12(p: &Llh) -> GnssEpoch {
    let constellation = GpsConstellation::augmented(2);
    let rx = ReceiverTruth {
        pos_ecef_m: earth::llh_to_ecef(p),
        vel_ecef_mps: Vector3::zeros(),
        clock_bias_m: 100.0,
        clock_drift_mps: 1.0,
    };
    let atmosphere = AtmosphereTruth {
        report_delays: true,
        ..AtmosphereTruth::vacuum()
    };
    let mut epoch = (0..1440)
        .map(|minute| {
            let t = minute as f64 * 60.0;
            let noise = |_| ObservationNoise::default();
            constellation.simulate_epoch(t, &rx, &atmosphere, 5f64.to_radians(), noise)
        })
        .find(|e| e.as_ref().is_ok_and(|e| e.satellites.len() >= 12))
        .expect("a time with 12 satellites in view")
        .expect("simulated epoch");
    epoch.satellites.truncate(12);
    epoch
}

fn imu_step(c: &mut Criterion) {
    let config = Config::default();
    let noise = process_noise(&config);
    let start = running_state(Llh::from_degrees(39.1, 117.2, 20.0));
    c.bench_function("imu_step_mechanization_and_covariance", |b| {
        let mut state = start.clone();
        let mut t = 0.0;
        b.iter(|| {
            t += 0.01;
            let mut next = state.last_imu;
            next.t_s = t;
            state.propagate(black_box(&next), &noise).expect("step");
        })
    });
}

fn tc_update(c: &mut Criterion) {
    let mut config = Config::default();
    config.gnss.innovation_gate_sigma = 0.0;
    config.gnss.elevation_mask_rad = 5f64.to_radians();
    let p = Llh::from_degrees(39.1, 117.2, 20.0);
    let epoch = epoch_12(&p);
    let start = running_state(p);
    let w = Vector3::zeros();
    let adaptation = Adaptation::new(&config);
    c.bench_function("tc_update_12_satellites", |b| {
        b.iter(|| {
            let mut state = start.clone();
            let mut adaptation = adaptation.clone();
            let mut model = Pseudoranges::new(black_box(&epoch), &w, &config);
            let report =
                update::apply(&mut state, &mut model, &mut adaptation, true).expect("update");
            assert_eq!(report.measurements_used, 24);
        })
    });
}

/// Noisy epochs of a static receiver, one per second.
fn noisy_epochs(p: &Llh, count: usize) -> Vec<GnssEpoch> {
    use rand_chacha::rand_core::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let constellation = GpsConstellation::augmented(2);
    let atmosphere = AtmosphereTruth {
        report_delays: true,
        ..AtmosphereTruth::vacuum()
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let unit = Normal::new(0.0, 1.0).expect("unit normal");
    let t0 = first_time_with_12(&constellation, p);
    (0..count)
        .map(|k| {
            let t = t0 + k as f64;
            let rx = ReceiverTruth {
                pos_ecef_m: earth::llh_to_ecef(p),
                vel_ecef_mps: Vector3::zeros(),
                clock_bias_m: 100.0 + t,
                clock_drift_mps: 1.0,
            };
            let mut noise = |_| ObservationNoise {
                pseudorange_m: 3.0 * unit.sample(&mut rng),
                pseudorange_rate_mps: 0.1 * unit.sample(&mut rng),
            };
            let mut e = constellation
                .simulate_epoch(t, &rx, &atmosphere, 5f64.to_radians(), &mut noise)
                .expect("simulated epoch");
            e.satellites.truncate(12);
            // Reported as a receiver does (u-blox `cno`), so that the judge's C/N0
            // deficit is weighed too (steady, no deficit).
            for s in &mut e.satellites {
                s.cn0_dbhz = Some(45.0);
            }
            e
        })
        .collect()
}

fn first_time_with_12(constellation: &GpsConstellation, p: &Llh) -> f64 {
    let rx = ReceiverTruth {
        pos_ecef_m: earth::llh_to_ecef(p),
        vel_ecef_mps: Vector3::zeros(),
        clock_bias_m: 0.0,
        clock_drift_mps: 0.0,
    };
    let atmosphere = AtmosphereTruth::vacuum();
    (0..1440)
        .map(|minute| minute as f64 * 60.0)
        .find(|&t| {
            constellation
                .simulate_epoch(t, &rx, &atmosphere, 5f64.to_radians(), |_| {
                    ObservationNoise::default()
                })
                .is_ok_and(|e| e.satellites.len() >= 14)
        })
        .expect("a time with 14 satellites in view")
}

/// The cost of one epoch in steady state (windows full, M = 100) for the plain EKF and the
/// adaptive variants: the difference is the adaptive step's added cost; and the EKF
/// without the error-correlation judge (`gnss.error_correlation`): the judge's cost.
fn tc_update_adaptive(c: &mut Criterion) {
    let p = Llh::from_degrees(39.1, 117.2, 20.0);
    let epochs = noisy_epochs(&p, 2000);
    let w = Vector3::zeros();
    for (variant, judged) in [
        (FilterVariant::Ekf, true),
        (FilterVariant::Ekf, false),
        (FilterVariant::Srmakf, true),
        (FilterVariant::Ermakf, true),
    ] {
        let mut config = Config::default();
        config.filter.variant = variant;
        config.gnss.error_correlation = judged;
        config.gnss.elevation_mask_rad = 5f64.to_radians();
        let mut state = running_state(p);
        let mut adaptation = Adaptation::new(&config);
        // Warm up: fill every window.
        for e in &epochs[..150] {
            let mut model = Pseudoranges::new(e, &w, &config);
            update::apply(&mut state, &mut model, &mut adaptation, true).expect("update");
        }
        let mut k = 150usize;
        let unjudged = if judged {
            ""
        } else {
            "_without_error_correlation"
        };
        let name = format!("tc_epoch_12_satellites_{}{unjudged}", variant.as_str());
        c.bench_function(&name, |b| {
            b.iter(|| {
                let laps = (k / epochs.len()) as f64;
                let mut e = epochs[k % epochs.len()].clone();
                e.t_s += laps * epochs.len() as f64;
                k += 1;
                let mut model = Pseudoranges::new(black_box(&e), &w, &config);
                update::apply(&mut state, &mut model, &mut adaptation, true).expect("update")
            })
        });
    }
}

/// The divergence monitor's step of one receiver fix: the prior's disagreement with it in
/// units of the combined σ, and the run of disagreeing epochs (here a divergence 3 m off
/// in a 1 σ covariance, the run growing on every call: the longest path).
fn divergence_monitor_step(c: &mut Criterion) {
    let p = Llh::from_degrees(39.1, 117.2, 20.0);
    let mut state = running_state(p);
    // A position σ of 0.5 m (latitude and longitude in radians).
    let rad2 = (0.5 / earth::SEMI_MAJOR_AXIS_M).powi(2);
    for (i, var) in [rad2, rad2, 0.25].into_iter().enumerate() {
        state.p[(DP + i, DP + i)] = var;
    }
    let config = Config::default();
    let fix = earth::enu_to_llh(&Vector3::new(3.0, -2.0, 1.0), &p).unwrap();
    let fix_covariance_enu_m2 = Matrix3::identity() * 0.36;
    let mut monitor = DivergenceMonitor::default();
    c.bench_function("divergence_monitor_step_loose", |b| {
        b.iter(|| {
            state.nav.t_s += 1.0;
            let d = Disagreement::of(
                black_box(&state),
                &fix,
                &fix_covariance_enu_m2,
                1.0,
                None,
                &config,
            );
            black_box(monitor.check(state.nav.t_s, Some(&d)))
        })
    });
}

/// One IMU step of a running filter whose heading σ of 20° split it into hypotheses
/// (13, 10° apart): every hypothesis' step and the moment matching of the state it
/// publishes.
fn heading_split_imu_step(c: &mut Criterion) {
    let config = Config::default();
    let noise = process_noise(&config);
    let mut running = running_state(Llh::from_degrees(39.1, 117.2, 20.0));
    running.p[(PHI + 2, PHI + 2)] = 20f64.to_radians().powi(2);
    let judges = Adaptation::new(&config).fix;
    let start = HeadingBank::split(&running, &config, &judges).expect("a split");
    assert_eq!(start.len(), 13);
    c.bench_function("heading_split_imu_step_13_hypotheses", |b| {
        let mut bank = start.clone();
        let mut next = running.last_imu;
        b.iter(|| {
            next.t_s += 0.01;
            bank.propagate(black_box(&next), &noise).expect("step");
        })
    });
}

criterion_group!(
    benches,
    imu_step,
    tc_update,
    tc_update_adaptive,
    divergence_monitor_step,
    heading_split_imu_step
);
criterion_main!(benches);
