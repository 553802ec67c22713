//! GPS (and QZSS) LNAV subframes from UBX-RXM-SFRBX: parity check (IS-GPS-200 Table
//! 20-XIV), ephemeris from subframes 1–3 (Table 20-III) and Klobuchar α/β from subframe 4
//! page 18 (Table 20-X).
//!
//! u-blox layout (checked on real data): 10 words; bits 29..0 of each hold the 30
//! transmitted bits (D1 = bit 29) and bits 31..30 the previous word's D29*, D30*.

use super::bits::{pow2, Bits};
use super::nav_error::NavDataError;
use crate::gnss::ephemeris::{GpsTime, GroupDelay, KeplerianEphemeris, NavSource};
use crate::gnss::{Klobuchar, SatId};

/// Words per LNAV subframe.
pub const LNAV_WORDS: usize = 10;
const PREAMBLE: u64 = 0x8B;
/// Subframe 4 page carrying the ionosphere and UTC parameters (SV ID 56 = page 18).
const IONO_UTC_PAGE_ID: u64 = 56;
/// Validity half-windows (s): fit-interval flag 0 → 4 h fit (±2 h), 1 → longer (±4 h).
const VALIDITY_NORMAL_S: f64 = 7_200.0;
const VALIDITY_EXTENDED_S: f64 = 14_400.0;

/// Parity-bit masks over d1..d24 (bit 23 = d1), IS-GPS-200 Table 20-XIV; the first item
/// says whether D29* (true) or D30* (false) enters.
const PARITY: [(bool, u32); 6] = [
    (true, 0xEC7CD2),
    (false, 0x763E69),
    (true, 0xBB1F34),
    (false, 0x5D8F9A),
    (false, 0xAEC7CD),
    (true, 0x2DEA27),
];

/// A parity-checked LNAV subframe: its id (1–5) and its 240 data bits (polarity
/// restored).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LnavSubframe {
    /// Subframe id from the HOW (1–5).
    pub id: u8,
    /// Data bits d1..d24 of the 10 words.
    pub data: Bits,
}

/// Checks parity and the preamble of one LNAV subframe and returns its data bits.
pub fn lnav_subframe(sat: SatId, words: &[u32]) -> Result<LnavSubframe, NavDataError> {
    if words.len() != LNAV_WORDS {
        return Err(NavDataError::WordCount {
            sat,
            words: words.len(),
            expected: LNAV_WORDS,
        });
    }
    let mut data = Bits::new();
    for (k, &w) in words.iter().enumerate() {
        let d29_star = (w >> 31) & 1;
        let d30_star = (w >> 30) & 1;
        let raw = (w >> 6) & 0xFF_FFFF;
        let d = if d30_star == 1 { !raw & 0xFF_FFFF } else { raw };
        for (bit, &(uses_d29, mask)) in PARITY.iter().enumerate() {
            let star = if uses_d29 { d29_star } else { d30_star };
            let expected = star ^ ((d & mask).count_ones() & 1);
            if expected != (w >> (5 - bit)) & 1 {
                return Err(NavDataError::Parity { sat, word: k });
            }
        }
        data.push(u64::from(d), 24);
    }
    if data.u(0, 8) != Some(PREAMBLE) {
        return Err(NavDataError::Preamble { sat });
    }
    let id = data.u(43, 3).unwrap_or(0) as u8;
    Ok(LnavSubframe { id, data })
}

/// The GPST nearest to `reference` whose seconds of week are `tow_s`.
pub fn nearest_gps_time(tow_s: f64, reference: &GpsTime) -> GpsTime {
    [-1, 0, 1]
        .iter()
        .map(|dw| GpsTime::new(reference.week.saturating_add(*dw), tow_s))
        .min_by(|a, b| {
            a.seconds_since(reference)
                .abs()
                .total_cmp(&b.seconds_since(reference).abs())
        })
        .unwrap_or(GpsTime::new(reference.week, tow_s))
}

