//! The shared step with the zero-velocity model, wrapped so that it reports the robust
//! weights, through every base and scheme; and the rows of H of the motion constraints
//! against differences of their predictions.

use nalgebra::{DVector, Matrix3, UnitQuaternion, Vector3};

use crate::config::{Config, Coupling, FilterVariant};
use crate::earth;
use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::{StateVector, DP, DV, N, PHI};

use super::super::adaptation::Adaptation;
use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::{
    apply, BaselineHeading, FixMeasurement, GnssFix, Linearization, MeasurementModel, NonHolonomic,
    WheelSpeed, ZeroRate, ZeroVelocity,
};

/// The zero-velocity model, reporting the robust weights in the fix's field.
struct Reported(ZeroVelocity);

impl MeasurementModel for Reported {
    fn t_s(&self) -> f64 {
        self.0.t_s()
    }

    fn kind(&self) -> MeasurementKind {
        self.0.kind()
    }

    fn linearize(&mut self, state: &mut FilterState, report: &mut EpochReport) -> Linearization {
        self.0.linearize(state, report)
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        self.0.predict(state, rows)
    }

    fn report_update(&self, report: &mut EpochReport, _rows: &[usize], outcome: &UpdateOutcome) {
        report.fix_robust_weights = outcome.robust_weights.iter().copied().collect();
    }
}

fn moving_state(p_velocity_m2_s2: f64) -> FilterState {
    FilterState::moving(p_velocity_m2_s2)
}

fn run(variant: FilterVariant) -> (FilterState, EpochReport) {
    let mut config = Config::default();
    config.filter.variant = variant;
    let mut adaptation = Adaptation::new(&config);
    let mut state = moving_state(1e-2);
    let mut model = Reported(ZeroVelocity {
        t_s: 1.0,
        sigma_mps: 0.01,
    });
    let report = apply(&mut state, &mut model, &mut adaptation, true).unwrap();
    (state, report)
}

#[test]
fn a_new_model_is_updated_by_every_base_and_scheme() {
    // P = 1e-2 I, R = 1e-4 I: each velocity axis keeps R / (P + R) of its value.
    let keep = 1e-4 / (1e-2 + 1e-4);
    let v0 = moving_state(1e-2).nav.v_n;
    let (ekf, report) = run(FilterVariant::Ekf);
    assert!((ekf.nav.v_n - v0 * keep).amax() < 1e-15);
    assert!((ekf.p[(DV, DV)] - 1e-2 * keep).abs() < 1e-15);
    assert_eq!(report.measurements_used, 3);
    assert_eq!(report.variant, "ekf");
    let nis = v0.norm_squared() / (1e-2 + 1e-4);
    assert!((report.nis - nis).abs() < 1e-9 * nis);
    // The model is linear: the cubature base gives the EKF's answer to rounding.
    let (ckf, _) = run(FilterVariant::Ckf);
    assert!((ckf.nav.v_n - ekf.nav.v_n).amax() < 1e-12);
    // The robust scheme weighs every row and the model reports the weights.
    let (_, iarf) = run(FilterVariant::Iarf);
    assert_eq!(iarf.fix_robust_weights.len(), 3);
    assert!(iarf
        .fix_robust_weights
        .iter()
        .all(|w| *w > 0.0 && *w <= 1.0));
    assert!(iarf.mahalanobis_d2 > iarf.chi2_threshold);
}

/// y(nominal) − y(true) against H δx for small errors δx of every state, the true state
/// being the nominal one corrected by δx.
fn check_rows<M: MeasurementModel>(mut model: M) {
    let mut nominal = moving_state(1.0);
    nominal.nav.q_nb = UnitQuaternion::from_euler_angles(0.05, -0.1, 0.8);
    nominal.nav.v_n = Vector3::new(8.0, -5.0, 0.3);
    nominal.last_imu.w_ib_b_rad_s = Vector3::new(0.02, -0.01, 0.3);
    nominal.gyro_bias_rad_s = Vector3::new(1e-3, -2e-3, 5e-4);
    let lin = model.linearize(
        &mut nominal.clone(),
        &mut EpochReport::new(0.0, model.kind(), "ekf"),
    );
    let every: Vec<usize> = (0..lin.rows.len()).collect();
    let y0 = model.predict(&nominal, &every);
    for (i, (row, predicted)) in lin.rows.iter().zip(&lin.predicted).enumerate() {
        assert_eq!(y0[i], *predicted);
        for k in 0..N {
            // Errors of milliradians, centimetres per second, 1e-4 rad/s.
            let step = if (DV..DV + 3).contains(&k) {
                1e-2
            } else {
                1e-4
            };
            let mut dx = StateVector::zeros();
            dx[k] = step;
            let mut plus = nominal.clone();
            plus.apply_correction(&dx);
            let mut minus = nominal.clone();
            minus.apply_correction(&(-dx));
            let slope =
                (model.predict(&minus, &[i])[0] - model.predict(&plus, &[i])[0]) / (2.0 * step);
            assert!(
                (slope - row[k]).abs() < 1e-6 + 1e-4 * row[k].abs(),
                "row {i}, state {k}: difference {slope}, H {}",
                row[k]
            );
        }
    }
}

