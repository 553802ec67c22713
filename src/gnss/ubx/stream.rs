//! [`UbxFramer`]: UBX frames from a byte stream that arrives in chunks of any size (a
//! serial port's reads, `std_msgs/UInt8MultiArray` messages): frames split across chunks
//! are joined, garbage is skipped, checksums are verified, by the same
//! [`super::scanner`] as the file reader, so any chunking of a stream gives the frames
//! and counts the file reader gives for the whole stream (once [`UbxFramer::finish`] has
//! been called).
//!
//! Memory is bounded: the buffer keeps the bytes from the first undecided sync on, at
//! most one frame of [`super::MAX_FRAME_LEN`] plus the latest chunk, and twice that
//! before it is compacted.

use super::frame::{frame_of, UbxFrame};
use super::scanner::FrameStats;
use super::scanner::Scanner;

/// A streaming UBX framer; see the module doc.
#[derive(Debug, Clone, Default)]
pub struct UbxFramer {
    /// Bytes from absolute offset `buffer_start` on.
    buffer: Vec<u8>,
    buffer_start: usize,
    scanner: Scanner,
    ended: bool,
}

impl UbxFramer {
    /// A framer that has seen no byte.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends the next bytes of the stream. Take the frames they complete with
    /// [`Self::next_frame`] before the next push.
    pub fn push(&mut self, bytes: &[u8]) {
        // Choice: compact only when at least half of the buffer is done with, so that
        // moving the kept bytes costs no more than the bytes dropped (linear overall).
        let done = self.scanner.pos().saturating_sub(self.buffer_start);
        if done > 0 && done >= self.buffer.len() / 2 {
            self.buffer.drain(..done.min(self.buffer.len()));
            self.buffer_start += done;
        }
        self.buffer.extend_from_slice(bytes);
    }

    /// The next complete, checksum-verified frame of the bytes pushed so far; its
    /// `offset` counts from the first byte ever pushed.
    pub fn next_frame(&mut self) -> Option<UbxFrame<'_>> {
        let (start, end) = self
            .scanner
            .next(&self.buffer, self.buffer_start, self.ended)?;
        let bytes = self
            .buffer
            .get(start - self.buffer_start..end - self.buffer_start)?;
        frame_of(bytes, start)
    }

    /// Marks the end of the stream: the bytes of an incomplete frame are counted as
    /// truncated and the search goes on behind its sync, so [`Self::next_frame`] may still
    /// give frames.
    pub fn finish(&mut self) {
        self.ended = true;
    }

    /// Counts so far.
    pub fn stats(&self) -> FrameStats {
        self.scanner.stats()
    }

    /// Bytes held (for the memory bound).
    pub fn buffered_len(&self) -> usize {
        self.buffer.len()
    }
}

#[cfg(test)]
mod tests {
    use super::super::frame::{encode_frame, FrameReader};
    use super::super::scanner::MAX_FRAME_LEN;
    use super::*;

    /// A frame as (class, id, payload, offset).
    type Owned = (u8, u8, Vec<u8>, usize);

    /// Frames and counts of `data` fed in chunks of `chunk` bytes.
    fn streamed(data: &[u8], chunk: usize) -> (Vec<Owned>, FrameStats) {
        let mut framer = UbxFramer::new();
        let mut frames = Vec::new();
        let mut take = |framer: &mut UbxFramer| {
            while let Some(f) = framer.next_frame() {
                frames.push((f.class, f.id, f.payload.to_vec(), f.offset));
            }
        };
        for piece in data.chunks(chunk) {
            framer.push(piece);
            take(&mut framer);
            assert!(framer.buffered_len() <= 2 * (MAX_FRAME_LEN + chunk));
        }
        framer.finish();
        take(&mut framer);
        (frames, framer.stats())
    }

    #[test]
    fn any_chunking_gives_what_the_file_reader_gives() {
        let a = encode_frame(0x02, 0x15, &[7; 48]).unwrap();
        let b = encode_frame(0x01, 0x07, &[0xB5, 0x62, 1, 2]).unwrap();
        let mut bad = encode_frame(0x02, 0x13, &[3; 40]).unwrap();
        bad[10] ^= 0x40;
        let mut data = vec![0x00, 0xB5, 0x62, 0xB5];
        for frame in [&a, &bad, &b, &a, &b] {
            data.extend_from_slice(frame);
            data.push(0xB5);
        }
        // A sync declaring a long payload, then frames, then the cut end of a frame.
        data.extend_from_slice(&[0xB5, 0x62, 0x02, 0x15, 0x00, 0x10]);
        data.extend_from_slice(&b);
        data.extend_from_slice(&a[..20]);
        let mut reader = FrameReader::new(&data);
        let whole: Vec<_> = reader
            .by_ref()
            .map(|f| (f.class, f.id, f.payload.to_vec(), f.offset))
            .collect();
        assert_eq!(whole.len(), 5);
        for chunk in [1, 2, 3, 5, 7, 64, data.len()] {
            let (frames, stats) = streamed(&data, chunk);
            assert_eq!(frames, whole, "chunk {chunk}");
            assert_eq!(stats, reader.stats(), "chunk {chunk}");
        }
        // Truncated: the leading sync (its header declares 610 bytes), the long one, the
        // cut frame at the end.
        let s = reader.stats();
        assert_eq!((s.bad_checksum, s.truncated), (1, 3), "{s:?}");
    }

    #[test]
    fn a_sync_flood_is_skipped_with_a_bounded_buffer() {
        let flood: Vec<u8> = [0xB5, 0x62, 0x02, 0x15, 0xFF, 0xFF]
            .iter()
            .copied()
            .cycle()
            .take(60_000)
            .collect();
        let (frames, stats) = streamed(&flood, 100);
        assert!(frames.is_empty());
        assert_eq!(stats.oversized, 10_000);
        assert_eq!(stats.skipped_bytes, flood.len());
    }
}
