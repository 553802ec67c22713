//! Standstill detection from the IMU: over a window of body-frame samples, the spread of
//! the specific force and of the angular rate (the sensor's noise and a parked vehicle's
//! vibration at rest, the road's and the engine's when moving) and the mean rate (a steady
//! turn has a steady rate). The initializer confirms a verdict of rest with the GNSS speed
//! when it has one: a vehicle cruising straight at constant speed is, to an IMU without
//! vibration, at rest. The levelling at start-up (`initializer`) takes its
//! attitude and gyro bias only from a window at rest.
//!
//! Choice (thresholds): from the IMU's own noise model, so that each IMU class gets its
//! own without a parameter of its own: the spreads may reach three times the white noise
//! of one sample (`imu.accel_vrw_ug_per_sqrt_hz`, `imu.gyro_arw_deg_per_sqrt_h` at the
//! window's sample rate) together with a parked vehicle's idle ([`IDLE_ACCEL_M_S2`],
//! [`IDLE_GYRO_RAD_S`]); the mean rate three times the turn-on gyro bias
//! (`imu.gyro_bias_deg_per_h`), at least [`REST_RATE_FLOOR_RAD_S`].
//!
//! Once the filter runs, the zero-velocity update (`constraints.zupt`) asks the same
//! window with thresholds of its own (`constraints.rest_*`, set per IMU class by the
//! presets): then the gyro bias is estimated, and the mean rate is tested with it removed.

use std::collections::VecDeque;

use nalgebra::Vector3;

use crate::config::{ConstraintsConfig, ImuConfig};
use crate::ins::ImuSample;

/// Length of the detector's window (s). Choice: 1 s, many periods of a vehicle's
/// vibration and short against a start-up.
pub const WINDOW_S: f64 = 1.0;
/// Most samples the window holds, whatever their stamps (a flood of samples stamped 1 µs
/// apart would otherwise fill it). Choice: the engine's IMU buffer's bound, a 1 s window
/// of a 10 kHz IMU.
pub const MAX_WINDOW_SAMPLES: usize = super::MAX_BUFFERED_IMU_SAMPLES;
/// Specific-force spread of a parked vehicle's idle (m/s²). Choice: 10 mg.
pub const IDLE_ACCEL_M_S2: f64 = 0.098;
/// Angular-rate spread of a parked vehicle's idle (rad/s). Choice: 0.2 °/s.
pub const IDLE_GYRO_RAD_S: f64 = 0.2 * std::f64::consts::PI / 180.0;
/// Smallest mean-rate threshold at rest (rad/s). Choice: 0.1 °/s, a thirtieth of the
/// steady turn of issue 11 (3.4 °/s) and seven times the earth rate.
pub const REST_RATE_FLOOR_RAD_S: f64 = 0.1 * std::f64::consts::PI / 180.0;

/// Sums over a set of body-frame samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionStatistics {
    count: usize,
    first_t_s: f64,
    last_t_s: f64,
    sum_f: Vector3<f64>,
    sum_ff: Vector3<f64>,
    sum_w: Vector3<f64>,
    sum_ww: Vector3<f64>,
}

impl Default for MotionStatistics {
    fn default() -> Self {
        Self {
            count: 0,
            first_t_s: f64::NAN,
            last_t_s: f64::NAN,
            sum_f: Vector3::zeros(),
            sum_ff: Vector3::zeros(),
            sum_w: Vector3::zeros(),
            sum_ww: Vector3::zeros(),
        }
    }
}

impl MotionStatistics {
    pub fn push(&mut self, s: &ImuSample) {
        if self.count == 0 {
            self.first_t_s = s.t_s;
        }
        self.last_t_s = s.t_s;
        self.count += 1;
        self.sum_f += s.f_ib_b_m_s2;
        self.sum_ff += s.f_ib_b_m_s2.component_mul(&s.f_ib_b_m_s2);
        self.sum_w += s.w_ib_b_rad_s;
        self.sum_ww += s.w_ib_b_rad_s.component_mul(&s.w_ib_b_rad_s);
    }

    pub fn count(&self) -> usize {
        self.count
    }

