//! Everything of a variant that adapts or learns, handed to the measurement updates as one
//! value: the measurement-noise strategy, the update (base filter and IARF scheme) and the
//! process-noise scaling.

use crate::config::Config;

use super::adaptive_noise::NoiseModel;
use super::q_scaling::QScaling;
use super::robust_update::RobustUpdate;

/// The adaptive parts of the configured variant.
#[derive(Debug, Clone)]
pub struct Adaptation {
    /// Measurement variances R.
    pub noise: NoiseModel,
    /// Base filter and IARF scheme.
    pub update: RobustUpdate,
    /// Scale of the process noise Q.
    pub q: QScaling,
}

impl Adaptation {
    /// The adaptive parts of `config`.
    pub fn new(config: &Config) -> Self {
        Self {
            noise: NoiseModel::new(config),
            update: RobustUpdate::new(config),
            q: QScaling::new(config),
        }
    }

    /// Forgets everything learned (after a filter reset).
    pub fn reset(&mut self) {
        self.noise.reset();
        self.q.reset();
    }
}
