//! Everything of a variant that adapts or learns, handed to the shared measurement step
//! ([`super::update`]) as one value: the measurement-noise strategy, the update (base
//! filter and IARF scheme) and the process-noise scaling. What the variant is made of comes
//! from its row of the variant table ([`crate::config::VARIANTS`]); this is where each
//! column becomes its strategy object.

use nalgebra::Matrix3;

use crate::adaptive::adaptive_factor::{AdaptiveFactorFunction, AdaptiveFactorOptions};
use crate::adaptive::equivalent_covariance::{EquivalentWeightFunction, EquivalentWeightOptions};
use crate::config::{AdaptiveFactorKind, Config, EquivalentWeightKind, RobustScheme};
use crate::filter::robust_update::{RobustUpdate, Scheme};

use super::adaptive_noise::{NoiseModel, Observable};
use super::error_correlation::ErrorCorrelation;
use super::fix_consistency::FixConsistency;
use super::q_scaling::QScaling;

/// The adaptive parts of the configured variant.
#[derive(Debug, Clone)]
pub struct Adaptation {
    /// The variant's name, for the reports.
    pub variant: &'static str,
    /// Measurement variances R.
    pub noise: NoiseModel,
    /// Base filter and IARF scheme.
    pub update: RobustUpdate,
    /// Scale of the process noise Q.
    pub q: QScaling,
    /// The judges of the receiver fixes' claimed covariance (loose coupling): of the
    /// position, and of the velocity.
    pub fix: [FixConsistency; 2],
    /// The judge of the satellites' error correlation (tight coupling).
    pub correlation: ErrorCorrelation,
}

impl Adaptation {
    /// The adaptive parts of `config`.
    pub fn new(config: &Config) -> Self {
        Self {
            variant: config.filter.variant.as_str(),
            noise: NoiseModel::new(config),
            update: robust_update(config),
            q: QScaling::new(config),
            fix: [(); 2].map(|()| FixConsistency::new(config.loose.fix_consistency)),
            correlation: ErrorCorrelation::new(
                config.gnss.error_correlation,
                config.gnss.error_correlation_max_inflation,
                config.adaptive.max_epoch_gap_s,
            ),
        }
    }

    /// What the judges found beyond the measurements' claims, as the covariances the
    /// published solution is at least (ENU): the position's (m²) and the velocity's
    /// ((m/s)²). See `FixConsistency::unclaimed_covariance` and [`super::range_excess`].
    pub fn unclaimed_covariances(&self) -> (Matrix3<f64>, Matrix3<f64>) {
        let ranges = |o| self.correlation.unclaimed_covariance(o);
        (
            self.fix[0].unclaimed_covariance() + ranges(Observable::Pseudorange),
            self.fix[1].unclaimed_covariance() + ranges(Observable::PseudorangeRate),
        )
    }

    /// Forgets everything learned (after a filter reset).
    pub fn reset(&mut self) {
        self.noise.reset();
        self.q.reset();
        self.fix.iter_mut().for_each(FixConsistency::reset);
        self.correlation.reset();
    }
}

/// The update of the configuration: the variant's base filter and scheme with the
/// constants of `robust.*`.
fn robust_update(config: &Config) -> RobustUpdate {
    let r = &config.robust;
    let function = match r.adaptive_factor_function {
        AdaptiveFactorKind::TwoSegment => AdaptiveFactorFunction::TwoSegment {
            c: r.adaptive_factor_c,
        },
        AdaptiveFactorKind::ThreeSegment => AdaptiveFactorFunction::ThreeSegment {
            c0: r.adaptive_factor_c0,
            c1: r.adaptive_factor_c1,
        },
    };
    let weight_function = match r.equivalent_weight_function {
        EquivalentWeightKind::DoubleFactor => EquivalentWeightFunction::DoubleFactor {
            c: r.double_factor_c,
        },
        EquivalentWeightKind::Igg3 => EquivalentWeightFunction::Igg3 {
            k0: r.igg3_k0,
            k1: r.igg3_k1,
        },
    };
    let scheme = match config.filter.variant.spec().scheme {
        RobustScheme::Plain => Scheme::Plain,
        RobustScheme::AdaptiveAll => Scheme::AdaptiveAll,
        RobustScheme::AdaptivePartial => Scheme::AdaptivePartial,
        RobustScheme::AdaptivelyRobust => Scheme::AdaptivelyRobust,
    };
    RobustUpdate {
        cubature: config.filter.uses_cubature(),
        scheme,
        factor: AdaptiveFactorOptions {
            function,
            alpha_floor: r.alpha_floor,
        },
        weights: EquivalentWeightOptions {
            function: weight_function,
            max_variance_inflation: r.max_variance_inflation,
        },
        chi2_confidence: r.chi2_confidence,
        joseph: config.filter.joseph_form,
    }
}
