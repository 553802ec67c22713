//! The framing state machine shared by the file reader ([`super::FrameReader`]) and the
//! stream framer ([`super::UbxFramer`]): find a sync pattern, read the header, verify the
//! checksum, resynchronize one byte after a rejected sync.
//!
//! Math note (linear time): the 8-bit Fletcher checksum of any byte range comes in O(1)
//! from running sums kept per byte, S_i = Σ_{k≤i} x_k and T_i = Σ_{k≤i} S_k (mod 256):
//! over x_s..x_{e−1}, CK_A = S_{e−1} − S_{s−1} and
//! CK_B = Σ_{j=s}^{e−1} (S_j − S_{s−1}) = T_{e−1} − T_{s−1} − (e − s)·S_{s−1}.
//! Each byte's sums are computed once, and each candidate sync costs O(1) however long a
//! payload it declares, so a sync flood costs as much as any other input of its size.
//! (Checking each candidate by summing its bytes costs up to 64 KiB per candidate.)

/// First sync byte.
pub const SYNC_1: u8 = 0xB5;
/// Second sync byte.
pub const SYNC_2: u8 = 0x62;
/// Header bytes before the payload (sync ×2, class, id, length ×2).
pub const HEADER_LEN: usize = 6;
/// Checksum bytes after the payload.
pub const CHECKSUM_LEN: usize = 2;

/// Counts of what the reader met.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameStats {
    /// Frames with a valid checksum.
    pub frames: usize,
    /// Frames rejected for a bad checksum.
    pub bad_checksum: usize,
    /// Frames whose declared length runs past the end of the input.
    pub truncated: usize,
    /// Headers declaring a payload longer than [`super::MAX_PAYLOAD_LEN`].
    pub oversized: usize,
    /// Bytes that are not part of a valid frame (garbage, rejected frames).
    pub skipped_bytes: usize,
}

/// The 8-bit Fletcher checksum (CK_A, CK_B) of `bytes`.
pub fn checksum(bytes: &[u8]) -> (u8, u8) {
    bytes.iter().fold((0u8, 0u8), |(a, b), &x| {
        let a = a.wrapping_add(x);
        (a, b.wrapping_add(a))
    })
}

/// Longest payload accepted (bytes).
///
/// Choice: a header declaring more is rejected at once (counted as oversized) instead of
/// waiting for up to 64 KiB: in a live stream, one spurious sync in garbage would
/// otherwise hold back every frame behind it until 64 KiB more arrived (seconds at
/// receiver data rates). 8 KiB holds the longest periodic u-blox output, UBX-RXM-RAWX of
/// 255 measurements (16 + 32 · 255 = 8 176 bytes), and it bounds the stream framer's
/// buffer.
pub const MAX_PAYLOAD_LEN: usize = 8_192;

/// Longest frame accepted (bytes).
pub const MAX_FRAME_LEN: usize = HEADER_LEN + MAX_PAYLOAD_LEN + CHECKSUM_LEN;

/// Running Fletcher sums (S_i, T_i) of the bytes at absolute offsets `first..`, counted
/// from the byte at `first` (the origin cancels in every difference).
#[derive(Debug, Clone, Default)]
struct RunningSums {
    first: usize,
    sums: Vec<(u8, u8)>,
}

impl RunningSums {
    /// Absolute offset one past the last byte with sums.
    fn end(&self) -> usize {
        self.first + self.sums.len()
    }

    /// Computes the sums up to (excluding) absolute offset `end` from `window`, which
    /// holds the bytes at absolute offsets `window_start..`, at least from [`Self::end`].
    fn extend_to(&mut self, window: &[u8], window_start: usize, end: usize) {
        let bytes = self
            .end()
            .checked_sub(window_start)
            .zip(end.checked_sub(window_start))
            .and_then(|(from, to)| window.get(from..to));
        let (mut s, mut t) = self.sums.last().copied().unwrap_or((0, 0));
        self.sums.extend(bytes.unwrap_or_default().iter().map(|&x| {
            s = s.wrapping_add(x);
            t = t.wrapping_add(s);
            (s, t)
        }));
    }

    /// Sums after the byte at absolute offset `i`.
    fn at(&self, i: usize) -> Option<(u8, u8)> {
        self.sums.get(i.checked_sub(self.first)?).copied()
    }

