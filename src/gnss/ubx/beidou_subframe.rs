//! BeiDou D1 (MEO/IGSO) and D2 (GEO) subframes from UBX-RXM-SFRBX: BCH(15,11,1) check,
//! preamble, subframe id and seconds of week (BDS-SIS-ICD B1I 5.1, 5.2.4, 5.3.3). Both
//! messages share this word structure; [`super::beidou_d1`] and [`super::beidou_d2`]
//! read their ephemerides.
//!
//! u-blox layout (checked on real data): 10 words, 30 bits each in bits 29..0, already
//! de-interleaved: word 1 = 26 information bits (15 unencoded, then 11 BCH-coded) and 4
//! parity bits; words 2–10 = 11 + 11 information bits, then 4 + 4 parity bits. The
//! parity-free concatenation has 26 + 9 · 22 = 224 bits; the field positions of the
//! ephemeris decoders index it (an ICD bit position p of the 300-bit subframe, in word
//! w = ⌊p/30⌋ at offset o = p mod 30, is o for w = 0 and 26 + 22 (w − 1) + o otherwise).

use super::bits::Bits;
use super::gps_lnav::nearest_gps_time;
use super::nav_error::NavDataError;
use crate::gnss::ephemeris::{GpsTime, BDT_MINUS_GPST_S};
use crate::gnss::SatId;

/// Words per D1 or D2 subframe.
pub const BDS_WORDS: usize = 10;
/// D1 preamble (11 bits).
const PREAMBLE: u64 = 0b111_0001_0010;
/// BCH(15,11) generator g(x) = x⁴ + x + 1.
const BCH_GENERATOR: u32 = 0b1_0011;
/// Ephemeris validity half-window (s): BDS updates hourly.
pub const BDS_VALIDITY_S: f64 = 3_600.0;

/// A BCH-checked D1 or D2 subframe: id (1–5), seconds of BDT week, and 224 information
/// bits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BdsSubframe {
    /// Subframe id (FraID).
    pub id: u8,
    /// Seconds of the BDT week at the start of the subframe.
    pub sow_s: u32,
    /// Information bits without parity.
    pub data: Bits,
}

/// Whether a 15-bit BCH(15,11) codeword (11 information bits, then 4 parity) is valid.
fn bch_ok(codeword: u32) -> bool {
    let mut r = codeword & 0x7FFF;
    for shift in (4..15).rev() {
        if (r >> shift) & 1 == 1 {
            r ^= BCH_GENERATOR << (shift - 4);
        }
    }
    r == 0
}

/// Checks the BCH codes and the preamble of one D1 or D2 subframe and strips the parity.
pub fn bds_subframe(sat: SatId, words: &[u32]) -> Result<BdsSubframe, NavDataError> {
    if words.len() != BDS_WORDS {
        return Err(NavDataError::WordCount {
            sat,
            words: words.len(),
            expected: BDS_WORDS,
        });
    }
    let mut data = Bits::new();
    for (k, &raw) in words.iter().enumerate() {
        let w = raw & 0x3FFF_FFFF;
        if k == 0 {
            if !bch_ok(((w >> 4) & 0x7FF) << 4 | (w & 0xF)) {
                return Err(NavDataError::Bch { sat, word: k });
            }
            data.push(u64::from(w >> 4), 26);
        } else {
            let (i1, i2) = ((w >> 19) & 0x7FF, (w >> 8) & 0x7FF);
            let (p1, p2) = ((w >> 4) & 0xF, w & 0xF);
            if !(bch_ok(i1 << 4 | p1) && bch_ok(i2 << 4 | p2)) {
                return Err(NavDataError::Bch { sat, word: k });
            }
            data.push(u64::from(i1), 11);
            data.push(u64::from(i2), 11);
        }
    }
    if data.u(0, 11) != Some(PREAMBLE) {
        return Err(NavDataError::Preamble { sat });
    }
    let id = data.u(15, 3).unwrap_or(0) as u8;
    let sow_s = data.u(18, 20).unwrap_or(0) as u32;
    Ok(BdsSubframe { id, sow_s, data })
}

/// The GPST of a BDT seconds-of-week value, in the week that puts it nearest `reference`.
pub fn from_bdt_sow(sow_s: f64, reference: &GpsTime) -> GpsTime {
    nearest_gps_time(sow_s - BDT_MINUS_GPST_S, reference)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Systematic BCH(15,11) encoding: parity = remainder of info·x⁴ by g(x).
    fn encode(info: u32) -> u32 {
        let mut r = info << 4;
        for shift in (4..15).rev() {
            if (r >> shift) & 1 == 1 {
                r ^= BCH_GENERATOR << (shift - 4);
            }
        }
        (info << 4) | r
    }

    #[test]
    fn bch_detects_every_single_bit_error() {
        for info in [0u32, 1, 0x5A5, 0x7FF, 0x123] {
            let c = encode(info);
            assert!(bch_ok(c));
            for bit in 0..15 {
                assert!(!bch_ok(c ^ (1 << bit)), "{info:#x} bit {bit}");
            }
        }
    }
}
