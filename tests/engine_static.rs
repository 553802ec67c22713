//! The engine on a receiver at rest: start-up and convergence, and every kind of bad input
//! (a typed error or a counted rejection; the engine keeps running and never holds a NaN).

mod support;

use adaptive_gnss_ins::earth;
use adaptive_gnss_ins::engine::{
    Engine, Output, RejectionReason, ResetReason, SatRejection, StatusEvent,
};
use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::ins::error_state::ACC_BIAS;
use nalgebra::{UnitQuaternion, Vector3};
use support::{static_config, StaticScenario};

/// Position error budget of a static receiver after a minute of 1 Hz GNSS with 3 m zenith
/// noise and about 9 satellites: the filter's own σ is then about 0.7, 1.1 and 1.9 m (E, N,
/// U; its clock and accelerometer process noise keep it from averaging every epoch), 2.3 m
/// in 3D, and the budget is three times that.
const MAX_STATIC_POSITION_ERR_M: f64 = 7.0;
/// The 99.9 % quantile of χ² with 3 degrees of freedom: the position error measured in the
/// filter's own covariance must stay below it.
const CHI2_3DOF_999: f64 = 16.27;

struct Run {
    scenario: StaticScenario,
    engine: Engine,
    outputs: Vec<Output>,
}

impl Run {
    fn new(seed: u64) -> Self {
        let scenario = StaticScenario::new(seed);
        let yaw = scenario.q_nb.euler_angles().2;
        Self {
            scenario,
            engine: Engine::new(static_config(yaw)),
            outputs: Vec::new(),
        }
    }

    /// Feeds IMU and 1 Hz GNSS over [t0, t1).
    fn run(&mut self, t0_s: f64, t1_s: f64) {
        let dt = 1.0 / self.scenario.imu_rate_hz;
        let n = ((t1_s - t0_s) / dt).round() as usize;
        for k in 0..n {
            let t = t0_s + k as f64 * dt;
            let out = self.engine.push_imu(&self.scenario.imu(t)).unwrap();
            self.outputs.extend(out);
            if (t - t.round()).abs() < 1e-9 {
                let epoch = self.scenario.gnss(t);
                self.outputs.extend(self.engine.push_gnss(epoch).unwrap());
            }
            self.assert_finite();
        }
    }

    fn assert_finite(&self) {
        if let Some(s) = self.engine.state() {
            assert!(s.is_finite(), "state holds a non-finite value: {s:?}");
        }
    }

    /// The error is within the budget and consistent with the filter's own covariance.
    fn assert_position_ok(&self) {
        let s = self.engine.state().expect("running");
        let e = earth::llh_to_enu(&s.nav.p, &self.scenario.position);
        let p = s.solution().position_covariance_enu_m2();
        let nees = e.dot(&(p.try_inverse().unwrap() * e));
        assert!(
            e.norm() < MAX_STATIC_POSITION_ERR_M,
            "position error {e:?} m"
        );
        assert!(
            nees < CHI2_3DOF_999,
            "position NEES {nees}: error {e:?}, covariance {p:?}"
        );
    }
}

#[test]
fn static_receiver_starts_and_converges() {
    let mut run = Run::new(1);
    run.run(0.0, 60.0);
    let initialized = run
        .outputs
        .iter()
        .filter(|o| matches!(o, Output::Status(StatusEvent::Initialized { .. })))
        .count();
    assert_eq!(initialized, 1);
    run.assert_position_ok();
    let s = run.engine.state().unwrap();
    assert!(s.nav.v_n.norm() < 0.1, "velocity {:?}", s.nav.v_n);
    let clock_truth = run.scenario.clock_bias_m + run.scenario.clock_drift_mps * 59.99;
    assert!(
        (s.clock_bias_m - clock_truth).abs() < 5.0,
        "clock {} vs {clock_truth}",
        s.clock_bias_m
    );
    assert!((s.clock_drift_mps - run.scenario.clock_drift_mps).abs() < 0.2);
    let epochs = run
        .outputs
        .iter()
        .filter(|o| matches!(o, Output::Epoch(_)))
        .count();
    assert!(epochs >= 55, "{epochs} epoch reports");
    assert_eq!(run.engine.counters().total(), 0);
}

