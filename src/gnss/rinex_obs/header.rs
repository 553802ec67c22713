//! The header of a RINEX 3 observation file (RINEX 3.04, Table A2): version, the
//! observation types of each system, the approximate position, the interval, the time of
//! the first observation and the time system the epochs are written in.

use std::collections::BTreeMap;

use nalgebra::Vector3;

use super::error::{columns, label, number, optional_real, RinexObsError};
use crate::gnss::ephemeris::{GpsTime, BDT_MINUS_GPST_S};
use crate::gnss::rinex_nav::{days_from_civil, GPS_EPOCH_DAYS};

/// Observation types per line of `SYS / # / OBS TYPES`, continuation lines included.
const TYPES_PER_LINE: usize = 13;
/// Calendar years accepted in dates; the bound keeps the day arithmetic far from
/// overflow and rejects garbage early.
const YEARS: std::ops::RangeInclusive<i64> = 1980..=2200;

/// A three-character observation code such as `C1C` (type, band, attribute).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ObsCode(pub [u8; 3]);

impl ObsCode {
    /// The code of `text` if it is three ASCII characters.
    pub fn parse(text: &str) -> Option<Self> {
        let bytes: [u8; 3] = text.as_bytes().try_into().ok()?;
        bytes
            .iter()
            .all(u8::is_ascii_graphic)
            .then_some(Self(bytes))
    }

    /// The code as text.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.0).unwrap_or("???")
    }

    /// The same band and attribute with another observation type letter (C, L, D, S).
    pub fn with_type(&self, kind: u8) -> Self {
        Self([kind, self.0[1], self.0[2]])
    }
}

impl std::fmt::Display for ObsCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The time scale the epochs of a file are written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeSystem {
    /// GPS time (also Galileo and QZSS system time, which share its seconds and epoch
    /// to within nanoseconds).
    Gps,
    /// BeiDou time, GPST − 14 s.
    Beidou,
}

impl TimeSystem {
    /// `GPS`, `GAL`, `QZS` and `BDT`; None for the others (GLONASS and UTC need leap
    /// seconds, which are not modelled here).
    fn from_code(code: &str) -> Option<Self> {
        match code {
            "GPS" | "GAL" | "QZS" => Some(Self::Gps),
            "BDT" => Some(Self::Beidou),
            _ => None,
        }
    }

    /// RINEX 3.04 5.2.2: the default of a file whose first-observation line names none.
    fn default_for(file_system: char) -> Option<Self> {
        match file_system {
            'G' | 'M' | ' ' | 'E' | 'J' => Some(Self::Gps),
            'C' => Some(Self::Beidou),
            _ => None,
        }
    }

    /// A calendar time in this scale, as GPS time; None for an impossible date.
    pub fn to_gps_time(
        self,
        year: i64,
        month: i64,
        day: i64,
        hour: i64,
        minute: i64,
        second: f64,
    ) -> Option<GpsTime> {
        let valid = YEARS.contains(&year)
            && (1..=12).contains(&month)
            && (1..=31).contains(&day)
            && (0..=23).contains(&hour)
            && (0..=59).contains(&minute)
            && second.is_finite()
            && (0.0..61.0).contains(&second);
        if !valid {
            return None;
        }
        let days = days_from_civil(year, month, day) - GPS_EPOCH_DAYS;
        let week = i32::try_from(days.div_euclid(7)).ok()?;
        let whole_s = days.rem_euclid(7) * 86_400 + hour * 3_600 + minute * 60;
        let t = GpsTime::new(week, whole_s as f64 + second);
        Some(match self {
            Self::Gps => t,
            Self::Beidou => t.add_seconds(-BDT_MINUS_GPST_S),
        })
    }
}

/// The header fields this crate uses.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsHeader {
    /// Format version, e.g. 3.04.
    pub version: f64,
    /// File satellite system: `G`, `R`, `E`, `C`, `J`, `S`, `I` or `M` (mixed).
    pub file_system: char,
    /// Observation types of each system letter, in the order of the records.
    pub obs_types: BTreeMap<char, Vec<ObsCode>>,
    /// `APPROX POSITION XYZ` (ECEF, m), if given.
    pub approx_position_ecef_m: Option<Vector3<f64>>,
    /// `INTERVAL` (s), if given.
    pub interval_s: Option<f64>,
    /// `TIME OF FIRST OBS` as GPS time, if given.
    pub time_of_first_obs: Option<GpsTime>,
    /// The time scale of the epochs.
    pub time_system: TimeSystem,
    /// Lines in the header, `END OF HEADER` included (records start on the next line).
    pub lines: usize,
}

