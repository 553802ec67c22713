//! The parameters of the [`super::UbxAdapter`]: a plain struct with documented defaults
//! and ranges, checked by [`UbxAdapterParams::validate`].

use crate::gnss::ionosphere::IonosphereMode;

/// Which clock the published GnssMeasurements are stamped on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeBase {
    /// The receiver's measurement time: GPST − leap seconds (UTC), for IMU stamps on a
    /// PTP/NTP-synced host clock.
    Gnss,
    /// The host receive stamp minus `host_latency_s`: IMU and GNSS on the host clock,
    /// synced or not.
    Host,
}

/// Parameters; see each field for its unit, default and range.
#[derive(Debug, Clone, PartialEq)]
pub struct UbxAdapterParams {
    /// `time_base` (`gnss` | `host`), default `gnss`: the clock of the published stamps.
    pub time_base: TimeBase,
    /// `leap_seconds` (s), default 18 (GPS − UTC since 2017), integer in [0, 60]: used
    /// while the receiver does not report valid leap seconds (RAWX recStat bit 0).
    pub leap_seconds: i32,
    /// `host_latency_s` (s), default 0.035, in [0, 1]: the time from the receiver's
    /// measurement epoch to the host receive stamp (the driver's `header.stamp`, or the
    /// arrival of the stream bytes). `host` stamps are the receive stamp minus this; in
    /// both time bases it is the offset the clock check expects. Choice: 35 ms is what a
    /// u-blox F9 at 4 Hz measured on walk_0827 (median 36 ms, σ 6 ms between the RAWX
    /// time and the logging host's receive time); the /diagnostics offset tells the value
    /// for another set-up.
    pub host_latency_s: f64,
    /// `max_imu_gnss_skew_s` (s), default 0.01, in (0, 10]: the clock check warns when
    /// the IMU stamps and the GNSS stamps disagree by more than this on average (beyond
    /// `host_latency_s`); 10 ms at 20 m/s is 0.2 m.
    pub max_imu_gnss_skew_s: f64,
    /// `ionosphere` (`iono_free` | `broadcast` | `none`), default `iono_free`: one
    /// ionosphere-free pair per satellite, or one signal with (or without) the broadcast
    /// Klobuchar model, as `gnss_ins convert --ionosphere`.
    pub ionosphere: IonosphereMode,
    /// `frame_id`, default `gnss_antenna`: the `header.frame_id` of the output (the
    /// antenna frame the node's lever arm refers to). Not empty.
    pub frame_id: String,
    /// `offset_window_epochs`, default 100, integer in [2, 10 000]: the epochs over
    /// which the receiver-to-host offset, its jitter and the IMU/GNSS skew are averaged.
    pub offset_window_epochs: usize,
}

/// Default of `host_latency_s` (s).
pub const DEFAULT_HOST_LATENCY_S: f64 = 0.035;

impl Default for UbxAdapterParams {
    fn default() -> Self {
        Self {
            time_base: TimeBase::Gnss,
            leap_seconds: 18,
            host_latency_s: DEFAULT_HOST_LATENCY_S,
            max_imu_gnss_skew_s: 0.01,
            ionosphere: IonosphereMode::IonoFree,
            frame_id: "gnss_antenna".to_owned(),
            offset_window_epochs: 100,
        }
    }
}

/// Largest GPS − UTC accepted (s), from the receiver or as a parameter.
/// Choice: 18 s today, +1 s every few years at most; 60 s leaves decades of margin and
/// refuses absurd values.
pub const MAX_LEAP_SECONDS: i32 = 60;

/// A parameter outside its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{name} = {value}: must be {range}")]
pub struct UbxAdapterParamError {
    pub name: &'static str,
    pub value: String,
    pub range: &'static str,
}

impl UbxAdapterParams {
    /// Checks every parameter against its range.
    pub fn validate(&self) -> Result<(), UbxAdapterParamError> {
        let error = |name, value: String, range| Err(UbxAdapterParamError { name, value, range });
        if !(0..=MAX_LEAP_SECONDS).contains(&self.leap_seconds) {
            return error(
                "leap_seconds",
                self.leap_seconds.to_string(),
                "an integer in [0, 60]",
            );
        }
        if !(0.0..=1.0).contains(&self.host_latency_s) {
            return error(
                "host_latency_s",
                self.host_latency_s.to_string(),
                "in [0, 1] s",
            );
        }
        if !(self.max_imu_gnss_skew_s > 0.0 && self.max_imu_gnss_skew_s <= 10.0) {
            return error(
                "max_imu_gnss_skew_s",
                self.max_imu_gnss_skew_s.to_string(),
                "in (0, 10] s",
            );
        }
        if self.frame_id.is_empty() {
            return error("frame_id", String::new(), "a non-empty frame name");
        }
        if !(2..=10_000).contains(&self.offset_window_epochs) {
            return error(
                "offset_window_epochs",
                self.offset_window_epochs.to_string(),
                "an integer in [2, 10000]",
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_each_range_is_enforced() {
        assert_eq!(UbxAdapterParams::default().validate(), Ok(()));
        let bad = [
            UbxAdapterParams {
                leap_seconds: -1,
                ..Default::default()
            },
            UbxAdapterParams {
                host_latency_s: f64::NAN,
                ..Default::default()
            },
            UbxAdapterParams {
                max_imu_gnss_skew_s: 0.0,
                ..Default::default()
            },
            UbxAdapterParams {
                frame_id: String::new(),
                ..Default::default()
            },
            UbxAdapterParams {
                offset_window_epochs: 1,
                ..Default::default()
            },
        ];
        let names: Vec<_> = bad.iter().map(|p| p.validate().unwrap_err().name).collect();
        assert_eq!(
            names,
            [
                "leap_seconds",
                "host_latency_s",
                "max_imu_gnss_skew_s",
                "frame_id",
                "offset_window_epochs"
            ]
        );
    }
}
