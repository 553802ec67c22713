//! A bit string (most significant bit first) assembled from navigation-message words,
//! with checked field extraction: reading past the end gives None, never a panic.

/// Bits of a navigation message, one element (0 or 1) per bit.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Bits {
    bits: Vec<u8>,
}

impl Bits {
    /// An empty bit string.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends the `len` (≤ 64) least significant bits of `value`, most significant first.
    pub fn push(&mut self, value: u64, len: u32) {
        for k in (0..len.min(64)).rev() {
            self.bits.push(((value >> k) & 1) as u8);
        }
    }

    /// Number of bits.
    pub fn len(&self) -> usize {
        self.bits.len()
    }

    /// Whether there are no bits.
    pub fn is_empty(&self) -> bool {
        self.bits.is_empty()
    }

    /// Unsigned field of `len` (≤ 64) bits starting at bit `pos`.
    pub fn u(&self, pos: usize, len: usize) -> Option<u64> {
        if len > 64 {
            return None;
        }
        let field = self.bits.get(pos..pos.checked_add(len)?)?;
        Some(field.iter().fold(0u64, |acc, &b| (acc << 1) | u64::from(b)))
    }

    /// Two's-complement signed field of `len` (1..=64) bits starting at bit `pos`.
    pub fn s(&self, pos: usize, len: usize) -> Option<i64> {
        let raw = self.u(pos, len)?;
        if len == 0 {
            return None;
        }
        let shift = 64 - len as u32;
        Some(((raw << shift) as i64) >> shift)
    }

    /// Unsigned field assembled from two pieces (MSB part, then LSB part), for fields
    /// split across words.
    pub fn u2(
        &self,
        pos_msb: usize,
        len_msb: usize,
        pos_lsb: usize,
        len_lsb: usize,
    ) -> Option<u64> {
        let msb = self.u(pos_msb, len_msb)?;
        let lsb = self.u(pos_lsb, len_lsb)?;
        Some((msb << len_lsb) | lsb)
    }

    /// Signed field assembled from two pieces (MSB part, then LSB part).
    pub fn s2(
        &self,
        pos_msb: usize,
        len_msb: usize,
        pos_lsb: usize,
        len_lsb: usize,
    ) -> Option<i64> {
        let raw = self.u2(pos_msb, len_msb, pos_lsb, len_lsb)?;
        let len = len_msb + len_lsb;
        if len == 0 || len > 64 {
            return None;
        }
        let shift = 64 - len as u32;
        Some(((raw << shift) as i64) >> shift)
    }

    /// The bits `pos..pos + len` as a new bit string.
    pub fn slice(&self, pos: usize, len: usize) -> Option<Bits> {
        Some(Bits {
            bits: self.bits.get(pos..pos.checked_add(len)?)?.to_vec(),
        })
    }

    /// Appends another bit string.
    pub fn extend(&mut self, other: &Bits) {
        self.bits.extend_from_slice(&other.bits);
    }

    /// The bits as a slice of 0/1 values.
    pub fn as_slice(&self) -> &[u8] {
        &self.bits
    }
}

/// 2^`exp` as f64 (scale factors of the ICD tables).
pub fn pow2(exp: i32) -> f64 {
    2f64.powi(exp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_signs_and_bounds() {
        let mut b = Bits::new();
        b.push(0b1011, 4);
        b.push(0xFF, 8);
        assert_eq!(b.len(), 12);
        assert_eq!(b.u(0, 4), Some(11));
        assert_eq!(b.s(0, 4), Some(-5));
        assert_eq!(b.u(4, 8), Some(255));
        assert_eq!(b.s(4, 8), Some(-1));
        assert_eq!(b.u2(0, 2, 10, 2), Some(0b1011));
        assert_eq!(b.u(8, 5), None);
        assert_eq!(b.u(usize::MAX, 2), None);
        assert_eq!(b.s(0, 0), None);
    }
}
