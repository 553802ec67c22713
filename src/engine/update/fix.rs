//! The loosely-coupled measurement model (the IARF paper's set-up): a GNSS receiver's
//! position fix, with an optional velocity, replaces the raw ranges.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::config::{Config, RobustScheme};
use crate::earth::{self, Llh};
use crate::filter::measurement_rows::AntennaGeometry;
use crate::filter::robust_update::UpdateOutcome;

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};

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

/// A fix as a measurement of the antenna position (E, N, U), then its velocity (E, N, U)
/// when it has one.
///
/// Choice: the measured values are taken as zero and the "prediction" of a state is its
/// innovation with respect to the fix, so the post-update residual of Ding's eq. (14) is
/// the innovation of the corrected state.
pub struct FixMeasurement<'a> {
    fix: &'a GnssFix,
    w_ib_b_rad_s: &'a Vector3<f64>,
    config: &'a Config,
    fix_ecef_m: Vector3<f64>,
    /// The ENU frame at the prior, held for every state the update predicts from, so that
    /// every cubature point is expressed in one frame.
    rot_ecef_to_enu: Matrix3<f64>,
    /// The covariance the position is known to beyond its own when it is held back by a
    /// GNSS leap ([`FixMeasurement::held_back`]).
    hold_covariance_enu_m2: Option<Matrix3<f64>>,
}

impl<'a> FixMeasurement<'a> {
    /// The fix as seen from the prior state; `w_ib_b_rad_s` is the compensated body rate
    /// at the fix (for the lever-arm velocity).
    pub fn new(
        fix: &'a GnssFix,
        w_ib_b_rad_s: &'a Vector3<f64>,
        config: &'a Config,
        prior: &FilterState,
    ) -> Self {
        Self {
            fix,
            w_ib_b_rad_s,
            config,
            fix_ecef_m: earth::llh_to_ecef(&fix.position),
            rot_ecef_to_enu: earth::rot_ecef_to_enu(&prior.nav.p),
            hold_covariance_enu_m2: None,
        }
    }

    /// The fix held back by a GNSS leap (see `engine::dispute`): its position moved back
    /// by the leap's offset `offset_enu_m` (GNSS less filter, m), its covariance grown by
    /// `covariance_enu_m2` (m²).
    pub fn held_back(self, offset_enu_m: &Vector3<f64>, covariance_enu_m2: &Matrix3<f64>) -> Self {
        let offset_ecef_m = self.rot_ecef_to_enu.transpose() * offset_enu_m;
        Self {
            fix_ecef_m: self.fix_ecef_m - offset_ecef_m,
            hold_covariance_enu_m2: Some(*covariance_enu_m2),
            ..self
        }
    }

    /// The fix's innovation (predicted − measured) from `state`: the antenna position error
    /// in the held ENU frame, then the ENU velocity error when the fix has a velocity.
    fn innovation(&self, state: &FilterState) -> DVector<f64> {
        let geo = AntennaGeometry::new(
            &state.nav,
            &self.config.mounting.lever_arm_b_m,
            self.w_ib_b_rad_s,
        );
        let y_pos = self.rot_ecef_to_enu * (geo.antenna_ecef_m(&state.nav.p) - self.fix_ecef_m);
        match self.fix.velocity_enu_mps {
            Some(v) => {
                let y_vel = state.nav.v_n + geo.lever_velocity_enu_mps() - v;
                DVector::from_iterator(6, y_pos.iter().chain(y_vel.iter()).copied())
            }
            None => DVector::from_iterator(3, y_pos.iter().copied()),
        }
    }
}

impl MeasurementModel for FixMeasurement<'_> {
    fn t_s(&self) -> f64 {
        self.fix.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::Fix
    }

    fn linearize(&mut self, state: &mut FilterState, report: &mut EpochReport) -> Linearization {
        let geo = AntennaGeometry::new(
            &state.nav,
            &self.config.mounting.lever_arm_b_m,
            self.w_ib_b_rad_s,
        );
        let predicted: Vec<f64> = self.innovation(state).iter().copied().collect();
        let m = predicted.len();
        let mut rows = geo.position_rows().to_vec();
        let mut r = DMatrix::zeros(m, m);
        r.view_mut((0, 0), (3, 3))
            .copy_from(&position_covariance(self.fix, self.config));
        let beyond_claim = self.hold_covariance_enu_m2.map(|held| {
            let mut beyond = DMatrix::zeros(m, m);
            beyond.view_mut((0, 0), (3, 3)).copy_from(&held);
            beyond
        });
        report.fix_held_back = beyond_claim.is_some();
        if self.fix.velocity_enu_mps.is_some() {
            rows.extend(geo.velocity_rows());
            r.view_mut((3, 3), (3, 3))
                .copy_from(&velocity_covariance(self.fix, self.config));
        }
        let block_lengths = if m == 6 { vec![3, 3] } else { vec![3] };
        Linearization {
            rows,
            measured: vec![0.0; m],
            predicted,
            noise: NominalNoise::JointBlocks {
                r,
                beyond_claim,
                block_lengths,
                outlier_sigma: outlier_sigma(self.config),
            },
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let all = self.innovation(state);
        DVector::from_iterator(rows.len(), rows.iter().map(|&i| all[i]))
    }

    fn report_outlying_block(&self, report: &mut EpochReport, block: usize, _sigmas: f64) {
        match block {
            0 => report.fix_position_outlier = true,
            _ => report.fix_velocity_outlier = true,
        }
    }

    /// The robust weights of every row of the fix, 0 for a row left out.
    fn report_update(&self, report: &mut EpochReport, rows: &[usize], outcome: &UpdateOutcome) {
        let weights = &outcome.robust_weights;
        if weights.len() == rows.len() && weights.iter().all(|w| w.is_finite()) {
            let m = if self.fix.velocity_enu_mps.is_some() {
                6
            } else {
                3
            };
            let mut all = vec![0.0; m];
            for (&row, &w) in rows.iter().zip(weights.iter()) {
                all[row] = w;
            }
            report.fix_robust_weights = all;
        }
    }
}

/// The outlier σ of a fix's blocks: `loose.fix_outlier_sigma`, or 0 (off) for a variant
/// whose scheme inflates R for outlying residuals itself at every epoch (iarf's robust R̄:
/// both together deweighted an outlier twice and cost iarf 10 % of its RMSE on the
/// canyon of tests/consumer_mems_drive.rs).
fn outlier_sigma(config: &Config) -> f64 {
    match config.filter.variant.spec().scheme {
        RobustScheme::AdaptivelyRobust => 0.0,
        RobustScheme::Plain | RobustScheme::AdaptiveAll | RobustScheme::AdaptivePartial => {
            config.loose.fix_outlier_sigma
        }
    }
}

/// The position covariance the update uses: the fix's own when configured and valid
/// (symmetric positive definite), else the configured diagonal.
pub(crate) fn position_covariance(fix: &GnssFix, config: &Config) -> Matrix3<f64> {
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

/// The velocity covariance the update uses (as [`position_covariance`]).
pub(crate) fn velocity_covariance(fix: &GnssFix, config: &Config) -> Matrix3<f64> {
    let configured = Matrix3::identity() * config.loose.velocity_sigma_mps.powi(2);
    match fix.velocity_covariance_enu_m2_s2 {
        Some(c) if config.loose.use_fix_covariance && c.cholesky().is_some() => {
            (c + c.transpose()) * 0.5
        }
        _ => configured,
    }
}
