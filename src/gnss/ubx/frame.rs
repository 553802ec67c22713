//! UBX framing: sync 0xB5 0x62, class, id, little-endian payload length, payload, and the
//! 8-bit Fletcher checksum over class..payload. The reader resynchronizes on any garbage,
//! in time linear in the input (see [`super::scanner`]), and never panics.
//!
//! Choice (resynchronization): after a bad checksum, or a header whose declared length
//! runs past the end of the input or beyond [`super::MAX_PAYLOAD_LEN`], the search for the
//! next sync pattern restarts one byte after the rejected sync, so a corrupt length field
//! cannot swallow the frames behind it. A frame cut by the end of the input is counted as
//! truncated; a frame cut in the middle of the stream (followed by other data) fails its
//! checksum and is counted as corrupt.

use super::scanner::{checksum, FrameStats, Scanner, CHECKSUM_LEN, HEADER_LEN, SYNC_1, SYNC_2};

/// One checksum-verified UBX frame, borrowing its payload from the input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UbxFrame<'a> {
    /// Message class.
    pub class: u8,
    /// Message id.
    pub id: u8,
    /// Payload bytes.
    pub payload: &'a [u8],
    /// Byte offset of the frame's first sync byte in the input.
    pub offset: usize,
}

/// Encodes a UBX frame (for tests and tools): sync, header, payload, checksum. None if
/// the payload is longer than a u16 length can state.
pub fn encode_frame(class: u8, id: u8, payload: &[u8]) -> Option<Vec<u8>> {
    let len = u16::try_from(payload.len()).ok()?;
    let mut out = Vec::with_capacity(payload.len() + HEADER_LEN + CHECKSUM_LEN);
    out.extend_from_slice(&[SYNC_1, SYNC_2, class, id]);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(payload);
    let (a, b) = checksum(out.get(2..).unwrap_or(&[]));
    out.push(a);
    out.push(b);
    Some(out)
}

/// Iterator over the valid UBX frames of a byte buffer; [`FrameReader::stats`] tells what
/// was skipped. The buffer is the whole input: a frame cut by its end is truncated.
#[derive(Debug, Clone)]
pub struct FrameReader<'a> {
    data: &'a [u8],
    scanner: Scanner,
}

impl<'a> FrameReader<'a> {
    /// A reader over `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Self {
            data,
            scanner: Scanner::default(),
        }
    }

    /// Counts so far.
    pub fn stats(&self) -> FrameStats {
        self.scanner.stats()
    }
}

impl<'a> Iterator for FrameReader<'a> {
    type Item = UbxFrame<'a>;

    fn next(&mut self) -> Option<UbxFrame<'a>> {
        let (start, end) = self.scanner.next(self.data, 0, true)?;
        frame_of(self.data.get(start..end)?, start)
    }
}

/// The frame whose bytes (sync to checksum, already verified) are `bytes`, found at
/// absolute offset `offset`.
pub(crate) fn frame_of(bytes: &[u8], offset: usize) -> Option<UbxFrame<'_>> {
    Some(UbxFrame {
        class: *bytes.get(2)?,
        id: *bytes.get(3)?,
        payload: bytes.get(HEADER_LEN..bytes.len().checked_sub(CHECKSUM_LEN)?)?,
        offset,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksum_of_a_known_frame() {
        // UBX-CFG-RATE poll-free example from the interface description family:
        // B5 62 06 08 06 00 E8 03 01 00 01 00 → checksum 01 39.
        let frame = [0x06, 0x08, 0x06, 0x00, 0xE8, 0x03, 0x01, 0x00, 0x01, 0x00];
        assert_eq!(checksum(&frame), (0x01, 0x39));
    }

    #[test]
    fn frames_garbage_corruption_and_truncation_are_counted() {
        let good = encode_frame(0x01, 0x07, &[1, 2, 3]).unwrap();
        let mut bad = encode_frame(0x02, 0x15, &[9, 9]).unwrap();
        let last = bad.len() - 1;
        bad[last] ^= 0xFF;
        let mut data = vec![0x00, 0x11, SYNC_1];
        data.extend_from_slice(&good);
        data.extend_from_slice(&bad);
        data.extend_from_slice(&good);
        data.extend_from_slice(&good[..5]);
        let mut reader = FrameReader::new(&data);
        let frames: Vec<_> = reader.by_ref().collect();
        assert_eq!(frames.len(), 2);
        assert_eq!(frames[0].payload, &[1, 2, 3]);
        assert_eq!((frames[0].class, frames[0].id), (0x01, 0x07));
        assert_eq!(frames[0].offset, 3);
        let stats = reader.stats();
        assert_eq!(stats.frames, 2);
        assert_eq!(stats.bad_checksum, 1);
        assert_eq!(stats.truncated, 1);
        // Every byte outside the two valid frames: garbage, the bad frame, the cut one.
        assert_eq!(stats.skipped_bytes, data.len() - 2 * good.len());
    }
}
