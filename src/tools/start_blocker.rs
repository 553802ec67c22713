//! Why a run produced no solution, in terms of the parameters a user can change: the
//! start-up phase the engine was still in at the end of the bag names them.

use crate::config::Config;
use crate::engine::InitPhase;

/// What kept the filter from starting, for the error of a run without a solution;
/// `phase` is where the start-up stood at the end (None: the filter was running).
pub fn start_blocker(phase: Option<InitPhase>, config: &Config) -> String {
    match phase {
        None => "the filter ran, but no solution passed the output guard (counts above)".to_owned(),
        Some(InitPhase::Leveling) => format!(
            "the start-up never levelled: it needs IMU samples, init.leveling_duration_s = \
             {} s of them at rest or GNSS positions to align in motion",
            config.init.leveling_duration_s
        ),
        Some(InitPhase::WaitingForPosition) => format!(
            "no GNSS epoch gave the starting position: a single-point solution needs \
             init.min_satellites = {} satellites above gnss.elevation_mask_deg = {} deg \
             with C/N0 above gnss.cn0_mask_dbhz = {} dB-Hz (loosely coupled: a fix)",
            config.init.min_satellites,
            config.gnss.elevation_mask_rad.to_degrees(),
            config.gnss.cn0_mask_dbhz
        ),
        Some(InitPhase::WaitingForHeading) => format!(
            "the heading never became known: the platform never moved faster than \
             init.heading_min_speed_mps = {} m/s",
            config.init.heading_min_speed_mps
        ),
        Some(InitPhase::AligningHeading) => {
            "the bag ended while the heading hypotheses were still being resolved".to_owned()
        }
    }
}
