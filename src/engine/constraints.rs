//! The constraints of the vehicle's motion (`constraints.*`), applied to the running
//! filter as measurements at `constraints.rate_hz`: at a standstill, zero velocity (ZUPT)
//! and zero angular rate (ZARU); otherwise, for a wheeled platform, the non-holonomic
//! constraint (NHC) unless the vehicle turns hard.
//!
//! A standstill is the IMU's verdict over its last second ([`super::standstill`]: the
//! spreads within `constraints.rest_*` and the mean rate, less the estimated gyro bias and
//! the earth rate, below `constraints.rest_rate_max_deg_per_s`), unless a receiver fix of
//! the last [`GNSS_SPEED_VALID_S`] moves faster than `constraints.rest_gnss_speed_max_mps`.
//!
//! Choices:
//! - The rate: an IMU sample carries the constraints when its stamp crosses a multiple of
//!   1 / `rate_hz`, so the choice depends on the stamps alone and a re-integration after
//!   a roll-back applies the same constraints at the same samples. The IMU's verdict of
//!   each buffered sample is kept with it for the same reason.
//! - The constraints are pseudo-measurements whose σ states a model's tolerance, not a
//!   sensor's noise: the noise strategies and the process-noise scaling do not learn from
//!   them (the update's `learn` is false), and they give no epoch report.
//! - ZARU measures the mean rate of the standstill test's window, compensated with the
//!   bias estimate, once per window ([`WINDOW_S`], at the constraint samples whose stamp
//!   also crosses a multiple of it: every second for a rate_hz that is a whole number),
//!   so that no sample is used twice; its σ adds the gyro's white noise
//!   over the window to `constraints.zaru_sigma_deg_per_s`.
//! - The yaw rate of the hard-turn test is the compensated rate about the body z axis.
//! - Counted once, when first applied (not again when re-applied after a roll-back).

use std::collections::VecDeque;

use nalgebra::Vector3;

use crate::config::{Config, ConstraintsConfig};
use crate::earth;
use crate::filter::ekf::FilterError;

use super::adaptation::Adaptation;
use super::filter_state::FilterState;
use super::standstill::{StandstillDetector, WINDOW_S};
use super::update::{self, GnssFix, NonHolonomic, ZeroRate, ZeroVelocity};

/// How long a receiver fix's speed vetoes a standstill (s). Choice: 2 s, two fixes of a
/// 1 Hz receiver.
pub const GNSS_SPEED_VALID_S: f64 = 2.0;

/// The constraint updates applied so far, by kind (shown on /diagnostics).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ConstraintUpdates {
    pub zero_velocity: u64,
    pub zero_rate: u64,
    pub non_holonomic: u64,
}

#[derive(Debug, Clone, Default)]
pub(super) struct Constraints {
    /// For each buffered IMU sample (by stamp) with `constraints.zupt`: the mean raw rate
    /// of the window ending at it when its spreads are those of rest, else None.
    windows: VecDeque<(f64, Option<Vector3<f64>>)>,
    /// The last receiver fix's time and speed.
    fix_speed: Option<(f64, f64)>,
    updates: ConstraintUpdates,
}

impl Constraints {
    pub fn updates(&self) -> ConstraintUpdates {
        self.updates
    }

    /// Keeps the IMU's verdict of the window that ends at the sample at `t_s`.
    pub fn push_window(&mut self, t_s: f64, detector: &StandstillDetector, config: &Config) {
        if config.constraints.zupt {
            let window = detector.window();
            self.windows
                .push_back((t_s, window.quiet_mean_rate(&config.constraints)));
        }
    }

    /// Forgets the verdicts of samples before `t_s` (no longer buffered).
    pub fn forget_before(&mut self, t_s: f64) {
        while self.windows.front().is_some_and(|(t, _)| *t < t_s) {
            self.windows.pop_front();
        }
    }

    /// Forgets everything but the counts (a filter reset).
    pub fn clear(&mut self) {
        self.windows.clear();
        self.fix_speed = None;
    }

    /// Notes a receiver fix's speed, when it has a velocity.
    pub fn note_fix(&mut self, fix: &GnssFix) {
        if let Some(v) = fix.velocity_enu_mps {
            self.fix_speed = Some((fix.t_s, v.norm()));
        }
    }

