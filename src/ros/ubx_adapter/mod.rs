//! [`UbxAdapter`]: raw GNSS from the u-blox ROS 2 drivers -> `GnssMeasurements`, without
//! any DDS (decoded messages in, messages to publish out, counters for /diagnostics), as
//! the node's message handler is. It serves `gnss_ins convert --bag` and the live node.
//!
//! Inputs, any mix: `ublox_ubx_msgs/UBXRxmRawx` and `UBXRxmSfrbx` (ublox_dgnss, one
//! message per UBX frame, stamped with the host receive time), and
//! `std_msgs/UInt8MultiArray` chunks of the receiver's byte stream (ublox_gps
//! `raw_data_stream`, frames cut anywhere, no stamp: the arrival time stands for it).
//! Subframes feed a [`BroadcastNav`]; each receiver epoch (RAWX) is built with what it
//! knew then, by the same code as `gnss_ins convert --ubx --ephemeris as-received`, and
//! published when it has a usable satellite. Satellites without a usable ephemeris are
//! left out and counted.
//!
//! Every input is checked and what is unusable is counted, never guessed: undecodable
//! and malformed messages, stream garbage (bad checksums, truncated and oversized
//! frames), subframes with a wrong word count, parity or issue of data, epochs with an
//! invalid, repeated, earlier or far later receiver time (see `sequence.rs`), satellites
//! with duplicated signals. The time base and the clock check are in `clock_check.rs`.

mod clock_check;
mod counts;
mod inbound;
mod params;
mod sequence;

pub use clock_check::{ClockReport, LeapSource};
pub use counts::UbxAdapterCounts;
pub use params::{
    TimeBase, UbxAdapterParamError, UbxAdapterParams, DEFAULT_HOST_LATENCY_S, MAX_LEAP_SECONDS,
};

use crate::gnss::ephemeris::{GpsTime, SECONDS_PER_WEEK};
use crate::gnss::ubx::{decode_message, BroadcastNav, RawX, UbxFramer, UbxMessage};
use crate::ros::convert::{seconds_to_time, time_to_seconds};
use crate::ros::log_limit::LogLimiter;
use crate::ros::msg::{
    DiagnosticStatus, GnssMeasurements, Imu, KeyValue, UInt8MultiArray, UbxRxmRawx, UbxRxmSfrbx,
};
use crate::ros::outbound;

use clock_check::ClockCheck;
use inbound::{rawx_of, sfrbx_of};
use sequence::{EpochSequence, Verdict};

/// See the module doc.
pub struct UbxAdapter {
    params: UbxAdapterParams,
    nav: BroadcastNav,
    framer: UbxFramer,
    sequence: EpochSequence,
    clock: ClockCheck,
    counts: UbxAdapterCounts,
    /// Leap seconds of the latest epoch and where they came from.
    last_leap: Option<(i32, LeapSource)>,
    /// Whether the skew warning is on (logged when it changes).
    skew_warning: bool,
    log: LogLimiter,
}

impl UbxAdapter {
    /// An adapter with `params` (checked).
    pub fn new(params: UbxAdapterParams) -> Result<Self, UbxAdapterParamError> {
        params.validate()?;
        Ok(Self {
            clock: ClockCheck::new(&params),
            params,
            nav: BroadcastNav::new(),
            framer: UbxFramer::new(),
            sequence: EpochSequence::default(),
            counts: UbxAdapterCounts::default(),
            last_leap: None,
            skew_warning: false,
            log: LogLimiter::default(),
        })
    }

    /// The counters.
    pub fn counts(&self) -> &UbxAdapterCounts {
        &self.counts
    }

    /// The clock check's findings.
    pub fn clock_report(&self) -> ClockReport {
        self.clock.report()
    }

    /// The leap seconds of the latest epoch, and where they came from.
    pub fn leap_seconds(&self) -> Option<(i32, LeapSource)> {
        self.last_leap
    }

    /// Records a payload on `topic` that did not decode.
    pub fn on_undecodable(&mut self, topic: &str, error: &str) {
        self.counts.undecodable += 1;
        self.log.warn(
            "undecodable",
            &format!("undecodable message on {topic}: {error}"),
        );
    }

