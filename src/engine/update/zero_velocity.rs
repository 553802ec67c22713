//! The zero-velocity update (ZUPT): at a standstill the IMU's ENU velocity is zero.

use nalgebra::{DMatrix, DVector};

use crate::filter::measurement_rows::Row;
use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::DV;

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};

/// The body is at rest at `t_s`: each ENU velocity component is zero with σ `sigma_mps`.
///
/// Math note: y = v^n(computed) − 0 = δV, so H = [0 I 0 ...]. The whole body is at rest,
/// so the IMU's point needs no lever arm.
pub struct ZeroVelocity {
    pub t_s: f64,
    pub sigma_mps: f64,
}

impl MeasurementModel for ZeroVelocity {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::ZeroVelocity
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

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
