//! BeiDou D2 navigation message (GEO): the ephemeris of subframe 1, pages 1 and 3–10 of
//! one 30-s page cycle (BDS-SIS-ICD B1I 5.3.3; page 2 holds the ionosphere, not used),
//! field positions in the parity-free bits of [`super::beidou_subframe`]. Fields split
//! across pages are joined, most significant part first.
//!
//! Not checked on real data: the walk_0827 recording (Colorado) sees no BeiDou GEO. The
//! positions follow the ICD page layouts through the bit mapping of
//! [`super::beidou_subframe`], which the D1 decoder's real-data test confirms.

use super::beidou_subframe::{from_bdt_sow, BdsSubframe, BDS_VALIDITY_S};
use super::bits::pow2;
use super::nav_error::NavDataError;
use crate::gnss::ephemeris::{GpsTime, GroupDelay, KeplerianEphemeris, NavSource};
use crate::gnss::SatId;

/// Pages of D2 subframe 1.
const D2_PAGES: u8 = 10;
/// The pages of subframe 1 that carry the ephemeris (page 2 holds the ionosphere).
pub const D2_EPHEMERIS_PAGES: [u8; 9] = [1, 3, 4, 5, 6, 7, 8, 9, 10];
/// Seconds between two pages of subframe 1 (one D2 frame).
const PAGE_PERIOD_S: u32 = 3;

/// The page number (1–10) of a D2 subframe 1, None for other subframes.
pub fn d2_page(sf: &BdsSubframe) -> Option<u8> {
    if sf.id != 1 {
        return None;
    }
    sf.data
        .u(38, 4)
        .and_then(|p| u8::try_from(p).ok())
        .filter(|p| (1..=D2_PAGES).contains(p))
}

/// `(msb << lsb_len) | lsb` for a field whose signed upper part and unsigned lower part
/// are on different pages.
fn join_signed(msb: i64, lsb: u64, lsb_len: u32) -> i64 {
    (msb << lsb_len) | lsb as i64
}

/// Ephemeris from the D2 subframe-1 pages of [`D2_EPHEMERIS_PAGES`], in that order, of
/// one cycle (page numbers, seconds of week 3 s apart); None while they are not.
/// `reference` (GPST within days) resolves the week.
///
/// Errors: [`NavDataError::IssueMismatch`] when, within one cycle, toc (page 1) differs
/// from toe (page 7); [`NavDataError::MissingField`] when a field lies beyond the bits.
pub fn decode_d2_ephemeris(
    sat: SatId,
    pages: [&BdsSubframe; 9],
    reference: &GpsTime,
) -> Result<Option<KeplerianEphemeris>, NavDataError> {
    let missing = NavDataError::MissingField { sat };
    let sow1 = pages[0].sow_s;
    let one_cycle = pages.iter().zip(D2_EPHEMERIS_PAGES).all(|(p, number)| {
        let offset_s = PAGE_PERIOD_S * u32::from(number - 1);
        d2_page(p) == Some(number) && p.sow_s.checked_sub(sow1) == Some(offset_s)
    });
    let toc_code = pages[0].data.u(65, 17).ok_or(missing.clone())?;
    let toe_code = pages[5].data.u(68, 17).ok_or(missing.clone())?;
    if !one_cycle {
        return Ok(None);
    }
    if toc_code != toe_code {
        return Err(NavDataError::IssueMismatch { sat });
    }
    elements(sat, pages, toe_code as f64 * 8.0, reference)
        .map(Some)
        .ok_or(missing)
}