    /// Handles one UBXRxmRawx that arrived at node time `arrival_s` (s): the
    /// GnssMeasurements of its epoch, if it is published.
    pub fn on_rawx(&mut self, msg: &UbxRxmRawx, arrival_s: f64) -> Option<GnssMeasurements> {
        self.counts.rawx += 1;
        let raw = match rawx_of(msg) {
            Ok(raw) => raw,
            Err(e) => return self.malformed(&e.to_string()),
        };
        let host_s = time_to_seconds(&msg.header.stamp).unwrap_or(f64::NAN);
        self.epoch(&raw, host_s, arrival_s)
    }

    /// Handles one UBXRxmSfrbx.
    pub fn on_sfrbx(&mut self, msg: &UbxRxmSfrbx) {
        self.counts.sfrbx += 1;
        match sfrbx_of(msg) {
            Ok(sfrbx) => {
                self.nav.on_sfrbx(sfrbx);
                self.counts.nav = self.nav.stats();
            }
            Err(e) => {
                self.malformed(&e.to_string());
            }
        }
    }

    /// Handles one chunk of the receiver's byte stream that arrived at node time
    /// `arrival_s` (s): the GnssMeasurements of the epochs it completed. Choice: the
    /// first `layout.data_offset` bytes are padding (std_msgs' meaning) and skipped.
    pub fn on_stream_chunk(
        &mut self,
        msg: &UInt8MultiArray,
        arrival_s: f64,
    ) -> Vec<GnssMeasurements> {
        self.counts.stream_chunks += 1;
        self.counts.stream_bytes += msg.data.len() as u64;
        let offset = usize::try_from(msg.layout.data_offset).unwrap_or(usize::MAX);
        self.framer.push(msg.data.get(offset..).unwrap_or_default());
        self.stream_frames(arrival_s)
    }

    /// Ends the byte stream (end of a bag): the frames still complete in it.
    pub fn finish_stream(&mut self, arrival_s: f64) -> Vec<GnssMeasurements> {
        self.framer.finish();
        self.stream_frames(arrival_s)
    }

    /// Records an IMU message that arrived at node time `arrival_s` (s), for the clock
    /// check.
    pub fn on_imu(&mut self, msg: &Imu, arrival_s: f64) {
        if let Ok(stamp_s) = time_to_seconds(&msg.header.stamp) {
            self.clock.record_imu(stamp_s, arrival_s);
        }
    }

    /// The frames the stream has completed, decoded and used.
    fn stream_frames(&mut self, arrival_s: f64) -> Vec<GnssMeasurements> {
        let mut out = Vec::new();
        while let Some(frame) = self.framer.next_frame() {
            match decode_message(&frame) {
                Ok(UbxMessage::RawX(raw)) => {
                    self.counts.rawx += 1;
                    out.extend(self.epoch(&raw, arrival_s, arrival_s));
                }
                Ok(UbxMessage::Sfrbx(sfrbx)) => {
                    self.counts.sfrbx += 1;
                    self.nav.on_sfrbx(sfrbx);
                }
                Ok(UbxMessage::NavPvt(_) | UbxMessage::Unknown { .. }) => {
                    self.counts.other_frames += 1;
                }
                Err(e) => {
                    self.malformed(&e.to_string());
                }
            }
        }
        self.counts.frames = self.framer.stats();
        self.counts.nav = self.nav.stats();
        out
    }

