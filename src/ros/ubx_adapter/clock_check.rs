//! The stamp of an epoch on the chosen time base, and the check of the clocks: the
//! offset between the receiver's time and the host receive stamp (mean and jitter over
//! a window of epochs) and the disagreement between the IMU stamps and the GNSS stamps.
//!
//! Math note (skew): when a GNSS epoch arrives at node time a_g, the IMU clock reads
//! t_i + (a_g − a_i), with (t_i, a_i) the stamp and node arrival time of the latest IMU
//! message. The epoch was measured `host_latency_s` = L earlier, so on the IMU clock it
//! should be stamped t_i + (a_g − a_i) − L; the skew is that minus the stamp given:
//! skew = t_i + (a_g − a_i) − L − t_g, positive when the IMU clock is ahead. With
//! `time_base: host` it is the disagreement of the IMU clock with the host clock (L
//! cancels); with `gnss` it also holds the host clock's offset from GPS time and any
//! error of L. The IMU's own transport delay (a_i − t_i, typically ~1 ms) enters as is.

use std::collections::VecDeque;

use super::params::{TimeBase, UbxAdapterParams, MAX_LEAP_SECONDS};
use crate::gnss::time_scale::{gpst_of_week_tow, utc_of_gpst};
use crate::gnss::ubx::RawX;

/// Choice: an IMU message older than this (node time) at a GNSS epoch's arrival is too
/// old to tell the IMU clock by (its rate may have drifted, or the IMU stopped).
const IMU_FRESH_S: f64 = 1.0;

/// Mean and standard deviation of a window of values.
fn mean_and_std(values: &VecDeque<f64>) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    Some((mean, var.sqrt()))
}

/// Where the leap seconds of an epoch came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeapSource {
    /// The receiver (RAWX leapS, valid and in range).
    Receiver,
    /// The `leap_seconds` parameter.
    Parameter,
}

/// The time of one epoch on both clocks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochTime {
    /// The receiver's measurement time as UTC (s since 1970): GPST − leap seconds.
    pub receiver_utc_s: f64,
    /// The stamp to publish (s since 1970), on the chosen time base.
    pub stamp_s: f64,
    /// The leap seconds used and where they came from.
    pub leap_s: i32,
    pub leap_source: LeapSource,
}

/// What the clock check found, for /diagnostics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockReport {
    /// Mean of host receive stamp − receiver UTC over the window (s), and its standard
    /// deviation (the jitter); None before the first epoch.
    pub receiver_to_host_s: Option<(f64, f64)>,
    /// Mean IMU/GNSS skew over the window (s); None without a fresh IMU message.
    pub imu_gnss_skew_s: Option<f64>,
    /// Whether |mean skew| exceeds `max_imu_gnss_skew_s`.
    pub skew_exceeded: bool,
}

/// See the module doc.
#[derive(Debug, Clone)]
pub struct ClockCheck {
    time_base: TimeBase,
    leap_seconds: i32,
    host_latency_s: f64,
    max_skew_s: f64,
    window: usize,
    offsets_s: VecDeque<f64>,
    skews_s: VecDeque<f64>,
    /// Stamp and node arrival time of the latest IMU message (s).
    last_imu: Option<(f64, f64)>,
}

fn push_bounded(window: &mut VecDeque<f64>, value: f64, len: usize) {
    if window.len() >= len {
        window.pop_front();
    }
    window.push_back(value);
}

impl ClockCheck {
    pub fn new(params: &UbxAdapterParams) -> Self {
        Self {
            time_base: params.time_base,
            leap_seconds: params.leap_seconds,
            host_latency_s: params.host_latency_s,
            max_skew_s: params.max_imu_gnss_skew_s,
            window: params.offset_window_epochs,
            offsets_s: VecDeque::new(),
            skews_s: VecDeque::new(),
            last_imu: None,
        }
    }

    /// The times of `raw`, received at host stamp `host_s` (the driver's receive stamp,
    /// or the arrival of the stream bytes).
    pub fn epoch_time(&self, raw: &RawX, host_s: f64) -> EpochTime {
        let (leap_s, leap_source) =
            if raw.leap_s_valid && (0..=MAX_LEAP_SECONDS).contains(&i32::from(raw.leap_s)) {
                (i32::from(raw.leap_s), LeapSource::Receiver)
            } else {
                (self.leap_seconds, LeapSource::Parameter)
            };
        let gpst_s = gpst_of_week_tow(i32::from(raw.week), raw.rcv_tow_s);
        let receiver_utc_s = utc_of_gpst(gpst_s, f64::from(leap_s));
        let stamp_s = match self.time_base {
            TimeBase::Gnss => receiver_utc_s,
            TimeBase::Host => host_s - self.host_latency_s,
        };
        EpochTime {
            receiver_utc_s,
            stamp_s,
            leap_s,
            leap_source,
        }
    }

