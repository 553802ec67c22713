//! The loosely-coupled measurement update (the IARF paper's set-up): a GNSS receiver's
//! position fix, with an optional velocity, replaces the raw ranges.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::config::Config;
use crate::earth::{self, Llh};
use crate::filter::ekf::{self, FilterError};
use crate::filter::measurement_rows::AntennaGeometry;
use crate::ins::error_state::N;

use super::filter_state::FilterState;
use super::output::{EpochReport, MeasurementKind};

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

/// Updates `state` with `fix`.
pub fn update(
    state: &mut FilterState,
    fix: &GnssFix,
    w_ib_b_rad_s: &Vector3<f64>,
    config: &Config,
) -> Result<EpochReport, FilterError> {
    let geo = AntennaGeometry::new(&state.nav, &config.mounting.lever_arm_b_m, w_ib_b_rad_s);
    // Position innovation in the ENU frame at the nominal point (predicted − measured).
    let predicted_ecef = geo.antenna_ecef_m(&state.nav.p);
    let y_pos =
        earth::rot_ecef_to_enu(&state.nav.p) * (predicted_ecef - earth::llh_to_ecef(&fix.position));
    let with_velocity = fix.velocity_enu_mps.is_some();
    let m = if with_velocity { 6 } else { 3 };
    let mut h = DMatrix::zeros(m, N);
    let mut y = DVector::zeros(m);
    let mut r = DMatrix::zeros(m, m);
    for (i, row) in geo.position_rows().iter().enumerate() {
        h.row_mut(i).copy_from(row);
        y[i] = y_pos[i];
    }
    r.view_mut((0, 0), (3, 3))
        .copy_from(&position_covariance(fix, config));
    if let Some(v) = fix.velocity_enu_mps {
        let y_vel = state.nav.v_n + geo.lever_velocity_enu_mps() - v;
        for (i, row) in geo.velocity_rows().iter().enumerate() {
            h.row_mut(3 + i).copy_from(row);
            y[3 + i] = y_vel[i];
        }
        r.view_mut((3, 3), (3, 3))
            .copy_from(&velocity_covariance(fix, config));
    }
    let result = ekf::update(&state.p, &h, &y, &r, config.filter.joseph_form)?;
    state.p = result.p;
    state.apply_correction(&result.dx);
    let mut report = EpochReport::new(fix.t_s, MeasurementKind::Fix, config);
    report.measurements_used = m;
    report.nis = result.nis;
    Ok(report)
}