    /// The epoch of `raw`, received at host stamp `host_s` and node time `arrival_s`.
    fn epoch(&mut self, raw: &RawX, host_s: f64, arrival_s: f64) -> Option<GnssMeasurements> {
        if !(raw.rcv_tow_s.is_finite() && (0.0..SECONDS_PER_WEEK).contains(&raw.rcv_tow_s)) {
            self.counts.invalid_time += 1;
            self.log.warn(
                "invalid_time",
                &format!(
                    "RAWX time of week {} s is not within a week: dropped",
                    raw.rcv_tow_s
                ),
            );
            return None;
        }
        let t = GpsTime::new(i32::from(raw.week), raw.rcv_tow_s);
        match self.sequence.judge(t) {
            Verdict::Next => {}
            Verdict::NewTimeline => {
                self.counts.timeline_restarts += 1;
                log::warn!(
                    "receiver time jumped to week {} TOW {:.3} s and went on: following it",
                    t.week,
                    t.tow_s
                );
            }
            Verdict::Ahead => {
                self.counts.time_jumps_ahead += 1;
                self.log.warn(
                    "time_jump_ahead",
                    &format!(
                        "RAWX at week {} TOW {:.3} s is far after the last epoch used: dropped \
                         until the next ones confirm it",
                        t.week, t.tow_s
                    ),
                );
                return None;
            }
            Verdict::Duplicate => {
                self.counts.duplicate_epochs += 1;
                self.log
                    .warn("duplicate_epoch", "RAWX of an epoch already used: dropped");
                return None;
            }
            Verdict::Backwards => {
                self.counts.time_backwards += 1;
                self.log.warn(
                    "time_backwards",
                    &format!(
                        "RAWX at week {} TOW {:.3} s is before the last epoch used: dropped",
                        t.week, t.tow_s
                    ),
                );
                return None;
            }
        }
        let built = self.nav.on_rawx(raw, self.params.ionosphere);
        self.counts.add_epoch(&built.stats);
        self.counts.nav = self.nav.stats();
        let time = self.clock.epoch_time(raw, host_s);
        if time.leap_source == LeapSource::Parameter {
            self.counts.leap_seconds_from_parameter += 1;
        }
        self.last_leap = Some((time.leap_s, time.leap_source));
        self.clock.record_epoch(&time, host_s, arrival_s);
        self.watch_skew();
        if built.epoch.satellites.is_empty() {
            self.counts.empty_epochs += 1;
            return None;
        }
        let Ok(stamp) = seconds_to_time(time.stamp_s) else {
            self.counts.unstampable += 1;
            self.log.warn(
                "unstampable",
                &format!("epoch stamp {} s is no ROS time: dropped", time.stamp_s),
            );
            return None;
        };
        self.counts.published += 1;
        Some(outbound::gnss_measurements(
            &built.epoch,
            raw.week,
            stamp,
            &self.params.frame_id,
        ))
    }

    /// Logs when the IMU/GNSS skew goes beyond its limit or back.
    fn watch_skew(&mut self) {
        let report = self.clock.report();
        if report.skew_exceeded == self.skew_warning {
            return;
        }
        self.skew_warning = report.skew_exceeded;
        let skew_ms = report.imu_gnss_skew_s.unwrap_or(f64::NAN) * 1e3;
        if report.skew_exceeded {
            log::warn!(
                "IMU and GNSS stamps disagree by {skew_ms:.1} ms on average (limit {:.1} ms): \
                 check the host clock sync, leap_seconds and host_latency_s",
                self.params.max_imu_gnss_skew_s * 1e3
            );
        } else {
            log::info!("IMU and GNSS stamps agree again ({skew_ms:.1} ms)");
        }
    }

    fn malformed(&mut self, error: &str) -> Option<GnssMeasurements> {
        self.counts.malformed += 1;
        self.log.warn(
            "malformed",
            &format!("malformed u-blox message dropped: {error}"),
        );
        None
    }

