//! The divergence monitor (issue 11, item 3) on the simulated drive of the engine tests,
//! tightly and loosely coupled.
//!
//! The divergence is caused, not injected: during a 30 s GNSS outage the accelerometer
//! has a constant forward bias of 1.1 m/s² (a fault the sample screening cannot see: every
//! sample is in range and like its neighbours), so when the GNSS returns the filter is
//! some 500 m and 33 m/s off with a covariance of a few metres. The monitor must see it
//! within 5 s of the first GNSS epoch after the outage, reset the filter once, and the
//! restarted filter must be within 3σ of the truth (its 9-state NEES below the χ² quantile
//! of 99.73 %) on every epoch from 60 s after its new start to the end of the drive.
//!
//! A gyro fault with GNSS present: a consumer-MEMS gyro whose biases jump to ten times
//! their value. The restart must not trust the diverged attitude and bias (kept, they left
//! the restarted filter at a NEES of 1,009 a minute later).
//!
//! And no false alarm: the same drive without the fault resets nothing, nor does a tenfold
//! bias of a tactical gyro (the drives with outliers of tests/iarf_engine.rs assert the
//! same).

use adaptive_gnss_ins::config::{Config, Coupling, FilterVariant};
use adaptive_gnss_ins::engine::{Engine, FilterState, GnssFix, Output, ResetReason, StatusEvent};
use adaptive_gnss_ins::eval;
use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::ins::error_state::PHI;
use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::ros::adapter::{OutputFrames, RosAdapter};
use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::DiagnosticStatus;
use adaptive_gnss_ins::ros::outbound;
use adaptive_gnss_ins::sim::constellation::GpsConstellation;
use adaptive_gnss_ins::sim::{ImuErrorModel, ImuErrorSpec, Trajectory};
use nalgebra::Vector3;
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use statrs::distribution::{ChiSquared, ContinuousCDF};

mod support;
use support::drive::{drive, drive_epoch};
use support::fixes::{FixNoise, Fixes};

/// The GNSS outage, and the accelerometer fault during it (s).
const OUTAGE_FROM_S: f64 = 60.0;
const OUTAGE_TO_S: f64 = 90.0;
/// The fault: a constant bias on the forward accelerometer axis (m/s²).
const ACCEL_FAULT_M_S2: f64 = 1.1;
/// When the gyro biases jump to ten times their value (s): GNSS present, mid-drive.
const GYRO_STEP_AT_S: f64 = 60.0;
/// The accelerometer burst: start (s, just after a GNSS epoch), length (s), size (m/s²).
const BURST_AT_S: f64 = 150.3;
const BURST_S: f64 = 0.5;
const BURST_M_S2: f64 = 40.0;
/// One degree per hour in rad/s.
const DEG_PER_H_RAD_S: f64 = std::f64::consts::PI / 180.0 / 3600.0;
/// Longest time from the first GNSS epoch after the outage to the reset (s).
const MAX_DETECTION_S: f64 = 5.0;
/// The restarted filter is scored from this long after its new start (s).
const SETTLING_S: f64 = 60.0;
/// The receiver fixes (loose coupling): a driving car's σ, all of it white — the noise
/// the filter models — so that the 3σ check judges the recovery; under the slow
/// correlated error of [`FixNoise::DRIVE`] the loosely-coupled filter is over-confident
/// with or without a reset (NEES 25.5 on the clean drive, see tests/start_in_motion.rs).
const WHITE_FIXES: FixNoise = FixNoise {
    gm_sigma_m: [0.0, 0.0],
    white_sigma_m: [0.6, 1.0],
};

