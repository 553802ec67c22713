//! Epoch records of a RINEX 3 observation file (RINEX 3.04, Table A3): the epoch line
//! (`>`, time, flag, number of satellites or special records, receiver clock offset)
//! and one line per satellite with 16 columns per observation type (F14.3, LLI, SSI).
//!
//! Choices:
//! - Observation epochs (flags 0 and 1) are kept. Event records (flags 2–5: antenna
//!   moving, new site, header information, external event) are skipped with their
//!   special records, and so are cycle-slip records (flag 6), each counted by flag.
//! - A malformed line costs only what it spoils: a bad satellite line drops that
//!   satellite, a bad epoch line drops its record, which ends where the next line
//!   starting with `>` begins (every RINEX 3 epoch line does). Each is reported as an
//!   error with its line number and reading goes on.
//! - A value of exactly 0 is read as missing: RINEX 3.04 5.7 allows 0.0 or blanks for
//!   a missing observation.
//! - Satellites of systems outside [`Constellation`] (NavIC) are skipped and counted.

use std::collections::BTreeMap;

use super::error::{columns, number, optional_real, RinexObsError};
use super::header::{ObsCode, ObsHeader};
use crate::gnss::ephemeris::GpsTime;
use crate::gnss::{Constellation, SatId};

/// Width of one observation field: F14.3 value, LLI digit, SSI digit.
const FIELD_WIDTH: usize = 16;
/// Width of the satellite identifier at the start of a satellite line.
const SAT_WIDTH: usize = 3;
/// Start and end columns of the receiver clock offset on the epoch line (F15.12).
const CLOCK_OFFSET_COLUMNS: (usize, usize) = (41, 56);

/// One observation with its loss-of-lock indicator and signal-strength indicator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObsValue {
    /// Pseudo-range (m), carrier phase (cycles), Doppler (Hz) or signal strength (as the
    /// header's unit, usually dB-Hz), by the code's type letter.
    pub value: f64,
    /// Loss-of-lock indicator (0–7), if written.
    pub lli: Option<u8>,
    /// Signal-strength indicator (1–9), if written.
    pub ssi: Option<u8>,
}

/// One observation code and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Observation code (`C1C`, `L1C`, ...).
    pub code: ObsCode,
    /// Its value and indicators.
    pub value: ObsValue,
}

/// The observations of one satellite at one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct SatRecord {
    /// The satellite.
    pub sat: SatId,
    /// The values present, in the header's order of types.
    pub observations: Vec<Observation>,
}

impl SatRecord {
    /// The value of observation `code`, if present.
    pub fn get(&self, code: ObsCode) -> Option<ObsValue> {
        self.observations
            .iter()
            .find(|o| o.code == code)
            .map(|o| o.value)
    }
}

/// An observation epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsEpoch {
    /// Line number of the epoch line (1-based).
    pub line: usize,
    /// Epoch (receiver clock) as GPS time.
    pub time: GpsTime,
    /// True for flag 1: a power failure happened since the previous epoch.
    pub power_failure: bool,
    /// Receiver clock offset (s), if written.
    pub receiver_clock_offset_s: Option<f64>,
    /// The satellites.
    pub satellites: Vec<SatRecord>,
}

/// Records that are not observation epochs, by epoch flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SkippedRecord {
    /// Flag 2: start of moving antenna.
    MovingAntenna,
    /// Flag 3: new site occupation.
    NewSite,
    /// Flag 4: header information follows.
    HeaderInformation,
    /// Flag 5: external event.
    ExternalEvent,
    /// Flag 6: cycle-slip records.
    CycleSlips,
}

impl SkippedRecord {
    fn from_flag(flag: u8) -> Option<Self> {
        Some(match flag {
            2 => Self::MovingAntenna,
            3 => Self::NewSite,
            4 => Self::HeaderInformation,
            5 => Self::ExternalEvent,
            6 => Self::CycleSlips,
            _ => return None,
        })
    }
}

/// What the record reader met besides observation epochs.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RecordStats {
    /// Observation epochs returned.
    pub epochs: usize,
    /// Epochs with flag 1 (returned, marked).
    pub power_failure_epochs: usize,
    /// Records skipped, by kind.
    pub skipped: BTreeMap<SkippedRecord, usize>,
    /// Satellite lines of systems this crate does not model (skipped).
    pub unsupported_satellites: usize,
    /// Lines outside any record that were not epoch lines (skipped).
    pub stray_lines: usize,
    /// Malformed lines, each with what it cost (see the module notes).
    pub errors: Vec<RinexObsError>,
}