/// Ephemeris from subframes 1, 2 and 3 (data bits) of one issue of data (the 8 LSBs of
/// subframe 1's IODC and the IODE of subframes 2 and 3 agree), which may come from
/// different frames; None while they are of different issues (a new upload arriving).
/// `reference` (a GPST within a few days, e.g. the receive time) resolves the weeks of
/// toe and toc.
///
/// Errors: [`NavDataError::IssueMismatch`] when the issues disagree within one frame
/// (consecutive HOW TOW counts), where a new upload never begins (IS-GPS-200 20.3.4.1:
/// cutovers are at frame boundaries): the clock does not match the orbit;
/// [`NavDataError::MissingField`] when a field lies beyond the bits.
pub fn decode_lnav_ephemeris(
    sat: SatId,
    source: NavSource,
    sf1: &Bits,
    sf2: &Bits,
    sf3: &Bits,
    reference: &GpsTime,
) -> Result<Option<KeplerianEphemeris>, NavDataError> {
    let missing = NavDataError::MissingField { sat };
    let field = |bits: &Bits, pos, len| bits.u(pos, len).ok_or(missing.clone());
    let iodc = sf1.u2(70, 2, 168, 8).ok_or(missing.clone())?;
    let iode2 = field(sf2, 48, 8)?;
    let iode3 = field(sf3, 216, 8)?;
    if iode2 == iode3 && iodc & 0xFF == iode2 {
        return lnav_elements(sat, source, sf1, sf2, sf3, iode2, reference)
            .map(Some)
            .ok_or(missing);
    }
    let tow = [
        field(sf1, 24, 17)?,
        field(sf2, 24, 17)?,
        field(sf3, 24, 17)?,
    ];
    if tow[1] == tow[0] + 1 && tow[2] == tow[0] + 2 {
        Err(NavDataError::IssueMismatch { sat })
    } else {
        Ok(None)
    }
}

/// The elements of subframes 1–3 of issue `iode`.
fn lnav_elements(
    sat: SatId,
    source: NavSource,
    sf1: &Bits,
    sf2: &Bits,
    sf3: &Bits,
    iode: u64,
    reference: &GpsTime,
) -> Option<KeplerianEphemeris> {
    let sc = std::f64::consts::PI;
    let fit_flag = sf2.u(232, 1)?;
    let f = |v: Option<i64>, scale: f64| v.map(|x| x as f64 * scale);
    let g = |v: Option<u64>, scale: f64| v.map(|x| x as f64 * scale);
    Some(KeplerianEphemeris {
        sat,
        source,
        toe: nearest_gps_time(g(sf2.u(216, 16), 16.0)?, reference),
        toc: nearest_gps_time(g(sf1.u(176, 16), 16.0)?, reference),
        sqrt_a_sqrt_m: g(sf2.u(184, 32), pow2(-19))?,
        eccentricity: g(sf2.u(136, 32), pow2(-33))?,
        inclination_rad: f(sf3.s(112, 32), pow2(-31) * sc)?,
        inclination_rate_rad_s: f(sf3.s(224, 14), pow2(-43) * sc)?,
        raan_rad: f(sf3.s(64, 32), pow2(-31) * sc)?,
        raan_rate_rad_s: f(sf3.s(192, 24), pow2(-43) * sc)?,
        arg_perigee_rad: f(sf3.s(160, 32), pow2(-31) * sc)?,
        mean_anomaly_rad: f(sf2.s(88, 32), pow2(-31) * sc)?,
        mean_motion_diff_rad_s: f(sf2.s(72, 16), pow2(-43) * sc)?,
        cuc_rad: f(sf2.s(120, 16), pow2(-29))?,
        cus_rad: f(sf2.s(168, 16), pow2(-29))?,
        crc_m: f(sf3.s(144, 16), pow2(-5))?,
        crs_m: f(sf2.s(56, 16), pow2(-5))?,
        cic_rad: f(sf3.s(48, 16), pow2(-29))?,
        cis_rad: f(sf3.s(96, 16), pow2(-29))?,
        af0_s: f(sf1.s(216, 22), pow2(-31))?,
        af1_s_s: f(sf1.s(200, 16), pow2(-43))?,
        af2_s_s2: f(sf1.s(192, 8), pow2(-55))?,
        group_delay: GroupDelay::Gps {
            tgd_s: f(sf1.s(160, 8), pow2(-31))?,
        },
        issue_of_data: u16::try_from(iode).ok()?,
        health: u16::try_from(sf1.u(64, 6)?).ok()?,
        validity_s: if fit_flag == 0 {
            VALIDITY_NORMAL_S
        } else {
            VALIDITY_EXTENDED_S
        },
    })
}