#[test]
fn non_finite_imu_fields_are_rejected_and_counted() {
    let mut run = Run::new(2);
    run.run(0.0, 5.0);
    for (field, value) in [(0, f64::NAN), (1, f64::INFINITY), (2, f64::NEG_INFINITY)] {
        let mut s = run.scenario.imu(5.0 + field as f64 * 0.001);
        s.w_ib_b_rad_s[field] = value;
        let err = run.engine.push_imu(&s).unwrap_err();
        assert_eq!(err.reason, RejectionReason::ImuNotFinite);
        let mut s = run.scenario.imu(5.0);
        s.f_ib_b_m_s2[field] = value;
        assert_eq!(
            run.engine.push_imu(&s).unwrap_err().reason,
            RejectionReason::ImuNotFinite
        );
    }
    let mut s = run.scenario.imu(5.0);
    s.t_s = f64::NAN;
    assert_eq!(
        run.engine.push_imu(&s).unwrap_err().reason,
        RejectionReason::ImuNotFinite
    );
    assert_eq!(
        run.engine.counters().count(RejectionReason::ImuNotFinite),
        7
    );
    run.run(5.0, 60.0);
    run.assert_position_ok();
}

#[test]
fn duplicate_and_backward_imu_stamps_are_rejected() {
    let mut run = Run::new(3);
    run.run(0.0, 5.0);
    let last = run.engine.last_imu_t_s().unwrap();
    let dup = run.scenario.imu(last);
    assert_eq!(
        run.engine.push_imu(&dup).unwrap_err().reason,
        RejectionReason::ImuDuplicate
    );
    let back = run.scenario.imu(last - 0.5);
    assert_eq!(
        run.engine.push_imu(&back).unwrap_err().reason,
        RejectionReason::ImuOutOfOrder
    );
    assert_eq!(run.engine.last_imu_t_s(), Some(last));
    run.run(5.0, 10.0);
    assert!(run.engine.state().is_some());
}

#[test]
fn imu_gap_resets_and_the_filter_starts_again() {
    let mut run = Run::new(4);
    run.run(0.0, 10.0);
    assert!(run.engine.state().is_some());
    run.outputs.clear();
    // 2.5 s without IMU (longer than engine.max_imu_gap_s = 1 s).
    run.run(12.5, 80.0);
    assert_eq!(run.engine.counters().count(RejectionReason::ImuGap), 1);
    assert!(run.outputs.iter().any(|o| matches!(
        o,
        Output::Status(StatusEvent::Reset {
            reason: ResetReason::ImuGap,
            ..
        })
    )));
    assert!(run
        .outputs
        .iter()
        .any(|o| matches!(o, Output::Status(StatusEvent::Initialized { .. }))));
    run.assert_position_ok();
}

#[test]
fn gnss_epoch_older_than_the_imu_buffer_is_rejected() {
    let mut run = Run::new(5);
    run.run(0.0, 10.0);
    let old = run.scenario.gnss(3.5);
    let err = run.engine.push_gnss(old).unwrap_err();
    assert_eq!(err.reason, RejectionReason::MeasurementTooOld);
    assert_eq!(
        run.engine
            .counters()
            .count(RejectionReason::MeasurementTooOld),
        1
    );
}

#[test]
fn late_gnss_epoch_within_the_buffer_is_applied_by_rolling_back() {
    let mut run = Run::new(6);
    run.run(0.0, 10.0);
    // An epoch 0.35 s in the past (within engine.imu_buffer_s = 2 s).
    let late = run.scenario.gnss(9.655);
    let out = run.engine.push_gnss(late).unwrap();
    let report = out.iter().find_map(|o| match o {
        Output::Epoch(e) => Some(e),
        _ => None,
    });
    let report = report.expect("the late epoch is reported");
    assert!((report.t_s - 9.655).abs() < 1e-12);
    assert!(report.measurements_used > 8);
    // Rolled-back integration emits no stale solutions, and counts the late epoch.
    assert!(!out.iter().any(|o| matches!(o, Output::Solution(_))));
    assert_eq!(run.engine.late_measurements(), 1);
    run.run(10.0, 60.0);
    run.assert_position_ok();
}

