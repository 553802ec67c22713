//! The measurement-noise strategies of the filter variants: fixed (ekf and the IARF-paper
//! variants), innovation-based (eiakf), redundant-measurement based (srmakf, ermakf) and
//! residual-based (residual_akf). Each is asked, per epoch, for the variance R of every
//! scalar measurement, one estimator per satellite and observable.

mod innovation;
mod redundant;
mod residual;

use std::collections::hash_map::Entry;
use std::collections::HashMap;

use nalgebra::{DMatrix, DVector};

use crate::config::{Config, NoiseStrategy};
use crate::filter::measurement_rows::Row;
use crate::gnss::SatId;

use super::output::MeasurementKind;

pub use innovation::InnovationNoise;
pub use redundant::RedundantNoise;
pub use residual::ResidualNoise;

/// Which observable a scalar measurement is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Observable {
    Pseudorange,
    PseudorangeRate,
}

/// One scalar measurement of an epoch, as the noise strategies see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalarMeasurement {
    pub sat: SatId,
    pub observable: Observable,
    /// The receiver's value (m or m/s).
    pub measured: f64,
    /// The value predicted from the prior (INS) state (m or m/s).
    pub predicted: f64,
    /// h P⁻ hᵀ of its row.
    pub hph: f64,
    /// Its row of H (the redundant strategy's correlation-aware option takes the
    /// geometry of the error common to all satellites from it).
    pub row: Row,
    /// The variance of the fixed σ model (gnss.*), used until an estimate is trusted.
    pub r_nominal: f64,
    /// The variance of the slow error part that the estimators do not see
    /// (`adaptive.pseudorange_slow_sigma_m` by elevation; 0 for rates), added to an
    /// estimate.
    pub r_slow: f64,
}

/// A strategy's answer for one scalar measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseVerdict {
    /// The variance to use.
    pub r: f64,
    /// True when `r` is an online estimate (false: the nominal variance).
    pub estimated: bool,
    /// KDE density of the newest mutual difference (NaN: not computed).
    pub kde_credibility: f64,
    /// Gaussian verdict of the KDE test (None: not computed).
    pub gaussian: Option<bool>,
    /// Order of the AR model in use (None: not in use).
    pub ar_order: Option<u8>,
}

impl NoiseVerdict {
    /// The nominal variance, nothing estimated.
    pub fn nominal(r: f64) -> Self {
        Self {
            r,
            estimated: false,
            kde_credibility: f64::NAN,
            gaussian: None,
            ar_order: None,
        }
    }
}

/// The noise strategy of the configured variant.
#[derive(Debug, Clone)]
pub enum NoiseModel {
    /// The fixed σ model of `gnss.*`.
    Fixed,
    Innovation(Box<InnovationNoise>),
    Redundant(Box<RedundantNoise>),
    /// Ding, Wang and Rizos' residual-based R, eqs. (14)–(15).
    Residual(Box<ResidualNoise>),
}

impl NoiseModel {
    /// The strategy of the configured variant's row of the variant table.
    pub fn new(config: &Config) -> Self {
        match config.filter.variant.spec().noise {
            NoiseStrategy::Fixed => Self::Fixed,
            NoiseStrategy::Innovation => Self::Innovation(Box::new(InnovationNoise::new(config))),
            NoiseStrategy::RedundantSimple => {
                Self::Redundant(Box::new(RedundantNoise::new(config, false)))
            }
            NoiseStrategy::RedundantEnhanced => {
                Self::Redundant(Box::new(RedundantNoise::new(config, true)))
            }
            NoiseStrategy::Residual => Self::Residual(Box::new(ResidualNoise::new(config))),
        }
    }

    /// The variances of an epoch's measurements, in the same order: an estimate plus the
    /// slow part its estimator cannot see (`ScalarMeasurement::r_slow`), or the nominal
    /// variance. With `learn` false (measurements re-applied after a roll-back) the
    /// estimators are only read.
    pub fn variances(
        &mut self,
        t_s: f64,
        rows: &[ScalarMeasurement],
        learn: bool,
    ) -> Vec<NoiseVerdict> {
        let mut verdicts = self.strategy_variances(t_s, rows, learn);
        for (verdict, row) in verdicts.iter_mut().zip(rows) {
            if verdict.estimated {
                verdict.r += row.r_slow;
            }
        }
        verdicts
    }

    /// The strategy's own variances (the estimate, without the slow part).
    fn strategy_variances(
        &mut self,
        t_s: f64,
        rows: &[ScalarMeasurement],
        learn: bool,
    ) -> Vec<NoiseVerdict> {
        match self {
            Self::Redundant(m) => m.variances(t_s, rows, learn),
            _ => rows
                .iter()
                .map(|row| match self {
                    Self::Innovation(m) => m.variance(t_s, row, learn),
                    Self::Residual(m) => m.variance(row),
                    Self::Fixed | Self::Redundant(_) => NoiseVerdict::nominal(row.r_nominal),
                })
                .collect(),
        }
    }

