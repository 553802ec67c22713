//! Galileo I/NAV nominal pages from UBX-RXM-SFRBX (E1-B), and the ephemeris, clock, BGD
//! and health of word types 1–5 (Galileo OS SIS ICD 4.3.5).
//!
//! u-blox layout: 8 words; words 0–3 hold the even page part (120 bits, MSB first from
//! bit 31 of word 0), words 4–7 the odd part. Even part: even/odd flag (0), page type,
//! data 1/2 (112 bits), tail. Odd part: flag (1), page type, data 2/2 (16 bits), OSNMA
//! (40), SAR (22), spare (2), CRC (24), SSP (8), tail. The CRC-24Q covers the even part's
//! first 114 bits followed by the odd part's first 82 bits.

use super::bits::{pow2, Bits};
use super::gps_lnav::nearest_gps_time;
use super::nav_error::NavDataError;
use crate::gnss::ephemeris::{GpsTime, GroupDelay, KeplerianEphemeris, NavSource};
use crate::gnss::SatId;

/// Words of a u-blox I/NAV page pair.
pub const INAV_WORDS: usize = 8;
/// CRC-24Q polynomial (without the x²⁴ term).
const CRC24Q_POLY: u32 = 0x86_4CFB;
/// Ephemeris validity half-window (s): 4 h.
const VALIDITY_S: f64 = 14_400.0;

/// One I/NAV data word: its type and its 128 bits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InavWord {
    /// Word type (0–63).
    pub word_type: u8,
    /// The 128 data bits, word type first.
    pub data: Bits,
}

/// CRC-24Q of a bit string (initial value 0), as used by Galileo I/NAV and SBAS.
pub fn crc24q(bits: &[u8]) -> u32 {
    bits.iter().fold(0u32, |crc, &b| {
        let top = ((crc >> 23) & 1) ^ u32::from(b & 1);
        let shifted = (crc << 1) & 0xFF_FFFF;
        if top == 1 {
            shifted ^ CRC24Q_POLY
        } else {
            shifted
        }
    })
}

/// Checks the page layout and CRC of a nominal I/NAV page pair and returns its data word.
pub fn inav_word(sat: SatId, words: &[u32]) -> Result<InavWord, NavDataError> {
    if words.len() != INAV_WORDS {
        return Err(NavDataError::WordCount {
            sat,
            words: words.len(),
            expected: INAV_WORDS,
        });
    }
    let mut all = Bits::new();
    for &w in words {
        all.push(u64::from(w), 32);
    }
    let layout = NavDataError::PageLayout { sat };
    let even = all.slice(0, 120).ok_or(layout.clone())?;
    let odd = all.slice(128, 120).ok_or(layout.clone())?;
    // Even part first (flag 0), odd second (flag 1); page type 0 = nominal.
    if even.u(0, 2) != Some(0) || odd.u(0, 2) != Some(2) {
        return Err(layout);
    }
    let mut covered = even.slice(0, 114).ok_or(layout.clone())?;
    covered.extend(&odd.slice(0, 82).ok_or(layout.clone())?);
    if odd.u(82, 24) != Some(u64::from(crc24q(covered.as_slice()))) {
        return Err(NavDataError::Crc { sat });
    }
    let mut data = even.slice(2, 112).ok_or(layout.clone())?;
    data.extend(&odd.slice(2, 16).ok_or(layout)?);
    let word_type = data.u(0, 6).unwrap_or(63) as u8;
    Ok(InavWord { word_type, data })
}

/// Issue of data (IODnav) of word types 1–4.
pub fn iod_nav(word: &InavWord) -> Option<u16> {
    matches!(word.word_type, 1..=4)
        .then(|| word.data.u(6, 10))
        .flatten()
        .and_then(|v| u16::try_from(v).ok())
}