fn epoch_report(outputs: &[Output]) -> &adaptive_gnss_ins::engine::EpochReport {
    outputs
        .iter()
        .find_map(|o| match o {
            Output::Epoch(e) => Some(e),
            _ => None,
        })
        .expect("an epoch report")
}

/// Feeds IMU up to just past `t` and then `epoch`, returning the outputs.
fn push_epoch_at(run: &mut Run, epoch: GnssEpoch) -> Vec<Output> {
    let t = epoch.t_s;
    run.engine.push_imu(&run.scenario.imu(t + 0.005)).unwrap();
    run.engine.push_gnss(epoch).unwrap()
}

#[test]
fn a_kilometre_pseudorange_error_is_rejected_by_the_gate() {
    let mut run = Run::new(7);
    run.run(0.0, 30.0);
    let mut epoch = run.scenario.gnss(30.0);
    epoch.satellites[2].pseudorange_m = epoch.satellites[2].pseudorange_m.map(|p| p + 1000.0);
    let bad = epoch.satellites[2].sat;
    let out = push_epoch_at(&mut run, epoch);
    let report = epoch_report(&out);
    let sat = report.satellites.iter().find(|s| s.sat == bad).unwrap();
    assert_eq!(sat.rejection, Some(SatRejection::InnovationGate));
    assert!(!sat.used_pseudorange);
    assert!((sat.innovation_pseudorange_m - 1000.0).abs() < 20.0);
    assert!(
        report
            .satellites
            .iter()
            .filter(|s| s.used_pseudorange)
            .count()
            >= 6
    );
    run.run(30.01, 60.0);
    run.assert_position_ok();
}

#[test]
fn a_receiver_clock_jump_of_one_millisecond_is_absorbed() {
    let mut run = Run::new(8);
    run.run(0.0, 20.0);
    let jump_m = 1e-3 * earth::SPEED_OF_LIGHT_M_S;
    run.scenario.clock_bias_m += jump_m;
    run.outputs.clear();
    run.run(20.0, 60.0);
    let jumps: Vec<f64> = run
        .outputs
        .iter()
        .filter_map(|o| match o {
            Output::Epoch(e) if e.clock_jump_m != 0.0 => Some(e.clock_jump_m),
            _ => None,
        })
        .collect();
    assert_eq!(jumps.len(), 1);
    assert!((jumps[0] - jump_m).abs() < 10.0, "absorbed {} m", jumps[0]);
    run.assert_position_ok();
}

#[test]
fn non_finite_gnss_fields_are_rejected_per_satellite_or_per_epoch() {
    let mut run = Run::new(9);
    run.run(0.0, 20.0);
    let mut epoch = run.scenario.gnss(20.0);
    epoch.satellites[0].pseudorange_m = Some(f64::NAN);
    epoch.satellites[1].sat_pos_ecef_m[0] = f64::INFINITY;
    epoch.satellites[2].sat_clock_bias_s = f64::NAN;
    epoch.satellites[3].pseudorange_rate_mps = Some(f64::NAN);
    let ids: Vec<_> = epoch.satellites.iter().take(4).map(|s| s.sat).collect();
    let out = push_epoch_at(&mut run, epoch);
    let report = epoch_report(&out);
    let of = |i: usize| report.satellites.iter().find(|s| s.sat == ids[i]).unwrap();
    assert_eq!(of(0).rejection, Some(SatRejection::NotANumber));
    assert_eq!(of(1).rejection, Some(SatRejection::NoSatelliteState));
    assert_eq!(of(2).rejection, Some(SatRejection::NoSatelliteState));
    assert!(of(3).used_pseudorange && !of(3).used_rate);
    let mut epoch = run.scenario.gnss(21.0);
    epoch.t_s = f64::NAN;
    assert_eq!(
        run.engine.push_gnss(epoch).unwrap_err().reason,
        RejectionReason::GnssNotFinite
    );
    let mut epoch = run.scenario.gnss(21.0);
    epoch.gps_time_of_week_s = f64::INFINITY;
    assert_eq!(
        run.engine.push_gnss(epoch).unwrap_err().reason,
        RejectionReason::GnssNotFinite
    );
    run.run(20.01, 60.0);
    run.assert_position_ok();
}

