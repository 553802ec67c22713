//! The dual-antenna heading: the compass heading of the baseline between a moving-base
//! receiver's antenna and its rover's (`dual_antenna.*`), as the pair measures it.
//!
//! Math note: the baseline in the navigation frame (ENU) is u = C_b^n b, b the baseline in
//! the body frame, and its heading ψ = atan2(u_E, u_N) (clockwise from north, the tilt of
//! the baseline left out as the receiver leaves it out). With C_b^n(true) = exp(φ×)
//! C_b^n(computed), u(computed) − u(true) = −φ × u = [u×] φ, so ψ(computed) − ψ(true) =
//! g [u×] φ with g = ∂ψ/∂u = (u_N, −u_E, 0) / (u_E² + u_N²). Nothing else enters.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::filter::measurement_rows::{row_variance, Row};
use crate::filter::robust_update::UpdateOutcome;
use crate::ins::error_state::PHI;
use crate::ins::mechanization::wrap_pi;

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};
use super::model::{Linearization, MeasurementModel, NominalNoise};

/// The heading of the baseline `baseline_b_m` (body frame) at the state's last IMU
/// sample is `heading_rad` (compass), with σ `sigma_rad`; an innovation beyond
/// `gate_sigma` of its own σ is left out (no rows: the caller counts it).
pub struct BaselineHeading<'a> {
    pub t_s: f64,
    pub baseline_b_m: &'a Vector3<f64>,
    pub heading_rad: f64,
    pub sigma_rad: f64,
    pub gate_sigma: f64,
}

/// Choice: a baseline whose horizontal part in the navigation frame is below this
/// fraction of its length (pointing within 0.6° of the vertical) has no heading to
/// predict.
const MIN_HORIZONTAL_FRACTION: f64 = 0.01;

impl BaselineHeading<'_> {
    /// The baseline in the navigation frame (ENU), None when it has no horizontal
    /// direction.
    fn baseline_n(&self, state: &FilterState) -> Option<Vector3<f64>> {
        let u = state.nav.q_nb.transform_vector(self.baseline_b_m);
        (u.xy().norm() > MIN_HORIZONTAL_FRACTION * u.norm()).then_some(u)
    }

    /// The predicted heading, wrapped to within π of the measured one (NaN without a
    /// horizontal baseline).
    fn predicted_rad(&self, state: &FilterState) -> f64 {
        self.baseline_n(state).map_or(f64::NAN, |u| {
            self.heading_rad + wrap_pi(u[0].atan2(u[1]) - self.heading_rad)
        })
    }
}

impl MeasurementModel for BaselineHeading<'_> {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::BaselineHeading
    }

    fn linearize(&mut self, state: &mut FilterState, _report: &mut EpochReport) -> Linearization {
        let none = Linearization {
            rows: Vec::new(),
            measured: Vec::new(),
            predicted: Vec::new(),
            noise: NominalNoise::Joint(DMatrix::zeros(0, 0)),
        };
        let Some(u) = self.baseline_n(state) else {
            return none;
        };
        let g = Vector3::new(u[1], -u[0], 0.0) / u.xy().norm_squared();
        let mut row = Row::zeros();
        row.fixed_view_mut::<1, 3>(0, PHI)
            .copy_from(&(g.transpose() * u.cross_matrix()));
        let variance = self.sigma_rad.powi(2);
        let predicted = self.predicted_rad(state);
        let innovation_sigma = (variance + row_variance(&row, &state.p)).sqrt();
        if (predicted - self.heading_rad).abs() > self.gate_sigma * innovation_sigma {
            return none;
        }
        Linearization {
            rows: vec![row],
            measured: vec![self.heading_rad],
            predicted: vec![predicted],
            noise: NominalNoise::Joint(DMatrix::from_element(1, 1, variance)),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        DVector::from_element(rows.len(), self.predicted_rad(state))
    }

    fn report_update(&self, _report: &mut EpochReport, _rows: &[usize], _: &UpdateOutcome) {}
}