/// What one run saw.
#[derive(Debug)]
struct Run {
    /// Times of the resets, and of the starts.
    resets: Vec<f64>,
    starts: Vec<f64>,
    /// Largest 3D position error the filter reached before its reset (m).
    worst_error_before_reset_m: f64,
    /// Scored epochs after the restart and the largest NEES among them.
    scored: usize,
    worst_nees: f64,
    /// Most heading hypotheses a split of the running filter had at once, and the largest
    /// yaw error at a GNSS epoch while split, in units of the published yaw σ.
    most_heading_hypotheses: usize,
    worst_split_yaw_sigmas: f64,
    /// Every GNSS epoch while running: time (s), 3D position error and the filter's 3D
    /// position σ (m).
    epochs: Vec<(f64, f64, f64)>,
}

/// A GNSS input of either coupling.
enum GnssInput {
    Epoch(GnssEpoch),
    Fix(GnssFix),
}

/// What goes wrong on the drive.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fault {
    None,
    /// [`ACCEL_FAULT_M_S2`] during the outage.
    AccelDuringOutage,
    /// From [`GYRO_STEP_AT_S`] on, with GNSS, the gyro biases are ten times the IMU's
    /// (`gyro_bias_deg_per_h` of the given spec): the filter's estimate is 10× wrong.
    GyroBiasTenfold,
    /// [`BURST_M_S2`] on the forward accelerometer for [`BURST_S`] from [`BURST_AT_S`],
    /// between two GNSS epochs: the filter jumps within a second.
    AccelBurst,
}

fn run(variant: FilterVariant, coupling: Coupling, fault: Fault) -> Run {
    run_late(variant, coupling, fault, 0)
}

/// [`run`] with every GNSS input delivered `gnss_delay_samples` IMU samples late.
fn run_late(
    variant: FilterVariant,
    coupling: Coupling,
    fault: Fault,
    gnss_delay_samples: usize,
) -> Run {
    run_with(
        variant,
        coupling,
        fault,
        &ImuErrorSpec::default(),
        Config::default(),
        gnss_delay_samples,
    )
}