    /// The checksum (CK_A, CK_B) of the bytes at absolute offsets `start..end`
    /// (`start > first`, sums computed up to `end`).
    fn checksum(&self, start: usize, end: usize) -> Option<(u8, u8)> {
        let (s0, t0) = self.at(start.checked_sub(1)?)?;
        let (s1, t1) = self.at(end.checked_sub(1)?)?;
        // (e − s) mod 256: only the low byte enters a product modulo 256.
        let count = (end - start) as u8;
        Some((
            s1.wrapping_sub(s0),
            t1.wrapping_sub(t0).wrapping_sub(count.wrapping_mul(s0)),
        ))
    }

    /// Forgets the sums before absolute offset `offset` (all of them, and restarts there,
    /// when it lies past the last); amortized O(1) per byte.
    fn forget_before(&mut self, offset: usize) {
        if offset >= self.end() {
            self.sums.clear();
            self.first = offset;
            return;
        }
        let drop = offset.saturating_sub(self.first);
        if drop > 0 && drop >= self.sums.len() / 2 {
            self.sums.drain(..drop);
            self.first += drop;
        }
    }
}

/// Framing position, running sums and counts; see the module doc.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scanner {
    /// Absolute offset of the next byte to examine.
    pos: usize,
    sums: RunningSums,
    stats: FrameStats,
}

impl Scanner {
    /// Counts so far.
    pub fn stats(&self) -> FrameStats {
        self.stats
    }

    /// Absolute offset of the first byte still needed (bytes before it are done with).
    pub fn pos(&self) -> usize {
        self.pos
    }

    fn skip(&mut self, bytes: usize) {
        self.pos += bytes;
        self.stats.skipped_bytes += bytes;
    }

    /// The next valid frame as absolute offsets (start of the sync, one past the
    /// checksum), from `window`, the bytes at absolute offsets `window_start..` (which
    /// must include the current position). None when the window holds no further frame:
    /// with `end_of_input` false the bytes of an incomplete candidate are kept for the next
    /// call; with `end_of_input` true they are counted (truncated, skipped) and the search
    /// goes on one byte after its sync, as after a bad checksum.
    pub fn next(
        &mut self,
        window: &[u8],
        window_start: usize,
        end_of_input: bool,
    ) -> Option<(usize, usize)> {
        let window_end = window_start + window.len();
        loop {
            let rest = window.get(self.pos.checked_sub(window_start)?..)?;
            let Some(found) = rest.windows(2).position(|w| w == [SYNC_1, SYNC_2]) else {
                // A first sync byte at the very end may be completed by the next bytes.
                let keep = usize::from(!end_of_input && rest.last() == Some(&SYNC_1));
                self.skip(rest.len() - keep);
                return None;
            };
            self.skip(found);
            let start = self.pos;
            let Some(header) = rest.get(found..found + HEADER_LEN) else {
                if end_of_input {
                    self.stats.truncated += 1;
                    self.skip(window_end - start);
                }
                return None;
            };
            let len = usize::from(u16::from_le_bytes([header[4], header[5]]));
            if len > MAX_PAYLOAD_LEN {
                self.stats.oversized += 1;
                self.skip(1);
                continue;
            }
            let end = start + HEADER_LEN + len + CHECKSUM_LEN;
            if end > window_end {
                if !end_of_input {
                    return None;
                }
                self.stats.truncated += 1;
                self.skip(1);
                continue;
            }
            let checked_end = end - CHECKSUM_LEN;
            // Sums from the byte after the sync on: those before are never needed again.
            self.sums.forget_before(start + 1);
            self.sums.extend_to(window, window_start, checked_end);
            let expected = window.get(checked_end - window_start..end - window_start)?;
            match self.sums.checksum(start + 2, checked_end) {
                Some((a, b)) if expected == [a, b] => {
                    self.stats.frames += 1;
                    self.pos = end;
                    return Some((start, end));
                }
                _ => {
                    self.stats.bad_checksum += 1;
                    self.skip(1);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::checksum;
    use super::*;

    #[test]
    fn running_sums_give_the_checksum_of_any_range() {
        let bytes: Vec<u8> = (0..600u32).map(|k| (k * 37 % 251) as u8).collect();
        let mut sums = RunningSums::default();
        sums.extend_to(&bytes, 0, bytes.len());
        for (start, end) in [(1, 2), (1, 600), (7, 300), (299, 300), (5, 5), (42, 555)] {
            assert_eq!(
                sums.checksum(start, end),
                Some(checksum(&bytes[start..end])),
                "{start}..{end}"
            );
        }
        assert_eq!(sums.checksum(0, 3), None, "needs the byte before the range");
        sums.forget_before(400);
        assert_eq!(sums.checksum(450, 600), Some(checksum(&bytes[450..600])));
        assert_eq!(sums.checksum(100, 600), None, "forgotten");
    }
}