    /// The time the samples span, one sample period included (s); 0 for fewer than two.
    pub fn duration_s(&self) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        let span = self.last_t_s - self.first_t_s;
        span + span / (self.count - 1) as f64
    }

    pub fn mean_f(&self) -> Vector3<f64> {
        self.sum_f / self.count.max(1) as f64
    }

    pub fn mean_w(&self) -> Vector3<f64> {
        self.sum_w / self.count.max(1) as f64
    }

    /// Root mean square over the axes of each axis's standard deviation.
    ///
    /// Math note: the one-pass form Σx² − n x̄² loses about 1e-16 Σx² to rounding, 1e-12
    /// (m/s²)² for a thousand samples of gravity: a standard deviation of 1e-6 m/s², far
    /// below any sensor's noise.
    fn spread(sum: &Vector3<f64>, sum_sq: &Vector3<f64>, n: usize) -> f64 {
        let n = n as f64;
        let var: f64 = (0..3)
            .map(|i| ((sum_sq[i] - sum[i] * sum[i] / n) / (n - 1.0)).max(0.0))
            .sum();
        (var / 3.0).sqrt()
    }

    /// The samples' rate (Hz); None for fewer than two samples or no time between them.
    fn rate_hz(&self) -> Option<f64> {
        (self.count >= 2 && self.last_t_s > self.first_t_s)
            .then(|| (self.count - 1) as f64 / (self.last_t_s - self.first_t_s))
    }

    /// True when the spreads of the specific force and of the angular rate stay within
    /// `accel_spread_max_m_s2` and `gyro_spread_max_rad_s`.
    fn quiet(&self, accel_spread_max_m_s2: f64, gyro_spread_max_rad_s: f64) -> bool {
        Self::spread(&self.sum_f, &self.sum_ff, self.count) <= accel_spread_max_m_s2
            && Self::spread(&self.sum_w, &self.sum_ww, self.count) <= gyro_spread_max_rad_s
    }

    /// The IMU's verdict: at rest when the samples' spreads and the mean rate stay within
    /// the thresholds that `imu` gives (see the module documentation). False for fewer
    /// than two samples.
    pub fn at_rest(&self, imu: &ImuConfig) -> bool {
        let Some(rate_hz) = self.rate_hz() else {
            return false;
        };
        let accel_noise = imu.accel_vrw_m_s_per_sqrt_s * rate_hz.sqrt();
        let gyro_noise = imu.gyro_arw_rad_per_sqrt_s * rate_hz.sqrt();
        let rate_max = (3.0 * imu.gyro_bias_sigma_rad_s).max(REST_RATE_FLOOR_RAD_S);
        self.quiet(
            (3.0 * accel_noise).hypot(IDLE_ACCEL_M_S2),
            (3.0 * gyro_noise).hypot(IDLE_GYRO_RAD_S),
        ) && self.mean_w().norm() <= rate_max
    }

    /// The running filter's test of rest, with the thresholds of `constraints.*`: the
    /// mean raw rate when the spreads stay within `rest_accel_spread_max_mg` and
    /// `rest_gyro_spread_max_deg_per_s` (the caller compares it, bias removed, with
    /// `rest_rate_max_deg_per_s`); None when they do not, or for fewer than two samples.
    pub fn quiet_mean_rate(&self, c: &ConstraintsConfig) -> Option<Vector3<f64>> {
        self.rate_hz()?;
        self.quiet(c.rest_accel_spread_max_m_s2, c.rest_gyro_spread_max_rad_s)
            .then(|| self.mean_w())
    }
}

/// The IMU samples of the last [`WINDOW_S`], and of the `history_s` before it: a late
/// measurement's start-up asks the window that ended at its time
/// ([`StandstillDetector::window_ending_at`]), as it would have in time.
#[derive(Debug, Clone, Default)]
pub struct StandstillDetector {
    samples: VecDeque<ImuSample>,
    history_s: f64,
}

impl StandstillDetector {
    /// A detector that keeps `history_s` (the engine's `engine.imu_buffer_s`) of samples
    /// before its window.
    pub fn new(history_s: f64) -> Self {
        Self {
            samples: VecDeque::new(),
            history_s,
        }
    }