/// The elements of a page cycle with toe = toc = `toe_sow` (BDT seconds of week).
fn elements(
    sat: SatId,
    pages: [&BdsSubframe; 9],
    toe_sow: f64,
    reference: &GpsTime,
) -> Option<KeplerianEphemeris> {
    let sc = std::f64::consts::PI;
    let [p1, p3, p4, p5, p6, p7, p8, p9, p10] = pages.map(|p| &p.data);
    let a1 = join_signed(p3.s(104, 4)?, p4.u(42, 18)?, 18);
    let cuc = join_signed(p4.s(92, 14)?, p5.u(42, 4)?, 4);
    let e = (p5.u(96, 10)? << 22) | p6.u(42, 22)?;
    let cic = join_signed(p6.s(96, 10)?, p7.u(42, 8)?, 8);
    let i0 = join_signed(p7.s(85, 21)?, p8.u(42, 11)?, 11);
    let raan_rate = join_signed(p8.s(89, 19)?, p9.u(42, 5)?, 5);
    let omega = join_signed(p9.s(79, 27)?, p10.u(42, 5)?, 5);
    let f = |v: i64, scale: f64| v as f64 * scale;
    Some(KeplerianEphemeris {
        sat,
        source: NavSource::BeidouD2,
        toe: from_bdt_sow(toe_sow, reference),
        toc: from_bdt_sow(toe_sow, reference),
        sqrt_a_sqrt_m: p6.u(64, 32)? as f64 * pow2(-19),
        eccentricity: e as f64 * pow2(-33),
        inclination_rad: f(i0, pow2(-31) * sc),
        inclination_rate_rad_s: f(p10.s(47, 14)?, pow2(-43) * sc),
        raan_rad: f(p9.s(47, 32)?, pow2(-31) * sc),
        raan_rate_rad_s: f(raan_rate, pow2(-43) * sc),
        arg_perigee_rad: f(omega, pow2(-31) * sc),
        mean_anomaly_rad: f(p5.s(46, 32)?, pow2(-31) * sc),
        mean_motion_diff_rad_s: f(p4.s(76, 16)?, pow2(-43) * sc),
        cuc_rad: f(cuc, pow2(-31)),
        cus_rad: f(p5.s(78, 18)?, pow2(-31)),
        crc_m: f(p8.s(53, 18)?, pow2(-6)),
        crs_m: f(p8.s(71, 18)?, pow2(-6)),
        cic_rad: f(cic, pow2(-31)),
        cis_rad: f(p7.s(50, 18)?, pow2(-31)),
        af0_s: f(p3.s(80, 24)?, pow2(-33)),
        af1_s_s: f(a1, pow2(-50)),
        af2_s_s2: f(p4.s(60, 11)?, pow2(-66)),
        group_delay: GroupDelay::Beidou {
            tgd1_s: f(p1.s(82, 10)?, 1e-10),
            tgd2_s: f(p1.s(92, 10)?, 1e-10),
        },
        issue_of_data: u16::try_from(p4.u(71, 5)?).ok()?,
        health: u16::try_from(p1.u(42, 1)?).ok()?,
        validity_s: BDS_VALIDITY_S,
    })
}

#[cfg(test)]
mod tests {
    use super::super::bits::Bits;
    use super::*;
    use crate::gnss::Constellation;

    const C03: SatId = SatId {
        constellation: Constellation::Beidou,
        prn: 3,
    };

    /// Subframe 1, page `number`, at BDT second `sow`, with the fields (position, length,
    /// two's-complement value) set in its 224 information bits.
    fn page(number: u8, sow: u32, fields: &[(usize, usize, i64)]) -> BdsSubframe {
        let mut bits = [0u8; 224];
        let mut put = |pos: usize, len: usize, value: i64| {
            for k in 0..len {
                bits[pos + k] = ((value >> (len - 1 - k)) & 1) as u8;
            }
        };
        put(15, 3, 1);
        put(18, 20, i64::from(sow));
        put(38, 4, i64::from(number));
        for &(pos, len, value) in fields {
            put(pos, len, value);
        }
        let mut data = Bits::new();
        for b in bits {
            data.push(u64::from(b), 1);
        }
        BdsSubframe {
            id: 1,
            sow_s: sow,
            data,
        }
    }

