//! Errors of the RINEX observation reader, and the fixed-column field readers they come
//! from.

use thiserror::Error;

/// What went wrong on which line (1-based) of a RINEX observation file.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum RinexObsError {
    /// No `END OF HEADER` line.
    #[error("no END OF HEADER line")]
    NoHeaderEnd,
    /// The first line is not a `RINEX VERSION / TYPE` line of an observation file.
    #[error("line {line}: not a RINEX observation file")]
    NotObservationFile { line: usize },
    /// A version other than 3.xx.
    #[error("line {line}: RINEX version {version} is not 3.xx")]
    UnsupportedVersion { line: usize, version: String },
    /// A time system other than GPS, Galileo, QZSS or BeiDou time.
    #[error("line {line}: time system '{system}' is not supported")]
    UnsupportedTimeSystem { line: usize, system: String },
    /// A field that should hold a value does not.
    #[error("line {line}: cannot read {what}")]
    BadField { line: usize, what: &'static str },
    /// A satellite of a system the header lists no observation types for.
    #[error("line {line}: no SYS / # / OBS TYPES for system '{system}'")]
    UndeclaredSystem { line: usize, system: char },
    /// An epoch record has fewer lines than its epoch line announces.
    #[error("line {line}: epoch record truncated ({announced} lines announced, {found} found)")]
    Truncated {
        line: usize,
        announced: usize,
        found: usize,
    },
}

/// Bytes `start..end` of `line` (shorter if the line is), as text; None when `start` is
/// past the end or the bytes are not UTF-8.
pub(crate) fn columns(line: &str, start: usize, end: usize) -> Option<&str> {
    let bytes = line.as_bytes();
    let end = end.min(bytes.len());
    let slice = bytes.get(start..end)?;
    std::str::from_utf8(slice).ok()
}

/// The header label (columns 61–80) of a header line, trimmed.
pub(crate) fn label(line: &str) -> &str {
    columns(line, 60, 80).map_or("", str::trim)
}

/// A number in columns `start..end`; errors name `what` and the line.
pub(crate) fn number<T: std::str::FromStr>(
    line: &str,
    start: usize,
    end: usize,
    line_no: usize,
    what: &'static str,
) -> Result<T, RinexObsError> {
    columns(line, start, end)
        .and_then(|s| s.trim().parse().ok())
        .ok_or(RinexObsError::BadField {
            line: line_no,
            what,
        })
}

/// A finite real in columns `start..end` (RINEX 'D' exponents accepted); None when the
/// columns are blank or absent.
pub(crate) fn optional_real(
    line: &str,
    start: usize,
    end: usize,
    line_no: usize,
    what: &'static str,
) -> Result<Option<f64>, RinexObsError> {
    let bad = RinexObsError::BadField {
        line: line_no,
        what,
    };
    let Some(text) = columns(line, start, end).map(str::trim) else {
        return if start >= line.len() {
            Ok(None)
        } else {
            Err(bad)
        };
    };
    if text.is_empty() {
        return Ok(None);
    }
    let value: f64 = text
        .replace(['D', 'd'], "E")
        .parse()
        .map_err(|_| bad.clone())?;
    if value.is_finite() {
        Ok(Some(value))
    } else {
        Err(bad)
    }
}
