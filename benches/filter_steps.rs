//! The filter's two hot steps: one IMU step (strapdown mechanization plus covariance
//! propagation) and one tightly-coupled update with 12 satellites (24 measurements).
//! Run with `cargo bench --bench filter_steps`; the README reports the numbers.

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::earth::{self, Llh};
use adaptive_gnss_ins::engine::{process_noise, tight_update, Adaptation, FilterState};
use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::ins::error_state::StateMatrix;
use adaptive_gnss_ins::ins::{ImuSample, NavState};
use adaptive_gnss_ins::sim::constellation::{
    AtmosphereTruth, GpsConstellation, ObservationNoise, ReceiverTruth,
};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::{UnitQuaternion, Vector3};

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
        p: StateMatrix::identity() * 1e-2,
        prev_increment: None,
        last_imu: imu,
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
            let report = tight_update::update(
                &mut state,
                black_box(&epoch),
                &w,
                &config,
                &mut adaptation,
                true,
            )
            .expect("update");
            assert_eq!(report.measurements_used, 24);
        })
    });
}

criterion_group!(benches, imu_step, tc_update);
criterion_main!(benches);
