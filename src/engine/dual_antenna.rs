//! The dual-antenna heading (`dual_antenna.*`): a moving-base pair's baseline heading as
//! it waits for its time, its screening, and what it becomes: the start's heading at rest
//! ([`super::initializer`]) or a measurement of the running filter
//! ([`update::BaselineHeading`]).

use crate::config::Config;

use super::initializer::AntennaHeading;
use super::rejection::RejectionReason;
use super::update::BaselineHeading;

/// How the pair resolved its carrier phases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CarrierSolution {
    /// Ambiguities not fixed: the baseline is a float solution.
    Float,
    /// Ambiguities fixed.
    Fixed,
}

/// One heading of the baseline from the moving base's antenna to the rover's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaselineHeadingReading {
    /// Time of validity (s).
    pub t_s: f64,
    /// Heading of the baseline, clockwise from north (rad).
    pub heading_rad: f64,
    /// Its 1-sigma as the receiver reports it (rad).
    pub sigma_rad: f64,
    /// Length of the baseline (m).
    pub length_m: f64,
    pub carrier: CarrierSolution,
}

impl BaselineHeadingReading {
    /// Whether the numbers are finite, the σ positive and the length positive.
    fn is_valid(&self) -> bool {
        [self.t_s, self.heading_rad, self.sigma_rad, self.length_m]
            .iter()
            .all(|v| v.is_finite())
            && self.sigma_rad > 0.0
            && self.length_m > 0.0
    }

    /// The σ the filter uses: the receiver's, times `dual_antenna.float_sigma_scale` for a
    /// float solution.
    fn sigma_used_rad(&self, config: &Config) -> f64 {
        match self.carrier {
            CarrierSolution::Fixed => self.sigma_rad,
            CarrierSolution::Float => self.sigma_rad * config.dual_antenna.float_sigma_scale,
        }
    }

    /// Screens the reading against the configuration: the reason to reject it, if any.
    pub(super) fn screen(&self, config: &Config) -> Result<(), RejectionReason> {
        let d = &config.dual_antenna;
        if !self.is_valid() {
            return Err(RejectionReason::BaselineHeadingInvalid);
        }
        if !d.enabled {
            return Err(RejectionReason::DualAntennaOff);
        }
        if self.carrier == CarrierSolution::Float && !d.accept_float {
            return Err(RejectionReason::BaselineHeadingFloat);
        }
        if self.sigma_used_rad(config) > d.max_sigma_rad {
            return Err(RejectionReason::BaselineHeadingInaccurate);
        }
        if (self.length_m - d.baseline_b_m.norm()).abs() > d.length_tolerance_m {
            return Err(RejectionReason::BaselineLengthMismatch);
        }
        Ok(())
    }

    /// The heading of the body's x axis for a start: the baseline's heading less the
    /// baseline's heading offset in the body frame (clockwise from x, the body's y axis
    /// pointing left), as for a level body.
    ///
    /// Choice: the start's roll and pitch are those of the levelling, and the tilt's
    /// effect on the offset (below the heading's σ for a car's few degrees) is left to the
    /// running filter's exact model.
    pub(super) fn start_heading(&self, config: &Config) -> AntennaHeading {
        let b = &config.dual_antenna.baseline_b_m;
        AntennaHeading {
            t_s: self.t_s,
            heading_rad: self.heading_rad - (-b[1]).atan2(b[0]),
            sigma_rad: self.sigma_used_rad(config),
        }
    }

    /// The measurement of the running filter.
    pub(super) fn model<'a>(&self, config: &'a Config) -> BaselineHeading<'a> {
        let d = &config.dual_antenna;
        BaselineHeading {
            t_s: self.t_s,
            baseline_b_m: &d.baseline_b_m,
            heading_rad: self.heading_rad,
            sigma_rad: self.sigma_used_rad(config),
            gate_sigma: d.gate_sigma,
        }
    }
}