/// Reads the header at the start of `lines`.
pub fn parse_header(lines: &[&str]) -> Result<ObsHeader, RinexObsError> {
    let first = lines.first().ok_or(RinexObsError::NoHeaderEnd)?;
    if label(first) != "RINEX VERSION / TYPE" || columns(first, 20, 21) != Some("O") {
        return Err(RinexObsError::NotObservationFile { line: 1 });
    }
    let version_text = columns(first, 0, 9).map_or("", str::trim);
    let version: f64 = version_text
        .parse()
        .ok()
        .filter(|v: &f64| (3.0..4.0).contains(v))
        .ok_or_else(|| RinexObsError::UnsupportedVersion {
            line: 1,
            version: version_text.to_string(),
        })?;
    let file_system = columns(first, 40, 41)
        .and_then(|s| s.chars().next())
        .unwrap_or(' ');

    let mut header = ObsHeader {
        version,
        file_system,
        obs_types: BTreeMap::new(),
        approx_position_ecef_m: None,
        interval_s: None,
        time_of_first_obs: None,
        time_system: TimeSystem::Gps,
        lines: 0,
    };
    let mut time_system = None;
    let mut first_obs_fields = None;
    // System whose type list continues on the next line, and how many types remain.
    let mut pending: Option<(char, usize)> = None;
    for (index, line) in lines.iter().enumerate().skip(1) {
        let line_no = index + 1;
        match label(line) {
            "END OF HEADER" => {
                header.lines = line_no;
                header.time_system = match time_system {
                    Some(ts) => ts,
                    None => TimeSystem::default_for(file_system).ok_or_else(|| {
                        RinexObsError::UnsupportedTimeSystem {
                            line: line_no,
                            system: file_system.to_string(),
                        }
                    })?,
                };
                if let Some((year, month, day, hour, minute, second, line)) = first_obs_fields {
                    header.time_of_first_obs = Some(
                        header
                            .time_system
                            .to_gps_time(year, month, day, hour, minute, second)
                            .ok_or(RinexObsError::BadField {
                                line,
                                what: "time of first observation",
                            })?,
                    );
                }
                return Ok(header);
            }
            "SYS / # / OBS TYPES" => {
                pending = obs_types_line(line, line_no, pending, &mut header.obs_types)?;
            }
            "APPROX POSITION XYZ" => {
                let xyz = |k: usize| number::<f64>(line, 14 * k, 14 * k + 14, line_no, "position");
                let p = Vector3::new(xyz(0)?, xyz(1)?, xyz(2)?);
                if p.iter().all(|v| v.is_finite()) {
                    header.approx_position_ecef_m = Some(p);
                }
            }
            "INTERVAL" => {
                header.interval_s =
                    optional_real(line, 0, 10, line_no, "interval")?.filter(|v| *v > 0.0);
            }
            "TIME OF FIRST OBS" => {
                let int = |a, b, what| number::<i64>(line, a, b, line_no, what);
                first_obs_fields = Some((
                    int(0, 6, "year")?,
                    int(6, 12, "month")?,
                    int(12, 18, "day")?,
                    int(18, 24, "hour")?,
                    int(24, 30, "minute")?,
                    number::<f64>(line, 30, 43, line_no, "second")?,
                    line_no,
                ));
                let code = columns(line, 48, 51).map_or("", str::trim);
                if !code.is_empty() {
                    time_system = Some(TimeSystem::from_code(code).ok_or_else(|| {
                        RinexObsError::UnsupportedTimeSystem {
                            line: line_no,
                            system: code.to_string(),
                        }
                    })?);
                }
            }
            _ => {}
        }
    }
    Err(RinexObsError::NoHeaderEnd)
}

/// One `SYS / # / OBS TYPES` line (A1, 2X, I3, 13(1X, A3)); returns what remains to be
/// read on continuation lines.
fn obs_types_line(
    line: &str,
    line_no: usize,
    pending: Option<(char, usize)>,
    types: &mut BTreeMap<char, Vec<ObsCode>>,
) -> Result<Option<(char, usize)>, RinexObsError> {
    let system = columns(line, 0, 1)
        .and_then(|s| s.chars().next())
        .unwrap_or(' ');
    let (system, remaining) = if system == ' ' {
        pending.ok_or(RinexObsError::BadField {
            line: line_no,
            what: "observation types continuation",
        })?
    } else {
        let count: usize = number(line, 3, 6, line_no, "number of observation types")?;
        types.insert(system, Vec::with_capacity(count));
        (system, count)
    };
    let here = remaining.min(TYPES_PER_LINE);
    let list = types.entry(system).or_default();
    for k in 0..here {
        let start = 7 + 4 * k;
        let code = columns(line, start, start + 3)
            .and_then(ObsCode::parse)
            .ok_or(RinexObsError::BadField {
                line: line_no,
                what: "observation type",
            })?;
        list.push(code);
    }
    Ok((remaining > here).then_some((system, remaining - here)))
}