#[test]
fn constraint_rows_match_differences() {
    check_rows(ZeroVelocity {
        t_s: 0.0,
        sigma_mps: 0.02,
    });
    let lever = Vector3::new(-1.2, 0.3, -0.5);
    check_rows(NonHolonomic {
        t_s: 0.0,
        lever_arm_b_m: &lever,
        sigma_lateral_mps: 0.1,
        sigma_vertical_mps: 0.1,
    });
    check_rows(WheelSpeed {
        t_s: 0.0,
        lever_arm_b_m: &lever,
        speed_mps: 12.0,
        sigma_mps: 0.05,
    });
}

/// The baseline heading's row against differences, for a baseline ahead, to the right
/// and tilted, with the measured heading on either side of north (the wrap).
#[test]
fn baseline_heading_rows_match_differences() {
    for baseline in [
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, -1.5, 0.0),
        Vector3::new(0.8, 0.6, 0.4),
    ] {
        for heading_rad in [0.01, 6.27, 2.0] {
            check_rows(BaselineHeading {
                t_s: 0.0,
                baseline_b_m: &baseline,
                heading_rad,
                sigma_rad: 0.01,
                // Choice: no gate here: the rows are checked whatever the innovation.
                gate_sigma: f64::INFINITY,
            });
        }
    }
}

/// A heading beyond the gate gives no rows (the engine counts it); within, one row whose
/// prediction is wrapped to within π of the measurement.
#[test]
fn baseline_heading_gates_and_wraps() {
    let baseline = Vector3::new(1.0, 0.0, 0.0);
    let mut state = moving_state(1e-4);
    // ENU yaw π/2 − 0.05: the body x axis points 0.05 rad east of north.
    state.nav.q_nb =
        UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2 - 0.05);
    let model = |heading_rad: f64| BaselineHeading {
        t_s: 0.0,
        baseline_b_m: &baseline,
        heading_rad,
        sigma_rad: 0.02,
        gate_sigma: 5.0,
    };
    let mut report = EpochReport::new(0.0, MeasurementKind::BaselineHeading, "ekf");
    let near = model(2.0 * std::f64::consts::PI - 0.01).linearize(&mut state.clone(), &mut report);
    assert_eq!(near.rows.len(), 1);
    let innovation = near.predicted[0] - near.measured[0];
    assert!((innovation - 0.06).abs() < 1e-9, "{innovation}");
    let heading_sigma = state.p[(PHI + 2, PHI + 2)].sqrt();
    let far = model(0.05 + 6.0 * heading_sigma.hypot(0.02)).linearize(&mut state, &mut report);
    assert!(far.rows.is_empty());
}

/// The zero-rate rows leave out the attitude's part of the earth rate (below 1e-7 rad/s
/// per milliradian): checked with the attitude columns allowed that much.
#[test]
fn zero_rate_rows_match_differences_but_the_earth_rates_attitude_part() {
    let mut model = ZeroRate {
        t_s: 0.0,
        mean_raw_rad_s: Vector3::new(0.02, -0.01, 0.3),
        sigma_rad_s: 1e-3,
    };
    let mut nominal = moving_state(1.0);
    nominal.last_imu.w_ib_b_rad_s = Vector3::new(0.02, -0.01, 0.3);
    let lin = model.linearize(
        &mut nominal.clone(),
        &mut EpochReport::new(0.0, model.kind(), "ekf"),
    );
    for (i, row) in lin.rows.iter().enumerate() {
        for k in 0..N {
            let mut dx = StateVector::zeros();
            dx[k] = 1e-4;
            let mut plus = nominal.clone();
            plus.apply_correction(&dx);
            let slope = (lin.predicted[i] - model.predict(&plus, &[i])[0]) / 1e-4;
            assert!(
                (slope - row[k]).abs() < 1e-4,
                "row {i}, state {k}: difference {slope}, H {}",
                row[k]
            );
        }
    }
}