fn run_with(
    variant: FilterVariant,
    coupling: Coupling,
    fault: Fault,
    imu_spec: &ImuErrorSpec,
    mut config: Config,
    gnss_delay_samples: usize,
) -> Run {
    let name = format!("{variant:?} {coupling:?} fault {fault:?}");
    let trajectory = Trajectory::new(&drive(1)).unwrap();
    let imu_rate_hz = 100.0;
    let mut imu = ImuErrorModel::new(imu_spec, imu_rate_hz, 42).unwrap();
    let gyro_step_rad_s = Vector3::from(imu_spec.gyro_bias_deg_per_h) * (9.0 * DEG_PER_H_RAD_S);
    let constellation = GpsConstellation::augmented(1);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut fixes = Fixes::new(WHITE_FIXES, 3);
    config.filter.variant = variant;
    config.filter.coupling = coupling;
    let mut engine = Engine::new(config);
    let chi2 = ChiSquared::new(9.0).unwrap().inverse_cdf(0.9973);
    let mut result = Run {
        resets: Vec::new(),
        starts: Vec::new(),
        worst_error_before_reset_m: 0.0,
        scored: 0,
        worst_nees: 0.0,
        most_heading_hypotheses: 0,
        worst_split_yaw_sigmas: 0.0,
        epochs: Vec::new(),
    };
    // The GNSS input waiting for its delivery: the sample it is due after, and the input.
    let mut held: Option<(usize, GnssInput)> = None;
    for (k, truth) in trajectory.samples(imu_rate_hz).unwrap().enumerate() {
        let t = truth.nav.t_s;
        let in_outage =
            fault == Fault::AccelDuringOutage && (OUTAGE_FROM_S..OUTAGE_TO_S).contains(&t);
        let mut measured = imu.corrupt(&truth.imu);
        if fault == Fault::GyroBiasTenfold && t >= GYRO_STEP_AT_S {
            measured.w_ib_b_rad_s += gyro_step_rad_s;
        }
        if fault == Fault::AccelBurst && (BURST_AT_S..BURST_AT_S + BURST_S).contains(&t) {
            measured.f_ib_b_m_s2.x += BURST_M_S2;
        }
        if in_outage {
            measured = ImuSample {
                f_ib_b_m_s2: measured.f_ib_b_m_s2 + Vector3::new(ACCEL_FAULT_M_S2, 0.0, 0.0),
                ..measured
            };
        }
        let mut out = engine.push_imu(&measured).unwrap();
        let epoch_due = (t - t.round()).abs() < 1e-9 && !in_outage;
        if epoch_due {
            let input = match coupling {
                Coupling::Tight => {
                    GnssInput::Epoch(drive_epoch(&constellation, &mut rng, &truth.nav))
                }
                Coupling::Loose => GnssInput::Fix(fixes.fix(&truth.nav)),
            };
            held = Some((k + gnss_delay_samples, input));
        }
        if let Some((_, input)) = held.take_if(|(due, _)| *due <= k) {
            out.extend(match input {
                GnssInput::Epoch(epoch) => engine.push_gnss(epoch).unwrap(),
                GnssInput::Fix(fix) => engine.push_fix(fix).unwrap(),
            });
        }
        for o in &out {
            match o {
                Output::Status(StatusEvent::Initialized { t_s, .. }) => result.starts.push(*t_s),
                Output::Status(StatusEvent::Reset { t_s, reason }) => {
                    assert_eq!(*reason, ResetReason::DivergedFromGnss, "{name}");
                    result.resets.push(*t_s);
                    assert!(engine.state().is_none(), "{name}: running after the reset");
                    assert_eq!(engine.diverged_at_t_s(), Some(*t_s), "{name}");
                }
                _ => {}
            }
        }
        let hypotheses = engine.heading_hypotheses();
        result.most_heading_hypotheses = result.most_heading_hypotheses.max(hypotheses);
        let Some(state) = engine.state() else {
            continue;
        };
        let reference = eval::TruthSample::from(&truth.nav);
        let error = eval::solution_error(&state.solution(), &reference);
        if result.resets.is_empty() {
            let e = error.position_enu_m.norm();
            result.worst_error_before_reset_m = result.worst_error_before_reset_m.max(e);
        }
        if epoch_due {
            let e = error.position_enu_m.norm();
            result.epochs.push((t, e, position_sigma_3d_m(state)));
        }
        if epoch_due && hypotheses > 0 {
            let yaw_error_rad = error.attitude_rpy_rad.unwrap()[2];
            let sigmas = yaw_error_rad.abs() / state.p[(PHI + 2, PHI + 2)].sqrt();
            result.worst_split_yaw_sigmas = result.worst_split_yaw_sigmas.max(sigmas);
        }
        let restarted = result.starts.len() > 1;
        let since_start = t - result.starts.last().copied().unwrap_or(f64::INFINITY);
        if epoch_due && restarted && since_start >= SETTLING_S {
            assert_eq!(engine.diverged_at_t_s(), None, "{name}");
            result.scored += 1;
            result.worst_nees = result.worst_nees.max(error.nees);
            assert!(
                error.nees <= chi2,
                "{name}: NEES {:.1} beyond 3σ ({chi2:.1}) at {t} s: {error:?}",
                error.nees
            );
        }
    }
    assert_eq!(
        engine.divergence_resets(),
        result.resets.len() as u64,
        "{name}"
    );
    println!(
        "{name}: resets at {:?} s, starts at {:?} s, worst error before the reset {:.1} m, \
         {} epochs scored after the restart, worst NEES {:.1} (3σ: {chi2:.1}), at most {} \
         heading hypotheses (yaw error while split at most {:.1} σ)",
        result.resets,
        result.starts,
        result.worst_error_before_reset_m,
        result.scored,
        result.worst_nees,
        result.most_heading_hypotheses,
        result.worst_split_yaw_sigmas
    );
    result
}

