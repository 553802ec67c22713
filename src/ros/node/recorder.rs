//! `gnss_ins_node --record OUT.mcap`: everything the node publishes, written to a
//! rosbag2 MCAP bag as it is published.
//!
//! Log times are the node's time at publishing (sim time under `use_sim_time`), as
//! `ros2 bag record` stamps what it receives. A write that fails is logged once and
//! recording stops; the node goes on publishing.

use std::path::Path;

use crate::ros::bag::BagWriter;
use crate::ros::msg::{RosMessage, Time};

/// An open recording.
pub struct Recorder {
    writer: Option<BagWriter>,
    written: u64,
}

impl Recorder {
    /// Creates the bag (an existing file is an error, as for `ros2 bag record -o`).
    pub fn create(path: &Path) -> Result<Self, String> {
        if path.exists() {
            return Err(format!(
                "--record {}: the file exists; choose a new name",
                path.display()
            ));
        }
        let writer =
            BagWriter::create(path).map_err(|e| format!("--record {}: {e}", path.display()))?;
        log::info!("recording what the node publishes into {}", path.display());
        Ok(Self {
            writer: Some(writer),
            written: 0,
        })
    }

    /// Writes `message` on `topic` at the node time `now`.
    pub fn record<M: RosMessage>(&mut self, topic: &str, message: &M, now: Time) {
        let Some(writer) = self.writer.as_mut() else {
            return;
        };
        let sec = u64::try_from(now.sec).unwrap_or(0);
        let log_time_ns = sec * 1_000_000_000 + u64::from(now.nanosec);
        match writer.write(topic, message, log_time_ns) {
            Ok(()) => self.written += 1,
            Err(e) => {
                log::error!("recording stopped: {e}");
                self.writer = None;
            }
        }
    }

    /// Completes the bag (summary and index), so it opens as an indexed rosbag2 bag.
    pub fn finish(self) {
        if let Some(writer) = self.writer {
            let path = writer.path().display().to_string();
            match writer.finish() {
                Ok(()) => log::info!("recorded {} messages into {path}", self.written),
                Err(e) => log::error!("{path}: finishing the recording failed: {e}"),
            }
        }
    }
}
