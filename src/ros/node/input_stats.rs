//! Input rates and the time since the last input, on the node's time, for /diagnostics.

use crate::ros::msg::{DiagnosticStatus, KeyValue};

/// The node's input streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// `imu`.
    Imu,
    /// `gnss/measurements`.
    Gnss,
    /// `gnss/fix`.
    Fix,
    /// `gnss/velocity`.
    Velocity,
}

const STREAMS: [Stream; 4] = [Stream::Imu, Stream::Gnss, Stream::Fix, Stream::Velocity];

impl Stream {
    fn index(self) -> usize {
        self as usize
    }

    fn key(self) -> &'static str {
        match self {
            Stream::Imu => "imu",
            Stream::Gnss => "gnss",
            Stream::Fix => "fix",
            Stream::Velocity => "velocity",
        }
    }
}

/// Choice: no IMU message for this long (node time) while one was seen before makes the
/// report a warning; at 100 Hz or more that is a hundred missing samples, and the engine
/// itself resets after `engine.max_imu_gap_s` of IMU time.
pub const IMU_STALE_S: f64 = 1.0;

/// Arrival counts and times of every message (decodable or not) per stream.
#[derive(Debug, Clone, Default)]
pub struct InputStats {
    count: [u64; 4],
    last_s: [Option<f64>; 4],
    /// Node time and counts at the previous report.
    previous_report: Option<(f64, [u64; 4])>,
}

fn key_value(key: String, value: String) -> KeyValue {
    KeyValue { key, value }
}

impl InputStats {
    /// Records one message of `stream` arriving at node time `now_s`.
    pub fn record(&mut self, stream: Stream, now_s: f64) {
        self.count[stream.index()] += 1;
        self.last_s[stream.index()] = Some(now_s);
    }

    /// Adds `<stream>_rate_hz` (messages per second of node time since the previous report;
    /// left out on the first report or when the node's time did not advance, e.g. a paused
    /// `/clock`) and `<stream>_since_last_s` (`never` before the first message) to
    /// `status`, and turns it into a warning when the IMU is stale.
    pub fn report(&mut self, status: &mut DiagnosticStatus, now_s: f64) {
        for stream in STREAMS {
            let i = stream.index();
            if let Some((then_s, counts)) = self.previous_report {
                if now_s > then_s {
                    let rate = (self.count[i] - counts[i]) as f64 / (now_s - then_s);
                    status.values.push(key_value(
                        format!("{}_rate_hz", stream.key()),
                        format!("{rate:.1}"),
                    ));
                }
            }
            let since = self.last_s[i].map_or_else(
                || "never".to_owned(),
                |t| format!("{:.3}", (now_s - t).max(0.0)),
            );
            status
                .values
                .push(key_value(format!("{}_since_last_s", stream.key()), since));
        }
        self.previous_report = Some((now_s, self.count));
        if let Some(t) = self.last_s[Stream::Imu.index()] {
            let silent_s = now_s - t;
            if silent_s > IMU_STALE_S && status.level < DiagnosticStatus::WARN {
                status.level = DiagnosticStatus::WARN;
                status.message = format!("no IMU input for {silent_s:.1} s");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(s: &DiagnosticStatus, key: &str) -> Option<String> {
        s.values
            .iter()
            .find(|kv| kv.key == key)
            .map(|kv| kv.value.clone())
    }

    #[test]
    fn rates_ages_and_stale_imu() {
        let mut stats = InputStats::default();
        let mut first = DiagnosticStatus::default();
        stats.report(&mut first, 100.0);
        assert_eq!(value(&first, "imu_since_last_s").as_deref(), Some("never"));
        assert_eq!(value(&first, "imu_rate_hz"), None, "no window yet");
        for k in 0..200 {
            stats.record(Stream::Imu, 100.0 + f64::from(k) * 0.01);
        }
        stats.record(Stream::Gnss, 101.0);
        let mut second = DiagnosticStatus::default();
        stats.report(&mut second, 102.0);
        assert_eq!(value(&second, "imu_rate_hz").as_deref(), Some("100.0"));
        assert_eq!(value(&second, "gnss_rate_hz").as_deref(), Some("0.5"));
        assert_eq!(value(&second, "fix_rate_hz").as_deref(), Some("0.0"));
        assert_eq!(value(&second, "imu_since_last_s").as_deref(), Some("0.010"));
        assert_eq!(
            value(&second, "gnss_since_last_s").as_deref(),
            Some("1.000")
        );
        assert_eq!(second.level, DiagnosticStatus::OK);
        let mut stale = DiagnosticStatus::default();
        stats.report(&mut stale, 104.0);
        assert_eq!(stale.level, DiagnosticStatus::WARN);
        assert!(stale.message.contains("no IMU input"), "{}", stale.message);
        assert_eq!(value(&stale, "imu_rate_hz").as_deref(), Some("0.0"));
        let mut paused = DiagnosticStatus::default();
        stats.report(&mut paused, 104.0);
        assert_eq!(value(&paused, "imu_rate_hz"), None, "time did not advance");
    }
}