/// Ephemeris from word types 1–4 (same IODnav) and 5 (BGD, health); None while the
/// IODnavs differ. `reference` (GPST within days) resolves the week of toe and toc.
///
/// Choice: differing IODnavs are never an error: I/NAV words carry no count that would
/// tell one batch's broadcast from the next, so a new batch arriving and a corrupt word
/// look alike; either way no ephemeris is formed until the four agree.
///
/// Errors: [`NavDataError::PageLayout`] when a word has the wrong type,
/// [`NavDataError::MissingField`] when a field lies beyond the bits.
///
/// Choice (health): the stored health packs E5b HS, E1-B HS, E5b DVS and E1-B DVS
/// (bits 5..0: hs5b<<4 | hs1b<<2 | dvs5b<<1 | dvs1b); the store uses only sets whose four
/// flags are all zero, the conservative reading for an E1 (and E5b) user.
pub fn decode_inav_ephemeris(
    sat: SatId,
    words: [&InavWord; 5],
    reference: &GpsTime,
) -> Result<Option<KeplerianEphemeris>, NavDataError> {
    let types = words.map(|w| w.word_type);
    if types != [1, 2, 3, 4, 5] {
        return Err(NavDataError::PageLayout { sat });
    }
    let missing = NavDataError::MissingField { sat };
    let iod = iod_nav(words[0]).ok_or(missing.clone())?;
    if words[1..4].iter().any(|w| iod_nav(w) != Some(iod)) {
        return Ok(None);
    }
    inav_elements(sat, words, iod, reference)
        .map(Some)
        .ok_or(missing)
}

/// The elements of word types 1–5 of issue `iod`.
fn inav_elements(
    sat: SatId,
    words: [&InavWord; 5],
    iod: u16,
    reference: &GpsTime,
) -> Option<KeplerianEphemeris> {
    let [w1, w2, w3, w4, w5] = words;
    let sc = std::f64::consts::PI;
    let (d1, d2, d3, d4, d5) = (&w1.data, &w2.data, &w3.data, &w4.data, &w5.data);
    let f = |v: Option<i64>, scale: f64| v.map(|x| x as f64 * scale);
    let g = |v: Option<u64>, scale: f64| v.map(|x| x as f64 * scale);
    let health = (d5.u(67, 2)? << 4) | (d5.u(69, 2)? << 2) | (d5.u(71, 1)? << 1) | d5.u(72, 1)?;
    Some(KeplerianEphemeris {
        sat,
        source: NavSource::GalileoInav,
        toe: nearest_gps_time(g(d1.u(16, 14), 60.0)?, reference),
        toc: nearest_gps_time(g(d4.u(54, 14), 60.0)?, reference),
        sqrt_a_sqrt_m: g(d1.u(94, 32), pow2(-19))?,
        eccentricity: g(d1.u(62, 32), pow2(-33))?,
        inclination_rad: f(d2.s(48, 32), pow2(-31) * sc)?,
        inclination_rate_rad_s: f(d2.s(112, 14), pow2(-43) * sc)?,
        raan_rad: f(d2.s(16, 32), pow2(-31) * sc)?,
        raan_rate_rad_s: f(d3.s(16, 24), pow2(-43) * sc)?,
        arg_perigee_rad: f(d2.s(80, 32), pow2(-31) * sc)?,
        mean_anomaly_rad: f(d1.s(30, 32), pow2(-31) * sc)?,
        mean_motion_diff_rad_s: f(d3.s(40, 16), pow2(-43) * sc)?,
        cuc_rad: f(d3.s(56, 16), pow2(-29))?,
        cus_rad: f(d3.s(72, 16), pow2(-29))?,
        crc_m: f(d3.s(88, 16), pow2(-5))?,
        crs_m: f(d3.s(104, 16), pow2(-5))?,
        cic_rad: f(d4.s(22, 16), pow2(-29))?,
        cis_rad: f(d4.s(38, 16), pow2(-29))?,
        af0_s: f(d4.s(68, 31), pow2(-34))?,
        af1_s_s: f(d4.s(99, 21), pow2(-46))?,
        af2_s_s2: f(d4.s(120, 6), pow2(-59))?,
        group_delay: GroupDelay::Galileo {
            bgd_e1_e5a_s: f(d5.s(47, 10), pow2(-32))?,
            bgd_e1_e5b_s: Some(f(d5.s(57, 10), pow2(-32))?),
        },
        issue_of_data: iod,
        health: u16::try_from(health).ok()?,
        validity_s: VALIDITY_S,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc24q_of_a_known_message() {
        // CRC-24Q (RTCM 3 / Galileo) of the ASCII bytes "123456789" is 0xCDE703.
        let mut bits = Bits::new();
        for b in b"123456789" {
            bits.push(u64::from(*b), 8);
        }
        assert_eq!(crc24q(bits.as_slice()), 0xCD_E703);
    }
}
