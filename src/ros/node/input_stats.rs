//! Input rates and the time since the last input, on the node's time, for /diagnostics.

use crate::ros::msg::{DiagnosticStatus, KeyValue};

/// The input streams of `gnss_ins_node`, in the order of [`FILTER_NODE_STREAMS`].
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
    /// `wheel/odometry` (subscribed with `wheel_odometry.enabled`).
    WheelOdometry,
    /// `ubx_nav_rel_pos_ned` (subscribed with `dual_antenna.enabled`).
    RelPosNed,
}

impl Stream {
    /// Its index in [`FILTER_NODE_STREAMS`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// A node's input streams: their keys on /diagnostics, and the streams whose silence (for
/// longer than the given node time, once one message was seen) makes the report a warning.
#[derive(Debug, Clone, Copy)]
pub struct StreamSet {
    /// Keys of the streams (`<key>_rate_hz`, `<key>_since_last_s`), by index.
    pub keys: &'static [&'static str],
    /// (index, seconds): a watched stream and how long it may be silent.
    pub watched: &'static [(usize, f64)],
}

/// Choice: no IMU message for this long (node time) while one was seen before makes the
/// report a warning; at 100 Hz or more that is a hundred missing samples, and the engine
/// itself resets after `engine.max_imu_gap_s` of IMU time.
pub const IMU_STALE_S: f64 = 1.0;

/// `gnss_ins_node`'s streams; the IMU is watched.
pub const FILTER_NODE_STREAMS: StreamSet = StreamSet {
    keys: &[
        "imu",
        "gnss",
        "fix",
        "velocity",
        "wheel_odometry",
        "rel_pos_ned",
    ],
    watched: &[(0, IMU_STALE_S)],
};

/// Arrival counts and times of every message (decodable or not) per stream.
#[derive(Debug, Clone)]
pub struct InputStats {
    streams: StreamSet,
    count: Vec<u64>,
    last_s: Vec<Option<f64>>,
    /// Node time and counts at the previous report.
    previous_report: Option<(f64, Vec<u64>)>,
}

fn key_value(key: String, value: String) -> KeyValue {
    KeyValue { key, value }
}

impl InputStats {
    /// No message seen yet on any of `streams`.
    pub fn new(streams: StreamSet) -> Self {
        Self {
            streams,
            count: vec![0; streams.keys.len()],
            last_s: vec![None; streams.keys.len()],
            previous_report: None,
        }
    }

    /// Records one message of stream `index` arriving at node time `now_s`.
    pub fn record(&mut self, index: usize, now_s: f64) {
        if let (Some(count), Some(last)) = (self.count.get_mut(index), self.last_s.get_mut(index)) {
            *count += 1;
            *last = Some(now_s);
        }
    }

    /// Adds `<key>_rate_hz` (messages per second of node time since the previous report;
    /// left out on the first report or when the node's time did not advance, e.g. a paused
    /// `/clock`) and `<key>_since_last_s` (`never` before the first message) to `status`,
    /// and turns it into a warning when a watched stream went silent.
    pub fn report(&mut self, status: &mut DiagnosticStatus, now_s: f64) {
        for (i, key) in self.streams.keys.iter().enumerate() {
            if let Some((then_s, counts)) = &self.previous_report {
                if now_s > *then_s {
                    let rate = (self.count[i] - counts[i]) as f64 / (now_s - then_s);
                    status
                        .values
                        .push(key_value(format!("{key}_rate_hz"), format!("{rate:.1}")));
                }
            }
            let since = self.last_s[i].map_or_else(
                || "never".to_owned(),
                |t| format!("{:.3}", (now_s - t).max(0.0)),
            );
            status
                .values
                .push(key_value(format!("{key}_since_last_s"), since));
        }
        self.previous_report = Some((now_s, self.count.clone()));
        for &(i, stale_s) in self.streams.watched {
            let Some(t) = self.last_s.get(i).copied().flatten() else {
                continue;
            };
            let silent_s = now_s - t;
            if silent_s > stale_s && status.level < DiagnosticStatus::WARN {
                status.level = DiagnosticStatus::WARN;
                status.message = format!("no {} input for {silent_s:.1} s", self.streams.keys[i]);
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
        let mut stats = InputStats::new(FILTER_NODE_STREAMS);
        let mut first = DiagnosticStatus::default();
        stats.report(&mut first, 100.0);
        assert_eq!(value(&first, "imu_since_last_s").as_deref(), Some("never"));
        assert_eq!(value(&first, "imu_rate_hz"), None, "no window yet");
        for k in 0..200 {
            stats.record(Stream::Imu.index(), 100.0 + f64::from(k) * 0.01);
        }
        stats.record(Stream::Gnss.index(), 101.0);
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
        assert!(stale.message.contains("no imu input"), "{}", stale.message);
        assert_eq!(value(&stale, "imu_rate_hz").as_deref(), Some("0.0"));
        let mut paused = DiagnosticStatus::default();
        stats.report(&mut paused, 104.0);
        assert_eq!(value(&paused, "imu_rate_hz"), None, "time did not advance");
    }

    #[test]
    fn a_watched_stream_warns_only_once_heard_and_then_silent() {
        const SET: StreamSet = StreamSet {
            keys: &["rawx", "sfrbx", "ubx_stream"],
            watched: &[(0, 3.0), (2, 3.0)],
        };
        let mut stats = InputStats::new(SET);
        stats.record(2, 10.0);
        stats.record(99, 10.0); // not a stream: ignored
        let mut heard = DiagnosticStatus::default();
        stats.report(&mut heard, 12.0);
        assert_eq!(
            heard.level,
            DiagnosticStatus::OK,
            "rawx never heard, stream fresh"
        );
        assert_eq!(value(&heard, "rawx_since_last_s").as_deref(), Some("never"));
        let mut silent = DiagnosticStatus::default();
        stats.report(&mut silent, 13.5);
        assert_eq!(silent.level, DiagnosticStatus::WARN);
        assert_eq!(silent.message, "no ubx_stream input for 3.5 s");
    }
}