fn detects_resets_and_recovers(variant: FilterVariant, coupling: Coupling, delay_samples: usize) {
    let r = run_late(variant, coupling, Fault::AccelDuringOutage, delay_samples);
    assert!(
        r.worst_error_before_reset_m > 300.0,
        "{variant:?} {coupling:?}: the fault was not a divergence: {r:?}"
    );
    let [reset_t_s] = r.resets.as_slice() else {
        panic!("{variant:?} {coupling:?}: one reset expected: {r:?}");
    };
    assert!(
        *reset_t_s >= OUTAGE_TO_S && *reset_t_s <= OUTAGE_TO_S + MAX_DETECTION_S,
        "{variant:?} {coupling:?}: reset at {reset_t_s} s: {r:?}"
    );
    assert!(r.scored > 60, "{variant:?} {coupling:?}: {r:?}");
}

#[test]
fn a_divergence_is_detected_within_5_s_reset_and_recovered_loosely_coupled() {
    for variant in [FilterVariant::Ekf, FilterVariant::Iarf] {
        detects_resets_and_recovers(variant, Coupling::Loose, 0);
    }
}

#[test]
fn a_divergence_is_detected_within_5_s_reset_and_recovered_tightly_coupled() {
    for variant in [FilterVariant::Ekf, FilterVariant::Iarf] {
        detects_resets_and_recovers(variant, Coupling::Tight, 0);
    }
}

/// The same with every GNSS input five IMU samples late (as DDS may deliver it): the
/// reset comes from a late input, in the re-integration after its roll-back.
#[test]
fn a_divergence_seen_in_late_gnss_is_detected_reset_and_recovered() {
    for coupling in [Coupling::Loose, Coupling::Tight] {
        detects_resets_and_recovers(FilterVariant::Ekf, coupling, 5);
    }
}

#[test]
fn the_clean_drive_resets_nothing() {
    for coupling in [Coupling::Loose, Coupling::Tight] {
        let r = run(FilterVariant::Ekf, coupling, Fault::None);
        assert!(r.resets.is_empty(), "{coupling:?}: {r:?}");
        assert_eq!(r.starts.len(), 1, "{coupling:?}: {r:?}");
    }
}

/// A consumer-MEMS IMU: biases and noise inside the ranges of
/// params/imu_consumer_mems.yaml (turn-on gyro biases of 200–400 °/h, offsets of 20 mg).
fn consumer_mems_imu() -> ImuErrorSpec {
    ImuErrorSpec {
        gyro_bias_deg_per_h: [200.0, -300.0, 400.0],
        accel_bias_ug: [20000.0, -20000.0, 20000.0],
        gyro_gm_sigma_deg_per_h: 30.0,
        gyro_gm_correlation_time_s: 300.0,
        accel_gm_sigma_ug: 500.0,
        accel_gm_correlation_time_s: 3600.0,
        gyro_arw_deg_per_sqrt_h: 0.3,
        accel_vrw_ug_per_sqrt_hz: 150.0,
        ..ImuErrorSpec::default()
    }
}

/// The configuration of that IMU class (the preset over the defaults).
fn consumer_mems_config() -> Config {
    let path = "params/imu_consumer_mems.yaml";
    let text = std::fs::read_to_string(path).unwrap();
    Config::from_yaml_str(&text, path).unwrap()
}

/// The 3D position σ of `state` (m).
fn position_sigma_3d_m(state: &FilterState) -> f64 {
    let cov = state.solution().position_covariance_enu_m2();
    cov.trace().max(0.0).sqrt()
}

/// A consumer-MEMS gyro whose biases jump to ten times their value (0.6–1.1 °/s, far beyond
/// the class's σ of 500 °/h) at 60 s, tightly coupled: the position runs off within
/// seconds; the monitor resets within 5 s of the first epoch beyond 5σ, and the restarted
/// filter (aligned again, with a wide gyro bias prior) is within 3σ from 60 s after its
/// start to the end of the drive (asserted in `run`).
#[test]
fn a_gyro_bias_jump_to_ten_times_is_detected_reset_and_recovered_tightly_coupled() {
    gyro_fault_is_detected_reset_and_recovered(Coupling::Tight, consumer_mems_config());
}

