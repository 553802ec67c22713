//! BeiDou D1 navigation message (MEO/IGSO) from UBX-RXM-SFRBX: BCH(15,11,1) check and the
//! ephemeris of subframes 1–3 (BDS-SIS-ICD B1I/B3I, 5.2.4). D2 (GEO) is not decoded.
//!
//! u-blox layout (checked on real data): 10 words, 30 bits each in bits 29..0, already
//! de-interleaved: word 1 = 26 information bits (15 unencoded, then 11 BCH-coded) and 4
//! parity bits; words 2–10 = 11 + 11 information bits, then 4 + 4 parity bits. The
//! parity-free concatenation has 26 + 9 · 22 = 224 bits; field positions below index it.

use super::bits::{pow2, Bits};
use super::gps_lnav::nearest_gps_time;
use super::nav_error::NavDataError;
use crate::gnss::ephemeris::{
    GpsTime, GroupDelay, KeplerianEphemeris, NavSource, BDT_MINUS_GPST_S,
};
use crate::gnss::SatId;

/// Words per D1 subframe.
pub const D1_WORDS: usize = 10;
/// D1 preamble (11 bits).
const PREAMBLE: u64 = 0b111_0001_0010;
/// BCH(15,11) generator g(x) = x⁴ + x + 1.
const BCH_GENERATOR: u32 = 0b1_0011;
/// Ephemeris validity half-window (s): BDS updates hourly.
const VALIDITY_S: f64 = 3_600.0;

/// A BCH-checked D1 subframe: id (1–5), seconds of BDT week, and 224 information bits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct D1Subframe {
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

/// Checks the BCH codes and the preamble of one D1 subframe and strips the parity.
pub fn d1_subframe(sat: SatId, words: &[u32]) -> Result<D1Subframe, NavDataError> {
    if words.len() != D1_WORDS {
        return Err(NavDataError::WordCount {
            sat,
            words: words.len(),
            expected: D1_WORDS,
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
    Ok(D1Subframe { id, sow_s, data })
}

/// The GPST of a BDT seconds-of-week value, in the week that puts it nearest `reference`.
fn from_bdt_sow(sow_s: f64, reference: &GpsTime) -> GpsTime {
    nearest_gps_time(sow_s - BDT_MINUS_GPST_S, reference)
}

/// Ephemeris from D1 subframes 1, 2, 3 of one frame (seconds of week t, t+6, t+12).
/// `reference` (GPST within days) resolves the week. None if the subframes are not of
/// one frame or a field is missing.
pub fn decode_d1_ephemeris(
    sat: SatId,
    sf1: &D1Subframe,
    sf2: &D1Subframe,
    sf3: &D1Subframe,
    reference: &GpsTime,
) -> Option<KeplerianEphemeris> {
    let same_frame = (sf1.id, sf2.id, sf3.id) == (1, 2, 3)
        && sf2.sow_s.checked_sub(sf1.sow_s) == Some(6)
        && sf3.sow_s.checked_sub(sf1.sow_s) == Some(12);
    if !same_frame {
        return None;
    }
    let sc = std::f64::consts::PI;
    let (d1, d2, d3) = (&sf1.data, &sf2.data, &sf3.data);
    let f = |v: Option<i64>, scale: f64| v.map(|x| x as f64 * scale);
    let g = |v: Option<u64>, scale: f64| v.map(|x| x as f64 * scale);
    // toe: 2 MSBs at the end of subframe 2, 15 LSBs at the start of subframe 3.
    let toe_sow = ((d2.u(222, 2)? << 15) | d3.u(38, 15)?) as f64 * 8.0;
    Some(KeplerianEphemeris {
        sat,
        source: NavSource::BeidouD1,
        toe: from_bdt_sow(toe_sow, reference),
        toc: from_bdt_sow(g(d1.u(61, 17), 8.0)?, reference),
        sqrt_a_sqrt_m: g(d2.u(190, 32), pow2(-19))?,
        eccentricity: g(d2.u(104, 32), pow2(-33))?,
        inclination_rad: f(d3.s(53, 32), pow2(-31) * sc)?,
        inclination_rate_rad_s: f(d3.s(145, 14), pow2(-43) * sc)?,
        raan_rad: f(d3.s(159, 32), pow2(-31) * sc)?,
        raan_rate_rad_s: f(d3.s(103, 24), pow2(-43) * sc)?,
        arg_perigee_rad: f(d3.s(191, 32), pow2(-31) * sc)?,
        mean_anomaly_rad: f(d2.s(72, 32), pow2(-31) * sc)?,
        mean_motion_diff_rad_s: f(d2.s(38, 16), pow2(-43) * sc)?,
        cuc_rad: f(d2.s(54, 18), pow2(-31))?,
        cus_rad: f(d2.s(136, 18), pow2(-31))?,
        crc_m: f(d2.s(154, 18), pow2(-6))?,
        crs_m: f(d2.s(172, 18), pow2(-6))?,
        cic_rad: f(d3.s(85, 18), pow2(-31))?,
        cis_rad: f(d3.s(127, 18), pow2(-31))?,
        af0_s: f(d1.s(173, 24), pow2(-33))?,
        af1_s_s: f(d1.s(197, 22), pow2(-50))?,
        af2_s_s2: f(d1.s(162, 11), pow2(-66))?,
        group_delay: GroupDelay::Beidou {
            tgd1_s: f(d1.s(78, 10), 1e-10)?,
            tgd2_s: f(d1.s(88, 10), 1e-10)?,
        },
        issue_of_data: u16::try_from(d1.u(219, 5)?).ok()?,
        health: u16::try_from(d1.u(38, 1)?).ok()?,
        validity_s: VALIDITY_S,
    })
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
