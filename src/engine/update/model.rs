//! What a measurement model gives the shared step: its rows of H, its measured and
//! predicted values and its nominal noise, linearized at the prior; its predictions of any
//! state; and what it writes into the report.

use nalgebra::{DMatrix, DVector};

use crate::filter::measurement_rows::Row;
use crate::filter::robust_update::UpdateOutcome;
use crate::gnss::SatId;

use super::super::adaptive_noise::{NoiseVerdict, Observable};
use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind};

/// One kind of measurement: what it measures, how it is predicted, its rows of H and its
/// nominal noise. The shared step ([`super::apply`]) does the rest: noise estimation,
/// gating, the robust update, the report's common fields and the learning.
///
/// Rows are referred to by their index in the [`Linearization`] the model returned.
pub trait MeasurementModel {
    /// Time of validity (s).
    fn t_s(&self) -> f64;

    /// What the report calls it.
    fn kind(&self) -> MeasurementKind;

    /// Screens the measurement against the prior `state` and linearizes what passes, noting
    /// what was left out and why in `report`. A model may correct the state first where the
    /// measurement shows a discontinuity the filter does not model (a receiver clock jump).
    fn linearize(&mut self, state: &mut FilterState, report: &mut EpochReport) -> Linearization;

    /// The predicted values of `rows` from `state`, in that order; NaN where a prediction
    /// fails. Evaluated at the cubature points and at the corrected state.
    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64>;

    /// Notes the variance the noise strategy gave `row` (per-row noise only).
    fn report_noise(&self, _report: &mut EpochReport, _row: usize, _verdict: &NoiseVerdict) {}

    /// Notes that the innovation gate left `row` out: its innovation measured − predicted
    /// and that divided by √S.
    fn report_gated(
        &self,
        _report: &mut EpochReport,
        _row: usize,
        _innovation: f64,
        _normalized: f64,
    ) {
    }

    /// Notes that block `block` of a [`NominalNoise::JointBlocks`] measurement lay at the
    /// Mahalanobis distance `sigmas` beyond its outlier σ and was deweighted (NaN: its
    /// covariance was not positive definite, and it was left out).
    fn report_outlying_block(&self, _report: &mut EpochReport, _block: usize, _sigmas: f64) {}

    /// Notes the update of `rows`, in the order of `outcome`'s vectors.
    fn report_update(&self, report: &mut EpochReport, rows: &[usize], outcome: &UpdateOutcome);
}

/// The screened measurements linearized at the prior.
pub struct Linearization {
    /// Row i of H (δx in the error state of [`crate::ins::error_state`]).
    pub rows: Vec<Row>,
    /// Measured value of each row.
    pub measured: Vec<f64>,
    /// Value of each row predicted from the prior, so y = predicted − measured.
    pub predicted: Vec<f64>,
    pub noise: NominalNoise,
}

/// The noise of the measurement before the strategy of the variant has its say.
pub enum NominalNoise {
    /// Independent scalar measurements (R diagonal), each learned by the strategy on its
    /// own channel and gated on its own.
    PerRow {
        channels: Vec<NoiseChannel>,
        /// Innovation gate in units of √S (0 = off).
        gate_sigma: f64,
    },
    /// One covariance of the whole measurement (m × m), learned as a whole; no gate (a
    /// row of correlated measurements is not an outlier on its own: the robust schemes
    /// weigh them).
    Joint(DMatrix<f64>),
    /// As [`NominalNoise::Joint`], in blocks: the rows fall into consecutive blocks of
    /// the given lengths (a fix's position, then its velocity), and a block whose
    /// Mahalanobis distance √(yᵀS⁻¹y) under its innovation covariance exceeds
    /// `outlier_sigma` is deweighted (0 = off; see `Step::deweight_outlying_blocks`).
    JointBlocks {
        /// The covariance the measurement claims (a receiver's).
        r: DMatrix<f64>,
        /// What the rows are known to err by beyond the claim (a held-back fix's
        /// offset, see `engine::dispute`): added to R after the claim is judged and
        /// adapted, and charged, like the filter's H P Hᵀ, not to the claim.
        beyond_claim: Option<DMatrix<f64>>,
        block_lengths: Vec<usize>,
        outlier_sigma: f64,
    },
}

/// A scalar measurement's channel and nominal variance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseChannel {
    /// The satellite and observable whose estimator learns the variance.
    pub sat: SatId,
    pub observable: Observable,
    /// The variance of the fixed σ model.
    pub r_nominal: f64,
    /// The variance of the slow error part added to an estimated variance
    /// (`adaptive.pseudorange_slow_sigma_m`; 0 for rates).
    pub r_slow: f64,
    /// The satellite's carrier-to-noise density ratio (dB-Hz), when reported.
    pub cn0_dbhz: Option<f64>,
}