/// The same fault loosely coupled, with the car's motion constraint (`constraints.platform:
/// car`; the drive is a car's). Without a constraint the restarted filter's wide vertical
/// gyro bias prior lets the heading drift tens of degrees on a straight road where
/// position fixes do not see it (see the next test). The non-holonomic constraint ties the
/// heading to the fixes' course: worst NEES 14.0 (ekf) and 13.9 (iarf), the reset 3–4 s
/// after the first epoch beyond 5σ.
#[test]
fn a_gyro_bias_jump_to_ten_times_is_detected_reset_and_recovered_loosely_coupled_in_a_car() {
    let mut config = consumer_mems_config();
    config.set_parameter("constraints.platform", "car").unwrap();
    gyro_fault_is_detected_reset_and_recovered(Coupling::Loose, config);
}

fn gyro_fault_is_detected_reset_and_recovered(coupling: Coupling, config: Config) {
    for variant in [FilterVariant::Ekf, FilterVariant::Iarf] {
        let r = run_with(
            variant,
            coupling,
            Fault::GyroBiasTenfold,
            &consumer_mems_imu(),
            config.clone(),
            0,
        );
        let [reset_t_s] = r.resets.as_slice() else {
            panic!("{variant:?}: one reset expected: {r:?}");
        };
        let beyond_5_sigma_t_s = r
            .epochs
            .iter()
            .find(|(t, e, sigma)| *t >= GYRO_STEP_AT_S && e > &(5.0 * sigma))
            .map(|(t, _, _)| *t)
            .unwrap_or_else(|| panic!("{variant:?}: never beyond 5σ: {r:?}"));
        assert!(
            *reset_t_s <= beyond_5_sigma_t_s + MAX_DETECTION_S,
            "{variant:?}: beyond 5σ at {beyond_5_sigma_t_s} s, reset at {reset_t_s} s"
        );
        assert!(r.scored > 60, "{variant:?}: {r:?}");
        println!("{variant:?}: beyond 5σ at {beyond_5_sigma_t_s} s, reset at {reset_t_s} s");
    }
}

/// The same jump on the tactical IMU (0.5 → 5 °/h) moves the position by little: no
/// reset (a false alarm would be one).
#[test]
fn a_tactical_gyro_bias_jump_to_ten_times_raises_no_alarm() {
    for coupling in [Coupling::Tight, Coupling::Loose] {
        let r = run(FilterVariant::Ekf, coupling, Fault::GyroBiasTenfold);
        assert!(r.resets.is_empty(), "{coupling:?}: {r:?}");
    }
}

/// A burst the sample screening lets through (4 g for half a second, in range and
/// steady) between two GNSS epochs, tightly coupled: the filter is 10 m and 20 m/s off at
/// the next epoch, a leap that looks like a GNSS jump, but the Doppler velocity of the
/// single-point solution disagrees with the filter's: divergence, reset within 5 s of the
/// burst, recovered (asserted in `run`). Without the velocity check the filter flew on to
/// 2.9 km with no reset. (Loosely coupled with fixes that carry no velocity the leap is
/// still taken for the GNSS's: a limit of the monitor, see src/engine/divergence.rs.)
#[test]
fn a_filter_that_jumps_within_a_second_is_detected_reset_and_recovered() {
    for variant in [FilterVariant::Ekf, FilterVariant::Iarf] {
        let r = run(variant, Coupling::Tight, Fault::AccelBurst);
        let [reset_t_s] = r.resets.as_slice() else {
            panic!("{variant:?}: one reset expected: {r:?}");
        };
        assert!(
            *reset_t_s <= BURST_AT_S + BURST_S + MAX_DETECTION_S,
            "{variant:?}: reset at {reset_t_s} s: {r:?}"
        );
        assert!(r.scored > 60, "{variant:?}: {r:?}");
    }
}