    /// True when the strategy needs the predictions of the corrected state.
    pub fn wants_posterior_predictions(&self) -> bool {
        matches!(self, Self::Redundant(_) | Self::Residual(_))
    }

    /// True when the strategy also needs h P̂ hᵀ of the posterior covariance per
    /// measurement (only the residual-based one; the redundant-measurement estimators are
    /// independent of the state's covariance, and the 24 products cost more than their
    /// whole KDE).
    pub fn wants_posterior_hph(&self) -> bool {
        matches!(self, Self::Residual(_))
    }

    /// Hands over the measurements with their predictions from the corrected state and
    /// their h P̂ hᵀ of the posterior covariance (empty unless [`Self::wants_posterior_hph`]).
    pub fn after_update(
        &mut self,
        t_s: f64,
        rows: &[ScalarMeasurement],
        posterior: &[f64],
        posterior_hph: &[f64],
    ) {
        match self {
            Self::Redundant(m) => m.after_update(t_s, rows, posterior),
            Self::Residual(m) => m.after_update(t_s, rows, posterior, posterior_hph),
            Self::Fixed | Self::Innovation(_) => {}
        }
    }

    /// The covariance of a measurement whose noise is one matrix (a receiver fix). Only
    /// the residual-based strategy estimates it, one window per kind of measurement; the
    /// others are per-satellite strategies and give `nominal` back.
    pub fn joint_covariance(
        &self,
        kind: MeasurementKind,
        t_s: f64,
        nominal: &DMatrix<f64>,
    ) -> DMatrix<f64> {
        match self {
            Self::Residual(m) => m.joint_covariance(kind, t_s, nominal),
            Self::Fixed | Self::Innovation(_) | Self::Redundant(_) => nominal.clone(),
        }
    }

    /// Hands over the post-update residual ε = z − H x̂ of such a measurement, its
    /// H P̂ Hᵀ and the normalised innovation squared of the update's prior.
    pub fn after_joint_update(
        &mut self,
        kind: MeasurementKind,
        t_s: f64,
        residual: &DVector<f64>,
        hph: &DMatrix<f64>,
        prior_nis: f64,
    ) {
        if let Self::Residual(m) = self {
            m.after_joint_update(kind, t_s, residual, hph, prior_nis);
        }
    }

    /// Forgets every estimate (after a filter reset).
    pub fn reset(&mut self) {
        match self {
            Self::Fixed => {}
            Self::Innovation(m) => m.reset(),
            Self::Redundant(m) => m.reset(),
            Self::Residual(m) => m.reset(),
        }
    }
}

/// The bounds of `adaptive.*` on an estimated variance, per observable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VarianceBounds {
    pseudorange_m2: (f64, f64),
    rate_m2_s2: (f64, f64),
}

impl VarianceBounds {
    pub(crate) fn new(config: &Config) -> Self {
        let a = &config.adaptive;
        Self {
            pseudorange_m2: (
                a.pseudorange_sigma_min_m.powi(2),
                a.pseudorange_sigma_max_m.powi(2),
            ),
            rate_m2_s2: (
                a.pseudorange_rate_sigma_min_mps.powi(2),
                a.pseudorange_rate_sigma_max_mps.powi(2),
            ),
        }
    }

    /// (minimum, maximum) variance of `observable`.
    pub(crate) fn of(&self, observable: Observable) -> (f64, f64) {
        match observable {
            Observable::Pseudorange => self.pseudorange_m2,
            Observable::PseudorangeRate => self.rate_m2_s2,
        }
    }
}

/// The track of `row`'s satellite and observable in `tracks`, made by `new_track` when it
/// is first seen. None when `new_track` fails: the estimator options were validated with
/// the configuration, so that would be a programming error, and the caller falls back to
/// the nominal variance (or learns nothing).
pub(crate) fn track_for<'a, T, E>(
    tracks: &'a mut HashMap<(SatId, Observable), T>,
    row: &ScalarMeasurement,
    new_track: impl FnOnce() -> Result<T, E>,
) -> Option<&'a mut T> {
    match tracks.entry((row.sat, row.observable)) {
        Entry::Occupied(e) => Some(e.into_mut()),
        Entry::Vacant(e) => new_track().ok().map(|track| e.insert(track)),
    }
}

/// A seed per satellite and observable derived from the configured one, so that every
/// estimator draws its own reproducible random weights.
pub(crate) fn estimator_seed(base: u64, sat: SatId, observable: Observable) -> u64 {
    let id = (u64::from(sat.constellation.code()) << 17)
        | (u64::from(sat.prn) << 1)
        | u64::from(observable == Observable::PseudorangeRate);
    base.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(id)
}