    /// The /diagnostics status named `name`: the time base, the clock check and every
    /// count. WARN when the IMU/GNSS skew is beyond its limit, or when epochs arrive but
    /// none has a usable satellite (no ephemeris yet: about 30 s after a cold start).
    pub fn diagnostics(&self, name: &str) -> DiagnosticStatus {
        let report = self.clock.report();
        let fmt_s = |v: Option<f64>| v.map_or("unknown".to_owned(), |s| format!("{s:.4}"));
        let mut values: Vec<KeyValue> = vec![
            key_value(
                "time_base",
                match self.params.time_base {
                    TimeBase::Gnss => "gnss",
                    TimeBase::Host => "host",
                },
            ),
            key_value(
                "leap_seconds",
                &self.last_leap.map_or("unknown".to_owned(), |(s, source)| {
                    format!(
                        "{s} ({})",
                        match source {
                            LeapSource::Receiver => "receiver",
                            LeapSource::Parameter => "parameter",
                        }
                    )
                }),
            ),
            key_value(
                "receiver_to_host_offset_s",
                &fmt_s(report.receiver_to_host_s.map(|(mean, _)| mean)),
            ),
            key_value(
                "receiver_to_host_jitter_s",
                &fmt_s(report.receiver_to_host_s.map(|(_, std)| std)),
            ),
            key_value("imu_gnss_skew_s", &fmt_s(report.imu_gnss_skew_s)),
        ];
        values.extend(
            self.counts
                .key_values()
                .into_iter()
                .map(|(k, v)| key_value(k, &v)),
        );
        let (level, message) = if report.skew_exceeded {
            (
                DiagnosticStatus::WARN,
                "IMU and GNSS stamps disagree beyond max_imu_gnss_skew_s".to_owned(),
            )
        } else if self.counts.rawx > 0 && self.counts.published == 0 {
            (
                DiagnosticStatus::WARN,
                "no epoch with a usable satellite yet (waiting for ephemerides?)".to_owned(),
            )
        } else {
            (
                DiagnosticStatus::OK,
                format!("{} epochs published", self.counts.published),
            )
        };
        DiagnosticStatus {
            level,
            name: name.to_owned(),
            message,
            hardware_id: String::new(),
            values,
        }
    }
}

fn key_value(key: &str, value: &str) -> KeyValue {
    KeyValue {
        key: key.to_owned(),
        value: value.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::msg::{Header, RawxData, RecStat, TrkStat};

    /// A RAWX of one GPS L1 signal at `tow_s`, received 40 ms later (UTC stamp).
    fn rawx(tow_s: f64) -> UbxRxmRawx {
        let gpst_s = 315_964_800.0 + 2381.0 * 604_800.0 + tow_s;
        UbxRxmRawx {
            header: Header {
                stamp: seconds_to_time(gpst_s - 18.0 + 0.04).unwrap(),
                frame_id: "ubx".to_owned(),
            },
            rcv_tow: tow_s,
            week: 2381,
            leap_s: 18,
            num_meas: 1,
            rec_stat: RecStat {
                leap_sec: true,
                clk_reset: false,
            },
            version: 1,
            rawx_data: vec![RawxData {
                pr_mes: 2.2e7,
                gnss_id: 0,
                sv_id: 5,
                trk_stat: TrkStat {
                    pr_valid: true,
                    ..TrkStat::default()
                },
                ..RawxData::default()
            }],
        }
    }

    fn value(status: &DiagnosticStatus, key: &str) -> String {
        status
            .values
            .iter()
            .find(|kv| kv.key == key)
            .map(|kv| kv.value.clone())
            .unwrap_or_default()
    }

    #[test]
    fn diagnostics_warn_while_no_epoch_is_usable_and_report_the_clocks() {
        let mut adapter = UbxAdapter::new(UbxAdapterParams::default()).unwrap();
        let status = adapter.diagnostics("ubx");
        assert_eq!(status.level, DiagnosticStatus::OK);
        assert_eq!(value(&status, "receiver_to_host_offset_s"), "unknown");
        for k in 0..3 {
            let msg = rawx(408_000.0 + f64::from(k) * 0.25);
            let arrival_s = time_to_seconds(&msg.header.stamp).unwrap();
            assert_eq!(adapter.on_rawx(&msg, arrival_s), None, "no ephemeris");
        }
        let status = adapter.diagnostics("ubx");
        assert_eq!(status.level, DiagnosticStatus::WARN);
        assert!(status.message.contains("no epoch with a usable satellite"));
        assert_eq!(value(&status, "empty_epochs"), "3");
        assert_eq!(value(&status, "satellite_epochs_no_ephemeris"), "3");
        assert_eq!(value(&status, "receiver_to_host_offset_s"), "0.0400");
        assert_eq!(value(&status, "leap_seconds"), "18 (receiver)");
        assert_eq!(value(&status, "imu_gnss_skew_s"), "unknown");
        // A count that disagrees with the array is malformed, not used.
        let mut bad = rawx(408_001.0);
        bad.num_meas = 2;
        assert_eq!(adapter.on_rawx(&bad, 0.0), None);
        assert_eq!(adapter.counts().malformed, 1);
        assert_eq!(adapter.counts().empty_epochs, 3);
    }
}
