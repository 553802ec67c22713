//! One bad IMU sample (issue 11, item 4): on the simulated drive of tests/engine_drive.rs,
//! a finite accelerometer sample of 1e6 m/s², a gyro sample of 1e10 rad/s and a lone
//! in-range spike of 8 g are dropped and counted, and the solution stays where the clean
//! run's is.

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::earth;
use adaptive_gnss_ins::engine::{Engine, Output, RejectionReason, StatusEvent};
use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::sim::constellation::GpsConstellation;
use adaptive_gnss_ins::sim::{ImuErrorModel, ImuErrorSpec, Trajectory};
use nalgebra::Vector3;
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;

mod support;
use support::drive::{drive, drive_epoch};

/// Largest distance between the solutions of the clean and the corrupted run (m): a
/// dropped sample makes one strapdown step span two sample periods.
const MAX_DIFFERENCE_M: f64 = 0.01;

/// The sample replacing the one at `t_s`, if any.
fn corrupt(s: &ImuSample) -> ImuSample {
    let at = |t: f64| (s.t_s - t).abs() < 1e-6;
    let mut bad = *s;
    if at(100.0) {
        bad.f_ib_b_m_s2[0] += 8.0 * 9.81;
    } else if at(150.0) {
        bad.w_ib_b_rad_s[2] = 1e10;
    } else if at(200.0) {
        bad.f_ib_b_m_s2 = Vector3::new(1e6, 0.0, 0.0);
    }
    bad
}

/// The solutions once per second (half-way between the GNSS epochs) after the filter
/// started, and the engine.
fn run(corrupted: bool) -> (Vec<(f64, earth::Llh)>, Engine) {
    let trajectory = Trajectory::new(&drive(1)).unwrap();
    let imu_rate_hz = 100.0;
    let mut imu_errors = ImuErrorModel::new(&ImuErrorSpec::default(), imu_rate_hz, 42).unwrap();
    let constellation = GpsConstellation::augmented(1);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut engine = Engine::new(Config::default());
    let mut solutions = Vec::new();
    for truth in trajectory.samples(imu_rate_hz).unwrap() {
        let t = truth.nav.t_s;
        let measured = imu_errors.corrupt(&truth.imu);
        let sample = if corrupted {
            corrupt(&measured)
        } else {
            measured
        };
        let mut out = match engine.push_imu(&sample) {
            Ok(out) => out,
            Err(rejected) => {
                assert!(corrupted, "a clean sample rejected at {t} s: {rejected:?}");
                Vec::new()
            }
        };
        if (t - t.round()).abs() < 1e-9 {
            let epoch = drive_epoch(&constellation, &mut rng, &truth.nav);
            out.extend(engine.push_gnss(epoch).unwrap());
        }
        // Half-way between epochs: both runs have applied the same measurements.
        if ((t - 0.5) - (t - 0.5).round()).abs() < 1e-9 {
            if let Some(state) = engine.state() {
                solutions.push((t, state.nav.p));
            }
        }
        for o in out {
            assert!(
                !matches!(o, Output::Status(StatusEvent::Reset { .. })),
                "{o:?} at {t} s"
            );
        }
    }
    (solutions, engine)
}

#[test]
fn bad_imu_samples_are_dropped_counted_and_leave_the_solution_alone() {
    let (clean, clean_engine) = run(false);
    let (corrupted, engine) = run(true);
    assert_eq!(clean_engine.counters().total(), 0);
    let counters = engine.counters();
    assert_eq!(counters.count(RejectionReason::ImuOutOfRange), 2);
    assert_eq!(counters.count(RejectionReason::ImuInconsistent), 1);
    assert_eq!(counters.total(), 3);
    assert_eq!(clean.len(), corrupted.len());
    let worst_m = clean
        .iter()
        .zip(&corrupted)
        .map(|((t0, a), (t1, b))| {
            assert_eq!(t0, t1);
            earth::llh_to_enu(a, b).norm()
        })
        .fold(0.0, f64::max);
    println!(
        "{} solutions compared, largest difference {worst_m:.4} m",
        clean.len()
    );
    assert!(worst_m < MAX_DIFFERENCE_M, "{worst_m} m");
}