    /// Applies the constraints due at `state`'s last sample (the one before was at
    /// `prev_t_s`); `count` says whether they are counted. On a filter failure or a
    /// non-finite result the state is left as it was and the error returned.
    pub fn apply(
        &mut self,
        state: &mut FilterState,
        prev_t_s: f64,
        config: &Config,
        adaptation: &mut Adaptation,
        count: bool,
    ) -> Result<(), FilterError> {
        let c = &config.constraints;
        let t_s = state.last_imu.t_s;
        let crosses = |period_s: f64| (prev_t_s / period_s).floor() < (t_s / period_s).floor();
        if !(c.zupt || c.platform.is_wheeled()) || !crosses(1.0 / c.rate_hz) {
            return Ok(());
        }
        let mut updated = state.clone();
        let mut updates = self.updates;
        let result = self
            .update(
                &mut updated,
                crosses(WINDOW_S),
                config,
                adaptation,
                &mut updates,
            )
            .and_then(|()| {
                updated
                    .is_finite()
                    .then_some(())
                    .ok_or(FilterError::NonFinite)
            });
        if result.is_ok() {
            *state = updated;
            if count {
                self.updates = updates;
            }
        }
        result
    }

    /// The updates due: ZUPT (and ZARU when `zaru_due`) at rest, else NHC for a wheeled
    /// platform that does not turn hard; each counted in `updates`.
    fn update(
        &self,
        state: &mut FilterState,
        zaru_due: bool,
        config: &Config,
        adaptation: &mut Adaptation,
        updates: &mut ConstraintUpdates,
    ) -> Result<(), FilterError> {
        let c = &config.constraints;
        let t_s = state.last_imu.t_s;
        let rest = if c.zupt { self.at_rest(state, c) } else { None };
        if let Some(mean_raw_rad_s) = rest {
            let mut zupt = ZeroVelocity {
                t_s,
                sigma_mps: c.zupt_sigma_mps,
            };
            update::apply(state, &mut zupt, adaptation, false)?;
            updates.zero_velocity += 1;
            if zaru_due {
                let white_rad_s = config.imu.gyro_arw_rad_per_sqrt_s / WINDOW_S.sqrt();
                let mut zaru = ZeroRate {
                    t_s,
                    mean_raw_rad_s,
                    sigma_rad_s: white_rad_s.hypot(c.zaru_sigma_rad_s),
                };
                update::apply(state, &mut zaru, adaptation, false)?;
                updates.zero_rate += 1;
            }
        } else if c.platform.is_wheeled() {
            let yaw_rate = state.compensate(&state.last_imu).w_ib_b_rad_s.z;
            if yaw_rate.abs() <= c.nhc_yaw_rate_max_rad_s {
                let mut nhc = NonHolonomic {
                    t_s,
                    lever_arm_b_m: &config.mounting.constraint_point_b_m,
                    sigma_lateral_mps: c.nhc_sigma_lateral_mps,
                    sigma_vertical_mps: c.nhc_sigma_vertical_mps,
                };
                update::apply(state, &mut nhc, adaptation, false)?;
                updates.non_holonomic += 1;
            }
        }
        Ok(())
    }

    /// The standstill test at `state`'s last sample (see the module documentation): the
    /// window's mean raw rate at rest, None when moving.
    fn at_rest(&self, state: &FilterState, c: &ConstraintsConfig) -> Option<Vector3<f64>> {
        let t_s = state.last_imu.t_s;
        let mean_w = self
            .windows
            .iter()
            .rev()
            .find(|(t, _)| *t == t_s)
            .and_then(|(_, mean_w)| *mean_w)?;
        let earth_b = state
            .nav
            .q_nb
            .inverse_transform_vector(&earth::earth_rate_enu_rad_s(state.nav.p.lat_rad));
        let rate = mean_w - state.gyro_bias_rad_s - state.gyro_markov_rad_s - earth_b;
        let moving = self.fix_speed.is_some_and(|(t_fix, speed)| {
            (t_s - t_fix).abs() <= GNSS_SPEED_VALID_S && speed > c.rest_gnss_speed_max_mps
        });
        (rate.norm() <= c.rest_rate_max_rad_s && !moving).then_some(mean_w)
    }
}
