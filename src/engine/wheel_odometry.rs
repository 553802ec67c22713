//! The base controller's wheel speeds (`wheel_odometry.*`): a reading as it waits for its
//! time, and the measurement model it becomes ([`update::WheelSpeed`]).

use crate::config::Config;

use super::update::WheelSpeed;

/// One forward speed of the wheels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct WheelSpeedReading {
    /// Time of validity (s).
    pub t_s: f64,
    /// Forward speed as reported (m/s; negative when reversing).
    pub speed_mps: f64,
    /// Its 1-sigma as reported (m/s); None: `wheel_odometry.sigma_mps`.
    pub sigma_mps: Option<f64>,
}

impl WheelSpeedReading {
    /// Whether the time and speed are finite and a given σ finite and positive.
    pub fn is_valid(&self) -> bool {
        self.t_s.is_finite()
            && self.speed_mps.is_finite()
            && self.sigma_mps.is_none_or(|s| s.is_finite() && s > 0.0)
    }

    /// The measurement of the point `mounting.constraint_point_lever_arm_m`, as reported:
    /// the filter state's wheel scale factor (`wheel_odometry.scale_factor`, fixed or
    /// estimated) turns it into the true speed.
    pub fn model<'a>(&self, config: &'a Config) -> WheelSpeed<'a> {
        let w = &config.wheel_odometry;
        WheelSpeed {
            t_s: self.t_s,
            lever_arm_b_m: &config.mounting.constraint_point_b_m,
            speed_mps: self.speed_mps,
            sigma_mps: self.sigma_mps.unwrap_or(w.sigma_mps),
        }
    }
}
