//! RTKLIB time-tag files (`FILE.tag` beside a logged stream `FILE`), pure parsing.
//!
//! Layout (RTKLIB `stream.c`, little-endian): a 64-byte header whose text starts
//! "TIMETAG RTKLIB" and whose last 4 bytes are the uint32 tick (ms) at which the file was
//! opened; a uint32 start time, whole seconds since 1970 in the GPS time scale; a float64
//! fraction of that second; then 8-byte records, each a uint32 tick (ms since the file
//! was opened) and a uint32 byte offset into the logged stream.

/// Bytes before the first record: 64-byte header, uint32 seconds, float64 fraction.
const HEADER_LEN: usize = 76;
const TEXT_LEN: usize = 60;
const RECORD_LEN: usize = 8;
const MAGIC: &[u8] = b"TIMETAG RTKLIB";

/// Why a time-tag file cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TimeTagError {
    #[error("{len} bytes: shorter than the {HEADER_LEN}-byte time-tag header")]
    TooShort { len: usize },
    #[error("the header does not start with \"TIMETAG RTKLIB\"")]
    BadMagic,
    #[error("the start time fraction {fraction_s} is not in [0, 1)")]
    BadFraction { fraction_s: f64 },
    #[error("no tick record after the header")]
    NoRecords,
}

/// One record: when (ms since the file was opened) the stream had reached which byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TagRecord {
    pub tick_ms: u32,
    pub byte_offset: u32,
}

/// A parsed time-tag file.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeTag {
    /// Tick (ms, the logging computer's clock) at which the file was opened.
    pub open_tick_ms: u32,
    /// Time the file was opened: GPST seconds since 1970 (GPS scale, no leap seconds).
    pub start_gpst_s: f64,
    pub records: Vec<TagRecord>,
    /// Bytes of a cut-off last record, ignored.
    pub trailing_bytes: usize,
}

impl TimeTag {
    /// The last record (a parsed tag always has one).
    pub fn last(&self) -> Option<&TagRecord> {
        self.records.last()
    }
}

/// Parses a time-tag file.
pub fn parse_time_tag(bytes: &[u8]) -> Result<TimeTag, TimeTagError> {
    if bytes.len() < HEADER_LEN {
        return Err(TimeTagError::TooShort { len: bytes.len() });
    }
    if !bytes.starts_with(MAGIC) {
        return Err(TimeTagError::BadMagic);
    }
    let u32_at = |at: usize| {
        let mut b = [0u8; 4];
        b.copy_from_slice(&bytes[at..at + 4]);
        u32::from_le_bytes(b)
    };
    let mut f = [0u8; 8];
    f.copy_from_slice(&bytes[68..76]);
    let fraction_s = f64::from_le_bytes(f);
    if !(0.0..1.0).contains(&fraction_s) {
        return Err(TimeTagError::BadFraction { fraction_s });
    }
    let body = &bytes[HEADER_LEN..];
    let records: Vec<TagRecord> = body
        .chunks_exact(RECORD_LEN)
        .map(|r| TagRecord {
            tick_ms: u32::from_le_bytes([r[0], r[1], r[2], r[3]]),
            byte_offset: u32::from_le_bytes([r[4], r[5], r[6], r[7]]),
        })
        .collect();
    if records.is_empty() {
        return Err(TimeTagError::NoRecords);
    }
    Ok(TimeTag {
        open_tick_ms: u32_at(TEXT_LEN),
        start_gpst_s: f64::from(u32_at(64)) + fraction_s,
        records,
        trailing_bytes: body.len() % RECORD_LEN,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tag_bytes(records: &[(u32, u32)], extra: &[u8]) -> Vec<u8> {
        let mut b = vec![0u8; 64];
        b[..MAGIC.len()].copy_from_slice(MAGIC);
        b[60..64].copy_from_slice(&7u32.to_le_bytes());
        b.extend_from_slice(&1_756_402_240u32.to_le_bytes());
        b.extend_from_slice(&0.25f64.to_le_bytes());
        for (t, o) in records {
            b.extend_from_slice(&t.to_le_bytes());
            b.extend_from_slice(&o.to_le_bytes());
        }
        b.extend_from_slice(extra);
        b
    }

    #[test]
    fn parses_header_and_records_and_counts_a_cut_record() {
        let tag = parse_time_tag(&tag_bytes(&[(113, 835), (134_271, 1_001_983)], &[1, 2])).unwrap();
        assert_eq!(tag.open_tick_ms, 7);
        assert_eq!(tag.start_gpst_s, 1_756_402_240.25);
        assert_eq!(tag.records.len(), 2);
        assert_eq!(tag.last().map(|r| r.tick_ms), Some(134_271));
        assert_eq!(tag.trailing_bytes, 2);
    }

    #[test]
    fn rejects_what_is_not_a_tag() {
        assert_eq!(
            parse_time_tag(b"TIMETAG"),
            Err(TimeTagError::TooShort { len: 7 })
        );
        let mut b = tag_bytes(&[(1, 2)], &[]);
        b[0] = b'X';
        assert_eq!(parse_time_tag(&b), Err(TimeTagError::BadMagic));
        assert_eq!(
            parse_time_tag(&tag_bytes(&[], &[])),
            Err(TimeTagError::NoRecords)
        );
    }
}
