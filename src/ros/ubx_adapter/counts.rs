//! What the [`super::UbxAdapter`] received, used and dropped, for /diagnostics and the
//! conversion summary.

use crate::gnss::epoch_build::EpochStats;
use crate::gnss::ubx::{BroadcastNavStats, FrameStats};

/// Counts since the adapter started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UbxAdapterCounts {
    /// UBXRxmRawx messages received, and RAWX frames of the byte stream.
    pub rawx: u64,
    /// UBXRxmSfrbx messages received, and SFRBX frames of the byte stream.
    pub sfrbx: u64,
    /// UInt8MultiArray chunks received, and their bytes.
    pub stream_chunks: u64,
    pub stream_bytes: u64,
    /// Payloads that did not decode (CDR), any topic.
    pub undecodable: u64,
    /// Driver messages whose stated count differs from their array (num_meas,
    /// num_words), or stream frames of RAWX/SFRBX whose payload does not fit the layout.
    pub malformed: u64,
    /// Valid stream frames of other message types (not used).
    pub other_frames: u64,
    /// RAWX with a receiver time that is not finite or not within a week.
    pub invalid_time: u64,
    /// RAWX at the receiver time of the last one used (dropped).
    pub duplicate_epochs: u64,
    /// RAWX before the last one used (dropped; receiver clock reset or a stray epoch).
    pub time_backwards: u64,
    /// RAWX more than 10 s after the last one used (dropped; a stray epoch, or the first
    /// ones after an outage).
    pub time_jumps_ahead: u64,
    /// Receiver timelines taken after a sustained jump.
    pub timeline_restarts: u64,
    /// Epochs whose leap seconds came from the parameter (receiver's not valid).
    pub leap_seconds_from_parameter: u64,
    /// GnssMeasurements published.
    pub published: u64,
    /// Epochs without a usable satellite (not published).
    pub empty_epochs: u64,
    /// Epochs whose stamp is no ROS time (not published).
    pub unstampable: u64,
    /// Satellite counts summed over the epochs built (measurements, used, left out by
    /// reason: no ephemeris, single frequency, duplicate signals, unsupported,
    /// ephemeris errors).
    pub satellites: EpochStats,
    /// Framing counts of the byte stream.
    pub frames: FrameStats,
    /// Navigation data counts (subframes rejected by reason, issue mismatches,
    /// ephemerides).
    pub nav: BroadcastNavStats,
}

impl UbxAdapterCounts {
    /// Adds the counts of one built epoch.
    pub fn add_epoch(&mut self, s: &EpochStats) {
        let t = &mut self.satellites;
        t.measurements += s.measurements;
        t.satellites += s.satellites;
        t.unsupported += s.unsupported;
        t.duplicate_signals += s.duplicate_signals;
        t.single_frequency += s.single_frequency;
        t.phase_only += s.phase_only;
        t.no_ephemeris += s.no_ephemeris;
        t.ephemeris_errors += s.ephemeris_errors;
        t.used += s.used;
    }

    /// Every count as (key, value), in a fixed order.
    pub fn key_values(&self) -> Vec<(&'static str, String)> {
        let own = [
            ("rawx", self.rawx),
            ("sfrbx", self.sfrbx),
            ("stream_chunks", self.stream_chunks),
            ("stream_bytes", self.stream_bytes),
            ("undecodable", self.undecodable),
            ("malformed", self.malformed),
            ("other_frames", self.other_frames),
            ("invalid_time", self.invalid_time),
            ("duplicate_epochs", self.duplicate_epochs),
            ("time_backwards", self.time_backwards),
            ("time_jumps_ahead", self.time_jumps_ahead),
            ("timeline_restarts", self.timeline_restarts),
            (
                "leap_seconds_from_parameter",
                self.leap_seconds_from_parameter,
            ),
            ("published", self.published),
            ("empty_epochs", self.empty_epochs),
            ("unstampable", self.unstampable),
        ];
        let (s, f, n) = (&self.satellites, &self.frames, &self.nav.decoder);
        let decoding = [
            ("satellite_epochs_used", s.used),
            ("satellite_epochs_no_ephemeris", s.no_ephemeris),
            ("satellite_epochs_single_frequency", s.single_frequency),
            ("satellite_epochs_phase_only", s.phase_only),
            ("satellite_epochs_duplicate_signals", s.duplicate_signals),
            ("satellite_epochs_unsupported", s.unsupported),
            ("satellite_epochs_ephemeris_errors", s.ephemeris_errors),
            ("frames_bad_checksum", f.bad_checksum),
            ("frames_truncated", f.truncated),
            ("frames_oversized", f.oversized),
            ("stream_skipped_bytes", f.skipped_bytes),
            ("subframes_rejected", n.rejected),
            ("subframes_wrong_word_count", n.rejected_word_count),
            ("subframes_parity_errors", n.rejected_parity),
            ("ephemeris_issue_mismatch", n.issue_mismatch),
            ("ephemerides", n.ephemerides),
            ("subframes_without_time", self.nav.sfrbx_without_time),
        ];
        own.iter()
            .map(|(k, v)| (*k, v.to_string()))
            .chain(decoding.iter().map(|(k, v)| (*k, v.to_string())))
            .collect()
    }
}