/// Klobuchar coefficients from subframe 4 page 18; None for any other page.
pub fn decode_lnav_klobuchar(sf4: &Bits) -> Option<Klobuchar> {
    if sf4.u(50, 6)? != IONO_UTC_PAGE_ID {
        return None;
    }
    let f = |pos: usize, exp: i32| sf4.s(pos, 8).map(|v| v as f64 * pow2(exp));
    Some(Klobuchar {
        alpha: [f(56, -30)?, f(64, -27)?, f(72, -24)?, f(80, -24)?],
        beta: [f(88, 11)?, f(96, 14)?, f(104, 16)?, f(112, 16)?],
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::gnss::Constellation;

    const G01: SatId = SatId {
        constellation: Constellation::Gps,
        prn: 1,
    };

    /// Encodes 24 data bits into a u-blox word with correct parity given D29*, D30*.
    fn encode(d: u32, d29: u32, d30: u32) -> u32 {
        let tx = if d30 == 1 { !d & 0xFF_FFFF } else { d };
        let mut w = (d29 << 31) | (d30 << 30) | (tx << 6);
        for (bit, &(uses_d29, mask)) in PARITY.iter().enumerate() {
            let star = if uses_d29 { d29 } else { d30 };
            w |= (star ^ ((d & mask).count_ones() & 1)) << (5 - bit);
        }
        w
    }

    /// The u-blox words of a subframe of ten 24-bit data words, parity chained.
    pub(crate) fn lnav_words(data: [u32; LNAV_WORDS]) -> Vec<u32> {
        let (mut d29, mut d30) = (0, 0);
        data.iter()
            .map(|&d| {
                let w = encode(d, d29, d30);
                d29 = (w >> 1) & 1;
                d30 = w & 1;
                w
            })
            .collect()
    }

    #[test]
    fn parity_accepts_encoded_words_and_rejects_a_flipped_bit() {
        let mut words = lnav_words(std::array::from_fn(|k| match k {
            0 => 0x8B0000,
            1 => 2 << 2,
            _ => 0x5A5A5A ^ k as u32,
        }));
        let sf = lnav_subframe(G01, &words).unwrap();
        assert_eq!(sf.id, 2);
        assert_eq!(sf.data.u(24 * 4, 24), Some(u64::from(0x5A5A5A ^ 4u32)));
        words[3] ^= 1 << 17;
        assert_eq!(
            lnav_subframe(G01, &words),
            Err(NavDataError::Parity { sat: G01, word: 3 })
        );
        assert!(matches!(
            lnav_subframe(G01, &words[..9]),
            Err(NavDataError::WordCount { .. })
        ));
    }

    /// Subframe data bits with the HOW TOW count and the given (position, length,
    /// value) fields set, the rest zero.
    fn subframe(tow_count: u64, fields: &[(usize, usize, u64)]) -> Bits {
        let mut bits = [0u8; 240];
        for &(pos, len, value) in [(24, 17, tow_count)].iter().chain(fields) {
            for k in 0..len {
                bits[pos + k] = ((value >> (len - 1 - k)) & 1) as u8;
            }
        }
        let mut data = Bits::new();
        for b in bits {
            data.push(u64::from(b), 1);
        }
        data
    }

    #[test]
    fn clock_and_orbit_of_different_issues_within_one_frame_are_an_error() {
        let t = GpsTime::new(2381, 408_000.0);
        let decode = |tows: [u64; 3], iodc: u64, iode: u64| {
            let sf1 = subframe(tows[0], &[(70, 2, iodc >> 8), (168, 8, iodc & 0xFF)]);
            let sf2 = subframe(tows[1], &[(48, 8, iode)]);
            let sf3 = subframe(tows[2], &[(216, 8, iode)]);
            decode_lnav_ephemeris(G01, NavSource::GpsLnav, &sf1, &sf2, &sf3, &t)
        };
        let eph = decode([100, 101, 102], 0x1A7, 0xA7).unwrap().unwrap();
        assert_eq!(eph.issue_of_data, 0xA7);
        assert_eq!(
            decode([100, 101, 102], 0x1A6, 0xA7),
            Err(NavDataError::IssueMismatch { sat: G01 })
        );
        // Subframe 1 of the next frame, with the next upload: waiting for 2 and 3.
        assert_eq!(decode([105, 101, 102], 0x1A6, 0xA7), Ok(None));
    }
}