    /// Records a published epoch: its times, its host stamp and its node arrival time.
    pub fn record_epoch(&mut self, time: &EpochTime, host_s: f64, arrival_s: f64) {
        let offset_s = host_s - time.receiver_utc_s;
        if offset_s.is_finite() {
            push_bounded(&mut self.offsets_s, offset_s, self.window);
        }
        if let Some((imu_stamp_s, imu_arrival_s)) = self.last_imu {
            let since_imu_s = arrival_s - imu_arrival_s;
            if since_imu_s.abs() <= IMU_FRESH_S {
                let skew_s = imu_stamp_s + since_imu_s - self.host_latency_s - time.stamp_s;
                if skew_s.is_finite() {
                    push_bounded(&mut self.skews_s, skew_s, self.window);
                }
            }
        }
    }

    /// Records an IMU message: its stamp and node arrival time (s).
    pub fn record_imu(&mut self, stamp_s: f64, arrival_s: f64) {
        if stamp_s.is_finite() && arrival_s.is_finite() {
            self.last_imu = Some((stamp_s, arrival_s));
        }
    }

    pub fn report(&self) -> ClockReport {
        let skew = mean_and_std(&self.skews_s).map(|(mean, _)| mean);
        ClockReport {
            receiver_to_host_s: mean_and_std(&self.offsets_s),
            imu_gnss_skew_s: skew,
            skew_exceeded: skew.is_some_and(|s| s.abs() > self.max_skew_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(week: u16, tow_s: f64, leap_s: i8, valid: bool) -> RawX {
        RawX::new(tow_s, week, leap_s, u8::from(valid), 1, Vec::new())
    }

    #[test]
    fn stamps_on_each_time_base_and_the_leap_seconds_used() {
        let mut params = UbxAdapterParams::default();
        let gnss = ClockCheck::new(&params);
        // GPS week 2381, TOW 408 657 s = 1 756 402 257 GPST s since 1970.
        let t = gnss.epoch_time(&raw(2381, 408_657.0, 18, true), 1_756_402_239.05);
        assert_eq!(t.receiver_utc_s, 1_756_402_239.0);
        assert_eq!(t.stamp_s, t.receiver_utc_s);
        assert_eq!(t.leap_source, LeapSource::Receiver);
        // Invalid or absurd receiver leap seconds: the parameter.
        params.leap_seconds = 17;
        let gnss = ClockCheck::new(&params);
        for r in [
            raw(2381, 408_657.0, 18, false),
            raw(2381, 408_657.0, -5, true),
        ] {
            let t = gnss.epoch_time(&r, 0.0);
            assert_eq!((t.leap_s, t.leap_source), (17, LeapSource::Parameter));
            assert_eq!(t.receiver_utc_s, 1_756_402_240.0);
        }
        params.time_base = TimeBase::Host;
        let host = ClockCheck::new(&params);
        let t = host.epoch_time(&raw(2381, 408_657.0, 18, true), 1_756_402_239.05);
        assert!((t.stamp_s - (1_756_402_239.05 - 0.035)).abs() < 1e-6);
    }

    #[test]
    fn offset_jitter_and_skew_over_the_window() {
        let params = UbxAdapterParams {
            offset_window_epochs: 4,
            ..Default::default()
        };
        let mut check = ClockCheck::new(&params);
        assert_eq!(check.report().receiver_to_host_s, None);
        // Host stamps 30, 40, 30, 40 ms after the receiver time; the IMU clock 50 ms
        // ahead of GNSS time (a host clock off by 50 ms).
        for (k, latency_s) in [0.1, 0.03, 0.04, 0.03, 0.04].iter().enumerate() {
            let t_g = 1000.0 + k as f64 * 0.25;
            let arrival_s = t_g + latency_s;
            check.record_imu(arrival_s + 0.05 - 0.002, arrival_s - 0.002);
            let time = EpochTime {
                receiver_utc_s: t_g,
                stamp_s: t_g,
                leap_s: 18,
                leap_source: LeapSource::Receiver,
            };
            check.record_epoch(&time, arrival_s, arrival_s);
        }
        let report = check.report();
        let (mean, jitter) = report.receiver_to_host_s.unwrap();
        assert!(
            (mean - 0.035).abs() < 1e-9,
            "the first epoch left the window"
        );
        assert!((jitter - 0.005).abs() < 1e-9);
        let skew = report.imu_gnss_skew_s.unwrap();
        // 50 ms of clock offset plus 35 ms mean latency minus the assumed 35 ms.
        assert!((skew - 0.05).abs() < 1e-9, "{skew}");
        assert!(report.skew_exceeded);
    }
}