/// A moving state whose position is known to `horizontal_m2` and `up_m2`, and a fix
/// without a covariance or a velocity `up_m` above it.
fn fix_above_state(horizontal_m2: f64, up_m2: f64, up_m: f64) -> (FilterState, GnssFix) {
    let mut state = moving_state(1e-4);
    let rad2 = (1.0 / earth::SEMI_MAJOR_AXIS_M).powi(2);
    for (i, var) in [horizontal_m2 * rad2, horizontal_m2 * rad2, up_m2]
        .into_iter()
        .enumerate()
    {
        state.p[(DP + i, DP + i)] = var;
    }
    let mut position = state.nav.p;
    position.height_m += up_m;
    let fix = GnssFix {
        t_s: 0.0,
        position,
        position_covariance_enu_m2: None,
        velocity_enu_mps: None,
        velocity_covariance_enu_m2_s2: None,
    };
    (state, fix)
}

/// A fix 300 m above a state that knows its height to 1 m (the configured σ 3 m) is an
/// outlier (95σ): deweighted, it moves the height by centimetres instead of the 30 m it
/// moved before `loose.fix_outlier_sigma` (with it off, as the IARF paper's filters), and
/// is flagged; a fix 2 m off is taken as before.
#[test]
fn a_fix_far_beyond_its_covariance_is_deweighted() {
    let moved_up_m = |offset_up_m: f64, outlier_sigma: f64| {
        let mut config = Config::default();
        config.filter.coupling = Coupling::Loose;
        config.loose.use_fix_covariance = false;
        config.loose.fix_outlier_sigma = outlier_sigma;
        let mut adaptation = Adaptation::new(&config);
        let (mut state, fix) = fix_above_state(1.0, 1.0, offset_up_m);
        let before_m = state.nav.p.height_m;
        let rate = Vector3::zeros();
        let mut model = FixMeasurement::new(&fix, &rate, &config, &state);
        let report = apply(&mut state, &mut model, &mut adaptation, true).unwrap();
        (state.nav.p.height_m - before_m, report.fix_position_outlier)
    };
    let (taken_m, flagged) = moved_up_m(300.0, 0.0);
    assert!((taken_m - 30.0).abs() < 0.5 && !flagged, "{taken_m}");
    let (deweighted_m, flagged) = moved_up_m(300.0, 5.0);
    assert!(deweighted_m.abs() < 0.2 && flagged, "{deweighted_m}");
    let (near_m, flagged) = moved_up_m(2.0, 5.0);
    assert_eq!((near_m, flagged), (moved_up_m(2.0, 0.0).0, false));
}

/// The fix judge goes on learning the claim while the fixes are held back by a leap: ten
/// held fixes 7 m off their claimed 1 m, whose hold allows 2 m more, leave the next fix
/// that is taken as it is with its claim scaled to what made the held ones typical, the
/// claim's share (about 16), not the hold's and the claim's together (4.1 with the hold
/// charged to the claim: the next fix, 7 m off, then weighed as 2 m).
#[test]
fn the_fix_judge_learns_the_claim_of_held_fixes() {
    let mut config = Config::default();
    config.filter.coupling = Coupling::Loose;
    config.loose.use_fix_covariance = false;
    config.loose.fix_sigma_horizontal_m = 1.0;
    config.loose.fix_sigma_vertical_m = 1.0;
    let mut adaptation = Adaptation::new(&config);
    let (mut state, fix) = fix_above_state(0.01, 1e-4, 7.0);
    let rate = Vector3::zeros();
    let hold = Matrix3::identity() * 4.0;
    for _ in 0..10 {
        let mut model =
            FixMeasurement::new(&fix, &rate, &config, &state).held_back(&Vector3::zeros(), &hold);
        apply(&mut state, &mut model, &mut adaptation, true).unwrap();
    }
    let mut model = FixMeasurement::new(&fix, &rate, &config, &state);
    let report = apply(&mut state, &mut model, &mut adaptation, true).unwrap();
    let scale = report.fix_scales[0];
    assert!((12.0..20.0).contains(&scale), "claim scaled by {scale}");
}