#[test]
fn an_epoch_with_no_satellites_is_rejected() {
    let mut run = Run::new(10);
    run.run(0.0, 5.0);
    let mut epoch = run.scenario.gnss(5.0);
    epoch.satellites.clear();
    let err = run.engine.push_gnss(epoch).unwrap_err();
    assert_eq!(err.reason, RejectionReason::GnssNoSatellites);
    run.run(5.0, 8.0);
    assert!(run.engine.state().is_some());
}

#[test]
fn gnss_before_any_imu_waits_for_the_imu() {
    let mut run = Run::new(11);
    // Between the whole seconds at which `run` feeds its own epochs.
    let epoch = run.scenario.gnss(0.5);
    assert!(run.engine.push_gnss(epoch).unwrap().is_empty());
    run.run(0.0, 20.0);
    assert!(run.engine.state().is_some());
    assert_eq!(run.engine.counters().total(), 0);
}

/// Over DDS the IMU and GNSS streams have no common order: a GNSS epoch stamped at an IMU
/// sample's time may arrive before or after that sample. Both orders give the same
/// outputs, through start-up and while running.
#[test]
fn arrival_order_at_equal_stamps_does_not_change_the_outputs() {
    let run = |gnss_first: bool| {
        // The same seed: the same draws in both runs.
        let mut scenario = StaticScenario::new(11);
        let yaw = scenario.q_nb.euler_angles().2;
        let dt = 1.0 / scenario.imu_rate_hz;
        let mut engine = Engine::new(static_config(yaw));
        let mut outputs = Vec::new();
        for k in 0..(40.0 / dt).round() as usize {
            let t = k as f64 * dt;
            let epoch = ((t - t.round()).abs() < 1e-9).then(|| scenario.gnss(t));
            if gnss_first {
                if let Some(e) = epoch.clone() {
                    outputs.extend(engine.push_gnss(e).unwrap());
                }
            }
            outputs.extend(engine.push_imu(&scenario.imu(t)).unwrap());
            if !gnss_first {
                if let Some(e) = epoch {
                    outputs.extend(engine.push_gnss(e).unwrap());
                }
            }
        }
        assert!(engine.state().is_some(), "the filter did not start");
        outputs
    };
    let (a, b) = (run(true), run(false));
    assert_eq!(a.len(), b.len(), "number of outputs");
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(format!("{x:?}"), format!("{y:?}"));
    }
}

/// The 1-sigma of the start's position (the root of the mean of its E, N and U variances)
/// and the position's NEES, when the filter starts after `leveling_s` of rest.
fn start_position(seed: u64, leveling_s: f64) -> (f64, f64) {
    let mut scenario = StaticScenario::new(seed);
    let mut config = static_config(scenario.q_nb.euler_angles().2);
    config.init.leveling_duration_s = leveling_s;
    // Below the single-point solutions' own σ: each is weighed by its covariance.
    config.init.position_sigma_m = 0.5;
    let mut engine = Engine::new(config);
    let dt = 1.0 / scenario.imu_rate_hz;
    for k in 0.. {
        let t = k as f64 * dt;
        engine.push_imu(&scenario.imu(t)).unwrap();
        if (t - t.round()).abs() < 1e-9 {
            engine.push_gnss(scenario.gnss(t)).unwrap();
        }
        if let Some(s) = engine.state() {
            let e = earth::llh_to_enu(&s.nav.p, &scenario.position);
            let p = s.solution().position_covariance_enu_m2();
            return (
                (p.trace() / 3.0).sqrt(),
                e.dot(&(p.try_inverse().unwrap() * e)),
            );
        }
        // The first levelling window is at rest (a standing receiver's Doppler speed
        // noise does not deny it), and the heading is given: the start comes at the next
        // 1 Hz epoch; one denied window would move it a window later.
        assert!(
            t < leveling_s + 1.0,
            "seed {seed}: no start by {t} s (a levelling window was denied)"
        );
    }
    unreachable!()
}

