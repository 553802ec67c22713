//! The zero-angular-rate update (ZARU): at a standstill the body turns only with the
//! earth, so the gyro's bias-compensated rate minus the earth rate is zero. It makes every
//! gyro bias observable at rest, the vertical one included, so heading stops drifting.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::earth;
use crate::filter::measurement_rows::Row;
use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::{GYRO_BIAS, GYRO_GM};

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};

/// The body was at rest over a window whose mean raw rate is `mean_raw_rad_s`: its
/// compensated rate is the earth rate, with σ `sigma_rad_s` per axis.
///
/// Math note: the raw rate is ω_true + b with b = b̂ + δb (the feedback adds δb̂ to the
/// estimate), so y = mean raw − b̂ − C_n^b ω_ie^n = δb_constant + δb_markov: H has I on both
/// gyro blocks. Choice: the attitude's part, −C_n^b [ω_ie^n ×] φ, is left out: 7e-5 rad/s
/// times an attitude error of milliradians is far below any gyro's noise.
pub struct ZeroRate {
    pub t_s: f64,
    pub mean_raw_rad_s: Vector3<f64>,
    pub sigma_rad_s: f64,
}

impl ZeroRate {
    /// The mean rate compensated with `state`'s biases, minus the earth rate, body axes.
    fn residual_rate(&self, state: &FilterState) -> Vector3<f64> {
        let w = self.mean_raw_rad_s - state.gyro_bias_rad_s - state.gyro_markov_rad_s;
        let earth_n = earth::earth_rate_enu_rad_s(state.nav.p.lat_rad);
        w - state.nav.q_nb.inverse_transform_vector(&earth_n)
    }
}

impl MeasurementModel for ZeroRate {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::ZeroRate
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let rows = (0..3)
            .map(|i| {
                let mut row = Row::zeros();
                row[GYRO_BIAS + i] = 1.0;
                row[GYRO_GM + i] = 1.0;
                row
            })
            .collect();
        Linearization {
            rows,
            measured: vec![0.0; 3],
            predicted: self.residual_rate(state).iter().copied().collect(),
            noise: NominalNoise::Joint(DMatrix::identity(3, 3) * self.sigma_rad_s.powi(2)),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let all = self.residual_rate(state);
        DVector::from_iterator(rows.len(), rows.iter().map(|&i| all[i]))
    }

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