    /// The nine pages of one cycle starting at `sow1`, fields split across pages.
    fn cycle(sow1: u32, toe_code: i64, toc_code: i64) -> Vec<BdsSubframe> {
        let (a1, cuc, e, cic) = (-123_456i64, -70_000i64, 0x0001_2345i64, -1_234i64);
        let (i0, raan_rate, omega) = (-1_234_567_890i64, -5_000_000i64, 987_654_321i64);
        let at = |n: u32| sow1 + 3 * (n - 1);
        vec![
            page(
                1,
                sow1,
                &[(42, 1, 0), (65, 17, toc_code), (82, 10, -7), (92, 10, 12)],
            ),
            page(3, at(3), &[(80, 24, -4_000_000), (104, 4, a1 >> 18)]),
            page(
                4,
                at(4),
                &[
                    (42, 18, a1),
                    (60, 11, -3),
                    (71, 5, 21),
                    (76, 16, 9_000),
                    (92, 14, cuc >> 4),
                ],
            ),
            page(
                5,
                at(5),
                &[
                    (42, 4, cuc),
                    (46, 32, 300_000_000),
                    (78, 18, 4_321),
                    (96, 10, e >> 22),
                ],
            ),
            page(
                6,
                at(6),
                &[(42, 22, e), (64, 32, 3_404_391_219), (96, 10, cic >> 8)],
            ),
            page(
                7,
                at(7),
                &[
                    (42, 8, cic),
                    (50, 18, -999),
                    (68, 17, toe_code),
                    (85, 21, i0 >> 11),
                ],
            ),
            page(
                8,
                at(8),
                &[
                    (42, 11, i0),
                    (53, 18, -50_000),
                    (71, 18, 60_000),
                    (89, 19, raan_rate >> 5),
                ],
            ),
            page(
                9,
                at(9),
                &[
                    (42, 5, raan_rate),
                    (47, 32, -2_000_000_000),
                    (79, 27, omega >> 5),
                ],
            ),
            page(10, at(10), &[(42, 5, omega), (47, 14, -100)]),
        ]
    }

    fn decode(pages: &[BdsSubframe]) -> Result<Option<KeplerianEphemeris>, NavDataError> {
        let refs: [&BdsSubframe; 9] = std::array::from_fn(|k| &pages[k]);
        decode_d2_ephemeris(C03, refs, &GpsTime::new(2381, 408_000.0))
    }

    #[test]
    fn fields_split_across_pages_are_joined_with_their_signs() {
        let toe_code = 50_850; // 406 800 s of BDT week
        let eph = decode(&cycle(406_000, toe_code, toe_code))
            .unwrap()
            .unwrap();
        let sc = std::f64::consts::PI;
        assert_eq!(eph.source, NavSource::BeidouD2);
        assert_eq!(eph.af1_s_s, -123_456.0 * pow2(-50));
        assert_eq!(eph.cuc_rad, -70_000.0 * pow2(-31));
        assert_eq!(eph.eccentricity, f64::from(0x0001_2345) * pow2(-33));
        assert_eq!(eph.cic_rad, -1_234.0 * pow2(-31));
        assert_eq!(eph.inclination_rad, -1_234_567_890.0 * pow2(-31) * sc);
        assert_eq!(eph.raan_rate_rad_s, -5_000_000.0 * pow2(-43) * sc);
        assert_eq!(eph.arg_perigee_rad, 987_654_321.0 * pow2(-31) * sc);
        assert_eq!(eph.sqrt_a_sqrt_m, 3_404_391_219.0 * pow2(-19));
        assert_eq!(eph.af0_s, -4_000_000.0 * pow2(-33));
        assert_eq!(eph.af2_s_s2, -3.0 * pow2(-66));
        assert_eq!(eph.raan_rad, -2_000_000_000.0 * pow2(-31) * sc);
        assert_eq!(eph.inclination_rate_rad_s, -100.0 * pow2(-43) * sc);
        assert_eq!(eph.issue_of_data, 21);
        assert_eq!(eph.health, 0);
        assert_eq!(
            eph.group_delay,
            GroupDelay::Beidou {
                tgd1_s: -7.0 * 1e-10,
                tgd2_s: 12.0 * 1e-10
            }
        );
        // BDT 406 800 s = GPST 406 814 s.
        assert_eq!((eph.toe.week, eph.toe.tow_s), (2381, 406_814.0));
        assert!(eph.is_valid());
    }

    #[test]
    fn pages_of_different_cycles_or_issues_do_not_form_an_ephemeris() {
        let mismatch = Err(NavDataError::IssueMismatch { sat: C03 });
        assert_eq!(
            decode(&cycle(406_000, 50_850, 50_851)),
            mismatch,
            "toc ≠ toe"
        );
        let mut pages = cycle(406_000, 50_850, 50_850);
        pages[4] = cycle(406_030, 50_850, 50_850)[4].clone();
        assert_eq!(
            decode(&pages),
            Ok(None),
            "a page of the next cycle: waiting"
        );
        let mut pages = cycle(406_000, 50_850, 50_850);
        pages.swap(2, 3);
        assert_eq!(decode(&pages), Ok(None), "pages out of order: waiting");
    }
}