/// Tightly coupled, the start combines every single-point solution since the start-up
/// began, and the truth stays within its σ (the simulated ranges are white with the
/// filter's σ model). At 1 Hz a start after 1 s of levelling combines the epochs at 0
/// and 1 s, one after 60 s the minute before it, which the track's one-minute memory
/// weighs as about 38 epochs: σ about √(2/38) = 0.23 times the first (measured 0.226 for
/// every seed); a start from its own epoch alone keeps about the same σ in both.
#[test]
fn start_combines_the_single_point_solutions_before_it() {
    for seed in 1..=10 {
        let (sigma_short_m, nees_short) = start_position(seed, 1.0);
        let (sigma_long_m, nees_long) = start_position(seed, 60.0);
        assert!(
            sigma_long_m < 0.5 * sigma_short_m,
            "seed {seed}: σ {sigma_long_m} m after 60 s against {sigma_short_m} m after 1 s"
        );
        for nees in [nees_short, nees_long] {
            assert!(nees < CHI2_3DOF_999, "seed {seed}: start NEES {nees}");
        }
    }
}

/// A levelling at rest measures the accelerometer bias along gravity (the magnitude of
/// the mean specific force less the normal gravity) and starts the filter with it; the
/// bias across gravity, which tilts the levelling instead, keeps the class's σ.
#[test]
fn the_levelling_at_rest_measures_the_accelerometer_bias_along_gravity() {
    let micro_g_m_s2 = 9.806_65e-6;
    let mut run = Run::new(3);
    run.scenario.q_nb = UnitQuaternion::from_euler_angles(0.05, -0.03, 0.7);
    let bias_m_s2 = Vector3::new(800.0, -600.0, 2000.0) * micro_g_m_s2;
    let dt = 1.0 / run.scenario.imu_rate_hz;
    let mut started = false;
    for k in 0..300 {
        let t = k as f64 * dt;
        let mut sample = run.scenario.imu(t);
        sample.f_ib_b_m_s2 += bias_m_s2;
        run.outputs.extend(run.engine.push_imu(&sample).unwrap());
        if (t - t.round()).abs() < 1e-9 {
            let epoch = run.scenario.gnss(t);
            run.outputs.extend(run.engine.push_gnss(epoch).unwrap());
        }
        if run.engine.state().is_some() {
            started = true;
            break;
        }
    }
    assert!(started, "the filter did not start within 3 s");
    let s = run.engine.state().unwrap();
    let up_b = (run.scenario.q_nb.inverse() * Vector3::z()).normalize();
    let p = s.p.fixed_view::<3, 3>(ACC_BIAS, ACC_BIAS).into_owned();
    let sigma_up_m_s2 = (up_b.dot(&(p * up_b))).sqrt();
    let error_up_m_s2 = up_b.dot(&(s.accel_bias_m_s2 - bias_m_s2));
    assert!(
        sigma_up_m_s2 < 250.0 * micro_g_m_s2,
        "σ along gravity {:.0} µg",
        sigma_up_m_s2 / micro_g_m_s2
    );
    assert!(
        error_up_m_s2.abs() < 3.0 * sigma_up_m_s2,
        "error along gravity {:.0} µg at a σ of {:.0} µg",
        error_up_m_s2 / micro_g_m_s2,
        sigma_up_m_s2 / micro_g_m_s2
    );
    let across_b = up_b.cross(&Vector3::x()).normalize();
    let sigma_across_m_s2 = (across_b.dot(&(p * across_b))).sqrt();
    assert!(
        sigma_across_m_s2 > 1200.0 * micro_g_m_s2,
        "σ across gravity {:.0} µg: the levelling cannot see it",
        sigma_across_m_s2 / micro_g_m_s2
    );
}
