//! Screening of IMU samples before they reach the filter: a sample beyond the sensor's
//! measurement range (`imu.gyro_range_deg_per_s`, `imu.accel_range_g`) is no measurement,
//! and one that jumps further from its neighbour than the sensor's signal can change in
//! one sample (`imu.gyro_max_step_deg_per_s`, `imu.accel_max_step_g`) is a spike. Both are
//! dropped (the engine counts them); the strapdown step then spans the missing sample.
//!
//! Choices:
//! - Both tests are made in the IMU's own axes, where the data sheet's range applies.
//! - A jump is a spike only while it is alone: when [`CONFIRMING_SAMPLES`] consecutive
//!   samples jump from the last kept one but agree with each other, the signal did change
//!   (a kerb, a dropped device) and the last of them is kept; the ones before it are lost.
//! - Only a kept sample less than [`NEIGHBOUR_S`] old is a neighbour: after a gap the level
//!   may have moved, and the first sample is kept.

use nalgebra::Vector3;

use crate::config::ImuConfig;
use crate::ins::ImuSample;

/// Consecutive agreeing samples that confirm a new level.
pub const CONFIRMING_SAMPLES: usize = 3;
/// Largest age of the last kept sample for the step test (s): the step limits are changes
/// from one sample to the next, and IMUs sample at 10 Hz or faster.
pub const NEIGHBOUR_S: f64 = 0.1;

/// What the screen made of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Screened {
    Kept,
    /// An axis beyond the measurement range.
    OutOfRange,
    /// A jump from the last kept sample that the samples after it have not (yet)
    /// confirmed.
    Spike,
}

/// The screen's memory: the last kept sample and the unconfirmed jumps after it.
#[derive(Debug, Clone, Default)]
pub struct ImuScreen {
    last_kept: Option<ImuSample>,
    suspects: Vec<ImuSample>,
}

impl ImuScreen {
    /// Screens `s` (IMU axes, finite).
    pub fn screen(&mut self, s: &ImuSample, imu: &ImuConfig) -> Screened {
        let beyond = |v: &Vector3<f64>, range: f64| v.amax() > range;
        if beyond(&s.w_ib_b_rad_s, imu.gyro_range_rad_s)
            || beyond(&s.f_ib_b_m_s2, imu.accel_range_m_s2)
        {
            return Screened::OutOfRange;
        }
        let jumps = |a: &ImuSample, b: &ImuSample| {
            let over = |d: Vector3<f64>, limit: f64| limit > 0.0 && d.amax() > limit;
            over(a.w_ib_b_rad_s - b.w_ib_b_rad_s, imu.gyro_step_max_rad_s)
                || over(a.f_ib_b_m_s2 - b.f_ib_b_m_s2, imu.accel_step_max_m_s2)
        };
        let neighbour = self
            .last_kept
            .filter(|last| s.t_s - last.t_s <= NEIGHBOUR_S);
        if !neighbour.is_some_and(|last| jumps(s, &last)) {
            return self.keep(s);
        }
        let continues = self.suspects.last().is_some_and(|prev| !jumps(s, prev));
        if !continues {
            self.suspects.clear();
        }
        self.suspects.push(*s);
        if self.suspects.len() >= CONFIRMING_SAMPLES {
            return self.keep(s);
        }
        Screened::Spike
    }

    fn keep(&mut self, s: &ImuSample) -> Screened {
        self.last_kept = Some(*s);
        self.suspects.clear();
        Screened::Kept
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn sample(t_s: f64, f_x: f64, w_z: f64) -> ImuSample {
        ImuSample {
            t_s,
            w_ib_b_rad_s: Vector3::new(0.0, 0.0, w_z),
            f_ib_b_m_s2: Vector3::new(f_x, 0.0, 9.8),
        }
    }

    #[test]
    fn ranges_spikes_and_confirmed_steps() {
        let imu = Config::default().imu;
        let mut screen = ImuScreen::default();
        assert_eq!(screen.screen(&sample(0.00, 0.0, 0.0), &imu), Screened::Kept);
        assert_eq!(
            screen.screen(&sample(0.01, 1e6, 0.0), &imu),
            Screened::OutOfRange
        );
        assert_eq!(
            screen.screen(&sample(0.02, 0.0, 1e10), &imu),
            Screened::OutOfRange
        );
        // One sample 90 m/s² off (within the 10 g range, beyond the 5 g step): a spike.
        assert_eq!(
            screen.screen(&sample(0.03, 90.0, 0.0), &imu),
            Screened::Spike
        );
        assert_eq!(screen.screen(&sample(0.04, 0.1, 0.0), &imu), Screened::Kept);
        // A real step of 60 m/s² on the x axis: two dropped, the third confirms it.
        for (k, expected) in [Screened::Spike, Screened::Spike, Screened::Kept]
            .into_iter()
            .enumerate()
        {
            let t = 0.05 + 0.01 * k as f64;
            assert_eq!(screen.screen(&sample(t, 60.0, 0.0), &imu), expected);
        }
        assert_eq!(
            screen.screen(&sample(0.08, 60.5, 0.0), &imu),
            Screened::Kept
        );
        // After a gap the level may have moved.
        assert_eq!(screen.screen(&sample(1.0, 0.0, 0.0), &imu), Screened::Kept);
        // 0 switches the step test off.
        let mut off = imu.clone();
        off.accel_step_max_m_s2 = 0.0;
        assert_eq!(
            screen.screen(&sample(1.01, 90.0, 0.0), &off),
            Screened::Kept
        );
    }
}