    /// Adds a body-frame sample; one older than the newest (the time went back, as when a
    /// bag plays in a loop) starts the window again: the old time line's samples would
    /// stay in front, never older than the new ones by the window's length, and the
    /// window would grow by every sample.
    pub fn push(&mut self, s: &ImuSample) {
        if self.samples.back().is_some_and(|newest| s.t_s < newest.t_s) {
            self.samples.clear();
        }
        self.samples.push_back(*s);
        while self
            .samples
            .front()
            .is_some_and(|old| old.t_s < s.t_s - WINDOW_S - self.history_s)
            || self.samples.len() > MAX_WINDOW_SAMPLES
        {
            self.samples.pop_front();
        }
    }

    /// The samples kept (the window and the history before it).
    pub fn sample_count(&self) -> usize {
        self.samples.len()
    }

    /// Forgets the window (a filter reset).
    pub fn clear(&mut self) {
        self.samples.clear();
    }

    /// The statistics of the window that ends at the newest sample (see
    /// [`StandstillDetector::window_ending_at`]).
    pub fn window(&self) -> MotionStatistics {
        self.samples
            .back()
            .map_or_else(MotionStatistics::default, |s| self.window_ending_at(s.t_s))
    }

    /// The statistics of the samples of the [`WINDOW_S`] that ends at `end_t_s` (at most
    /// [`MAX_WINDOW_SAMPLES`], the newest); its count is 0 unless they span most of
    /// [`WINDOW_S`] (a verdict on less would be one on a few samples).
    pub fn window_ending_at(&self, end_t_s: f64) -> MotionStatistics {
        let end = self.samples.partition_point(|s| s.t_s <= end_t_s);
        let start = self
            .samples
            .partition_point(|s| s.t_s < end_t_s - WINDOW_S)
            .max(end.saturating_sub(MAX_WINDOW_SAMPLES));
        let mut stats = MotionStatistics::default();
        for s in self.samples.range(start..end.max(start)) {
            stats.push(s);
        }
        // Choice: 90 % of the window, so that sample jitter does not delay every verdict.
        if stats.duration_s() < 0.9 * WINDOW_S {
            return MotionStatistics::default();
        }
        stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use rand::RngExt;
    use rand_chacha::rand_core::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn samples(
        rate_hz: f64,
        duration_s: f64,
        f: Vector3<f64>,
        w: Vector3<f64>,
        noise: f64,
    ) -> Vec<ImuSample> {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = (rate_hz * duration_s) as usize;
        (0..n)
            .map(|k| ImuSample {
                t_s: k as f64 / rate_hz,
                f_ib_b_m_s2: f + Vector3::from_fn(|_, _| noise * (rng.random::<f64>() - 0.5)),
                w_ib_b_rad_s: w,
            })
            .collect()
    }

    #[test]
    fn rest_vibration_and_a_steady_turn() {
        let imu = Config::default().imu;
        let g = Vector3::new(0.0, 0.0, 9.8);
        let verdict = |s: &[ImuSample]| {
            let mut d = StandstillDetector::default();
            for x in s {
                d.push(x);
            }
            d.window().at_rest(&imu)
        };
        // A quiet sensor at rest; the earth rate is far below the rate threshold.
        let earth = Vector3::new(0.0, 5e-5, 5e-5);
        assert!(verdict(&samples(100.0, 2.0, g, earth, 0.005)));
        // Vibration of 0.3 m/s² (a road): moving.
        assert!(!verdict(&samples(100.0, 2.0, g, earth, 1.0)));
        // A steady turn of 3.4 °/s with a steady specific force: moving.
        let turn = Vector3::new(0.0, 0.0, 3.4f64.to_radians());
        assert!(!verdict(&samples(100.0, 2.0, g, turn, 0.005)));
        // A consumer MEMS gyro's turn-on bias of 0.14 °/s (500 °/h) is no turn.
        let mut consumer = imu.clone();
        consumer.gyro_bias_sigma_rad_s = 0.14f64.to_radians();
        let bias = Vector3::new(0.0, 0.0, 0.14f64.to_radians());
        assert!(!verdict(&samples(100.0, 2.0, g, bias, 0.005)));
        let mut d = StandstillDetector::default();
        for x in samples(100.0, 2.0, g, bias, 0.005) {
            d.push(&x);
        }
        assert!(d.window().at_rest(&consumer));
        // Less than the window: no verdict.
        assert!(!verdict(&samples(100.0, 0.5, g, earth, 0.005)));
    }
}
