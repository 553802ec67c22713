//! The shared step with a model of its own: a zero-velocity measurement written the way
//! the recipe in the module documentation says (rows, prediction, nominal noise, report).

use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};

use crate::config::{Config, FilterVariant};
use crate::earth::Llh;
use crate::filter::measurement_rows::Row;
use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::{StateMatrix, DV};
use crate::ins::{ImuSample, NavState};

use super::super::adaptation::Adaptation;
use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::{apply, Linearization, MeasurementModel, NominalNoise};

/// The body is at rest: the ENU velocity is zero, with σ `sigma_mps` per axis.
struct ZeroVelocity {
    t_s: f64,
    sigma_mps: f64,
}

impl MeasurementModel for ZeroVelocity {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        // Choice: a test model borrows the kind whose report fields it fills.
        MeasurementKind::Fix
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let rows = (0..3)
            .map(|i| {
                let mut row = Row::zeros();
                row[DV + i] = 1.0;
                row
            })
            .collect();
        Linearization {
            rows,
            measured: vec![0.0; 3],
            predicted: state.nav.v_n.iter().copied().collect(),
            noise: NominalNoise::Joint(DMatrix::identity(3, 3) * self.sigma_mps.powi(2)),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        DVector::from_iterator(rows.len(), rows.iter().map(|&i| state.nav.v_n[i]))
    }

    fn report_update(&self, report: &mut EpochReport, _rows: &[usize], outcome: &UpdateOutcome) {
        report.fix_robust_weights = outcome.robust_weights.iter().copied().collect();
    }
}

fn moving_state(p_velocity_m2_s2: f64) -> FilterState {
    let imu = ImuSample {
        t_s: 0.0,
        w_ib_b_rad_s: Vector3::zeros(),
        f_ib_b_m_s2: Vector3::new(0.0, 0.0, 9.8),
    };
    FilterState {
        nav: NavState {
            t_s: 0.0,
            p: Llh::from_degrees(39.1, 117.2, 20.0),
            v_n: Vector3::new(0.5, -0.2, 0.1),
            q_nb: UnitQuaternion::identity(),
        },
        gyro_bias_rad_s: Vector3::zeros(),
        gyro_markov_rad_s: Vector3::zeros(),
        accel_bias_m_s2: Vector3::zeros(),
        clock_bias_m: 0.0,
        clock_drift_mps: 0.0,
        p: StateMatrix::identity() * p_velocity_m2_s2,
        prev_increment: None,
        last_imu: imu,
        phase_anchor: None,
    }
}

fn run(variant: FilterVariant) -> (FilterState, EpochReport) {
    let mut config = Config::default();
    config.filter.variant = variant;
    let mut adaptation = Adaptation::new(&config);
    let mut state = moving_state(1e-2);
    let mut model = ZeroVelocity {
        t_s: 1.0,
        sigma_mps: 0.01,
    };
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