/// The same fault loosely coupled without a motion constraint. The restarted filter's wide
/// vertical gyro bias prior lets its heading σ grow beyond 15° on the straight climb, and
/// the running filter splits into a bank of heading hypotheses (src/engine/heading_bank.rs)
/// that keeps publishing: one reset only, and while split the published yaw within 3σ of
/// the truth; and the restarted filter within 3σ from 60 s after its start (asserted in
/// `run`): worst NEES 19.1 (ekf) and 21.5 (iarf) against the bound of 25.3. When the split
/// came, the single filter after it carried a roll 2° off through the next turn (worst
/// NEES about 90, yaw 3.2σ off), and before the split 276 with two more resets
/// (docs/results.md); by 774cf4f later changes had brought it to 20.1 and 20.8 unnoticed,
/// as this test printed the NEES instead of asserting it.
#[test]
fn a_gyro_bias_jump_loosely_coupled_without_a_constraint_splits_the_heading() {
    for variant in [FilterVariant::Ekf, FilterVariant::Iarf] {
        let r = run_with(
            variant,
            Coupling::Loose,
            Fault::GyroBiasTenfold,
            &consumer_mems_imu(),
            consumer_mems_config(),
            0,
        );
        assert_eq!(r.resets.len(), 1, "{variant:?}: {r:?}");
        assert!(
            r.most_heading_hypotheses > 1,
            "{variant:?}: no split: {r:?}"
        );
        assert!(r.scored > 60, "{variant:?}: {r:?}");
        assert!(r.worst_split_yaw_sigmas <= 3.0, "{variant:?}: {r:?}");
    }
}

/// The split of [`a_gyro_bias_jump_loosely_coupled_without_a_constraint_splits_the_heading`]
/// as the node reports it: the same drive played through the ROS adapter (sensor_msgs/Imu
/// and NavSatFix as a driver sends them); while the heading is split `/diagnostics` says
/// WARN with the number of hypotheses, and OK once one filter runs again.
#[test]
fn a_heading_split_is_a_warning_on_diagnostics() {
    let imu_spec = consumer_mems_imu();
    let trajectory = Trajectory::new(&drive(1)).unwrap();
    let mut imu = ImuErrorModel::new(&imu_spec, 100.0, 42).unwrap();
    let gyro_step_rad_s = Vector3::from(imu_spec.gyro_bias_deg_per_h) * (9.0 * DEG_PER_H_RAD_S);
    let mut fixes = Fixes::new(WHITE_FIXES, 3);
    let mut config = consumer_mems_config();
    config.filter.coupling = Coupling::Loose;
    let mut adapter = RosAdapter::new(config, OutputFrames::default());
    let (mut warned_split, mut ok_after_split) = (0, 0);
    for truth in trajectory.samples(100.0).unwrap() {
        let t = truth.nav.t_s;
        let stamp = seconds_to_time(t).unwrap();
        let mut measured = imu.corrupt(&truth.imu);
        if t >= GYRO_STEP_AT_S {
            measured.w_ib_b_rad_s += gyro_step_rad_s;
        }
        adapter.on_imu(&outbound::imu(&measured, stamp, "imu"));
        if (t - t.round()).abs() > 1e-9 {
            continue;
        }
        adapter.on_fix(&outbound::receiver_fix(
            &fixes.fix(&truth.nav),
            stamp,
            "gnss",
        ));
        let status = &adapter.diagnostics("/ins", stamp).status[0];
        let hypotheses = adapter.engine().heading_hypotheses();
        if hypotheses > 0 {
            assert_eq!(status.level, DiagnosticStatus::WARN, "{}", status.message);
            let phase = format!("running, heading split into {hypotheses} hypotheses");
            assert!(status.message.contains(&phase), "{}", status.message);
            warned_split += 1;
        } else if warned_split > 0 && adapter.engine().state().is_some() {
            ok_after_split += usize::from(status.level == DiagnosticStatus::OK);
        }
    }
    println!("{warned_split} epochs split and warned, {ok_after_split} OK after");
    assert!(warned_split > 0, "no split");
    assert!(ok_after_split > 0, "never OK again after the split");
}
