//! The loosely-coupled measurement update (the IARF paper's set-up): a GNSS receiver's
//! position fix, with an optional velocity, replaces the raw ranges.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::config::Config;
use crate::earth::{self, Llh};
use crate::filter::ekf::FilterError;
use crate::filter::measurement_rows::AntennaGeometry;
use crate::ins::error_state::N;

use super::adaptation::Adaptation;
use super::filter_state::FilterState;
use super::output::{EpochReport, MeasurementKind};
use super::robust_update::MeasurementSet;

/// A receiver's own solution of the antenna position (and optionally velocity).
#[derive(Debug, Clone, PartialEq)]
pub struct GnssFix {
    /// Time of validity (s) on the engine's time axis.
    pub t_s: f64,
    /// Antenna position (geodetic).
    pub position: Llh,
    /// Position covariance in ENU (m²); None: use the configured σ.
    pub position_covariance_enu_m2: Option<Matrix3<f64>>,
    /// Antenna velocity in ENU (m/s), if the receiver gives one.
    pub velocity_enu_mps: Option<Vector3<f64>>,
    /// Velocity covariance in ENU ((m/s)²); None: use the configured σ.
    pub velocity_covariance_enu_m2_s2: Option<Matrix3<f64>>,
}

impl GnssFix {
    /// True when every number the update uses is finite.
    pub fn is_finite(&self) -> bool {
        let finite3 = |m: &Option<Matrix3<f64>>| m.is_none_or(|m| m.iter().all(|v| v.is_finite()));
        self.t_s.is_finite()
            && self.position.is_finite()
            && finite3(&self.position_covariance_enu_m2)
            && self
                .velocity_enu_mps
                .is_none_or(|v| v.iter().all(|x| x.is_finite()))
            && finite3(&self.velocity_covariance_enu_m2_s2)
    }
}

/// The position covariance the update uses: the fix's own when configured and valid
/// (symmetric positive definite), else the configured diagonal.
fn position_covariance(fix: &GnssFix, config: &Config) -> Matrix3<f64> {
    let configured = Matrix3::from_diagonal(&Vector3::new(
        config.loose.fix_sigma_horizontal_m.powi(2),
        config.loose.fix_sigma_horizontal_m.powi(2),
        config.loose.fix_sigma_vertical_m.powi(2),
    ));
    match fix.position_covariance_enu_m2 {
        Some(c) if config.loose.use_fix_covariance && c.cholesky().is_some() => {
            (c + c.transpose()) * 0.5
        }
        _ => configured,
    }
}

fn velocity_covariance(fix: &GnssFix, config: &Config) -> Matrix3<f64> {
    let configured = Matrix3::identity() * config.loose.velocity_sigma_mps.powi(2);
    match fix.velocity_covariance_enu_m2_s2 {
        Some(c) if config.loose.use_fix_covariance && c.cholesky().is_some() => {
            (c + c.transpose()) * 0.5
        }
        _ => configured,
    }
}

/// The fix's innovation (predicted − measured) from `state`: the antenna position error in
/// the ENU frame `rot_ecef_to_enu` (held at the nominal point of the update, so every
/// cubature point is expressed in one frame), then the ENU velocity error when the fix has
/// a velocity.
fn fix_innovation(
    state: &FilterState,
    fix: &GnssFix,
    fix_ecef_m: &Vector3<f64>,
    rot_ecef_to_enu: &Matrix3<f64>,
    w_ib_b_rad_s: &Vector3<f64>,
    config: &Config,
) -> DVector<f64> {
    let geo = AntennaGeometry::new(&state.nav, &config.mounting.lever_arm_b_m, w_ib_b_rad_s);
    let y_pos = rot_ecef_to_enu * (geo.antenna_ecef_m(&state.nav.p) - fix_ecef_m);
    match fix.velocity_enu_mps {
        Some(v) => {
            let y_vel = state.nav.v_n + geo.lever_velocity_enu_mps() - v;
            DVector::from_iterator(6, y_pos.iter().chain(y_vel.iter()).copied())
        }
        None => DVector::from_iterator(3, y_pos.iter().copied()),
    }
}

/// Updates `state` with `fix` by the configured base filter and scheme; `adaptation`
/// learns from it unless `learn` is false (a fix re-applied after a roll-back).
///
/// Choice: the measured values of the loose model are taken as zero and the "prediction"
/// of a state is its innovation with respect to the fix, so the post-update residual of
/// Ding's eq. (14) is the innovation of the corrected state.
pub fn update(
    state: &mut FilterState,
    fix: &GnssFix,
    w_ib_b_rad_s: &Vector3<f64>,
    config: &Config,
    adaptation: &mut Adaptation,
    learn: bool,
) -> Result<EpochReport, FilterError> {
    let geo = AntennaGeometry::new(&state.nav, &config.mounting.lever_arm_b_m, w_ib_b_rad_s);
    let rot = earth::rot_ecef_to_enu(&state.nav.p);
    let fix_ecef = earth::llh_to_ecef(&fix.position);
    let y = fix_innovation(state, fix, &fix_ecef, &rot, w_ib_b_rad_s, config);
    let m = y.len();
    let mut h = DMatrix::zeros(m, N);
    let mut r = DMatrix::zeros(m, m);
    for (i, row) in geo.position_rows().iter().enumerate() {
        h.row_mut(i).copy_from(row);
    }
    r.view_mut((0, 0), (3, 3))
        .copy_from(&position_covariance(fix, config));
    if fix.velocity_enu_mps.is_some() {
        for (i, row) in geo.velocity_rows().iter().enumerate() {
            h.row_mut(3 + i).copy_from(row);
        }
        r.view_mut((3, 3), (3, 3))
            .copy_from(&velocity_covariance(fix, config));
    }
    let r = adaptation.noise.fix_covariance(&r);
    let predict = |s: &FilterState| {
        Some(fix_innovation(
            s,
            fix,
            &fix_ecef,
            &rot,
            w_ib_b_rad_s,
            config,
        ))
    };
    let set = MeasurementSet {
        h: h.clone(),
        y,
        r,
        predict: &predict,
    };
    let result = adaptation.update.update(state, &set)?;
    let mut report = EpochReport::new(fix.t_s, MeasurementKind::Fix, config);
    report.measurements_used = m;
    report.nis = result.nis;
    report.adaptive_factor = result.adaptive_factor;
    report.mahalanobis_d2 = result.mahalanobis_d2;
    report.chi2_threshold = result.chi2_threshold;
    report.q_scale = adaptation.q.scale();
    if result.robust_weights.iter().all(|w| w.is_finite()) {
        report.fix_robust_weights = result.robust_weights.iter().copied().collect();
    }
    if learn {
        adaptation
            .q
            .push(&result.innovation, &result.r, &result.hph);
        let residual = -fix_innovation(state, fix, &fix_ecef, &rot, w_ib_b_rad_s, config);
        let p = DMatrix::from_column_slice(N, N, state.p.as_slice());
        let hph = &h * p * h.transpose();
        adaptation
            .noise
            .after_fix_update(fix.t_s, &residual, &((&hph + hph.transpose()) * 0.5));
    }
    Ok(report)
}