/// The epoch records after the header, read in order.
pub fn parse_records(header: &ObsHeader, lines: &[&str]) -> (Vec<ObsEpoch>, RecordStats) {
    let mut stats = RecordStats::default();
    let mut epochs = Vec::new();
    let mut i = header.lines;
    while let Some(line) = lines.get(i) {
        let line_no = i + 1;
        i += 1;
        if line.trim().is_empty() {
            continue;
        }
        if !line.starts_with('>') {
            stats.stray_lines += 1;
            continue;
        }
        let head = match epoch_line(header, line, line_no) {
            Ok(h) => h,
            Err(e) => {
                stats.errors.push(e);
                // Resynchronize at the next epoch line.
                while lines.get(i).is_some_and(|l| !l.starts_with('>')) {
                    i += 1;
                }
                continue;
            }
        };
        // The lines of this record: up to `count`, never across the next epoch line.
        let available = lines
            .get(i..)
            .unwrap_or(&[])
            .iter()
            .take(head.count)
            .take_while(|l| !l.starts_with('>'))
            .count();
        let body = lines.get(i..i + available).unwrap_or(&[]);
        let body_start = i;
        i += available;
        if available < head.count {
            stats.errors.push(RinexObsError::Truncated {
                line: line_no,
                announced: head.count,
                found: available,
            });
            continue;
        }
        if let Some(kind) = SkippedRecord::from_flag(head.flag) {
            *stats.skipped.entry(kind).or_default() += 1;
            continue;
        }
        let mut satellites = Vec::with_capacity(body.len());
        for (k, sat_line) in body.iter().enumerate() {
            match satellite_line(header, sat_line, body_start + k + 1) {
                Ok(Some(record)) => satellites.push(record),
                Ok(None) => stats.unsupported_satellites += 1,
                Err(e) => stats.errors.push(e),
            }
        }
        stats.epochs += 1;
        if head.flag == 1 {
            stats.power_failure_epochs += 1;
        }
        epochs.push(ObsEpoch {
            line: line_no,
            time: head.time,
            power_failure: head.flag == 1,
            receiver_clock_offset_s: head.clock_offset_s,
            satellites,
        });
    }
    (epochs, stats)
}

/// The fields of an epoch line.
struct EpochHead {
    time: GpsTime,
    flag: u8,
    /// Satellite lines (flags 0, 1, 6) or special records (flags 2–5) that follow.
    count: usize,
    clock_offset_s: Option<f64>,
}

/// `> yyyy mm dd hh mm ss.sssssss  f nnn      clock-offset`.
fn epoch_line(header: &ObsHeader, line: &str, line_no: usize) -> Result<EpochHead, RinexObsError> {
    let int = |a, b, what| number::<i64>(line, a, b, line_no, what);
    let flag: u8 = number(line, 29, 32, line_no, "epoch flag")?;
    if flag > 6 {
        return Err(RinexObsError::BadField {
            line: line_no,
            what: "epoch flag",
        });
    }
    let count: usize = number(line, 32, 35, line_no, "number of satellites")?;
    // Event records (flags 2–5) may leave the time blank; their time is not used.
    let time = if (2..=5).contains(&flag) {
        GpsTime::new(0, 0.0)
    } else {
        let second: f64 = number(line, 18, 29, line_no, "second")?;
        header
            .time_system
            .to_gps_time(
                int(1, 6, "year")?,
                int(6, 9, "month")?,
                int(9, 12, "day")?,
                int(12, 15, "hour")?,
                int(15, 18, "minute")?,
                second,
            )
            .ok_or(RinexObsError::BadField {
                line: line_no,
                what: "epoch time",
            })?
    };
    let (a, b) = CLOCK_OFFSET_COLUMNS;
    let clock_offset_s = optional_real(line, a, b, line_no, "receiver clock offset")?;
    Ok(EpochHead {
        time,
        flag,
        count,
        clock_offset_s,
    })
}

/// One satellite line; None for a system outside [`Constellation`].
fn satellite_line(
    header: &ObsHeader,
    line: &str,
    line_no: usize,
) -> Result<Option<SatRecord>, RinexObsError> {
    let bad = |what| RinexObsError::BadField {
        line: line_no,
        what,
    };
    let system = columns(line, 0, 1)
        .and_then(|s| s.chars().next())
        .ok_or(bad("satellite system"))?;
    let prn: u16 = number(line, 1, SAT_WIDTH, line_no, "satellite number")?;
    let types = header
        .obs_types
        .get(&system)
        .ok_or(RinexObsError::UndeclaredSystem {
            line: line_no,
            system,
        })?;
    let constellation = match system {
        'G' => Constellation::Gps,
        'R' => Constellation::Glonass,
        'E' => Constellation::Galileo,
        'C' => Constellation::Beidou,
        'J' => Constellation::Qzss,
        'S' => Constellation::Sbas,
        _ => return Ok(None),
    };
    let mut observations = Vec::with_capacity(types.len());
    for (k, &code) in types.iter().enumerate() {
        let start = SAT_WIDTH + FIELD_WIDTH * k;
        let Some(value) = optional_real(line, start, start + 14, line_no, "observation value")?
        else {
            continue;
        };
        if value == 0.0 {
            continue;
        }
        let digit = |col: usize, what| -> Result<Option<u8>, RinexObsError> {
            match columns(line, col, col + 1) {
                None | Some("") | Some(" ") => Ok(None),
                Some(s) => s.parse::<u8>().map(Some).map_err(|_| bad(what)),
            }
        };
        observations.push(Observation {
            code,
            value: ObsValue {
                value,
                lli: digit(start + 14, "loss-of-lock indicator")?,
                ssi: digit(start + 15, "signal-strength indicator")?,
            },
        });
    }
    Ok(Some(SatRecord {
        sat: SatId { constellation, prn },
        observations,
    }))
}
