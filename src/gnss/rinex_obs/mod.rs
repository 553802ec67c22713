//! A RINEX 3 observation-file reader (text in, epochs out) and the conversion of its
//! epochs into [`crate::gnss::GnssEpoch`]s with the broadcast ephemerides.
//!
//! Header errors are fatal ([`RinexObsError`] with the line number); a malformed record
//! line costs only its satellite or epoch and is listed in [`RecordStats::errors`] (see
//! [`record`]'s notes). Nothing in here panics on bad input.
//!
//! Choice: hand-written rather than on the `rinex` crate. Evaluated: `rinex` 0.24.0 is
//! MPL-2.0 (file-level copyleft, usable as a dependency of this Apache-2.0 crate), and
//! with its `obs` and `nav` features it reads walk_1730.obs (536 epochs, the three
//! systems' types) and walk_1730.nav (17 records) correctly and did not panic on 40
//! mutated copies. Against it: it brings 287 crates into the lock file (hifitime,
//! anise, ring, geo, ...), 22 minutes of cold build on this project's 2-core machine,
//! and it drops malformed records silently, where this crate's input rule wants each
//! bad line reported with its number and counted. RINEX 3 observation records are
//! fixed-column text that takes a few hundred lines to read that way, and the
//! navigation side is already hand-written ([`crate::gnss::rinex_nav`]).

mod epoch;
mod error;
mod header;
pub mod record;

pub use epoch::{build_rinex_epoch, pseudorange_codes};
pub use error::RinexObsError;
pub use header::{parse_header, ObsCode, ObsHeader, TimeSystem};
pub use record::{
    parse_records, ObsEpoch, ObsValue, Observation, RecordStats, SatRecord, SkippedRecord,
};

/// Contents of a RINEX 3 observation file.
#[derive(Debug, Clone, PartialEq)]
pub struct RinexObs {
    /// The header.
    pub header: ObsHeader,
    /// Observation epochs (flags 0 and 1), in file order.
    pub epochs: Vec<ObsEpoch>,
    /// What else the records held, and the malformed lines.
    pub stats: RecordStats,
}

/// Parses the text of a RINEX 3 observation file.
pub fn parse_rinex_obs(text: &str) -> Result<RinexObs, RinexObsError> {
    let lines: Vec<&str> = text.lines().collect();
    let header = parse_header(&lines)?;
    let (epochs, stats) = parse_records(&header, &lines);
    Ok(RinexObs {
        header,
        epochs,
        stats,
    })
}
