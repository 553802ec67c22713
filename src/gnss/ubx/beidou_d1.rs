//! BeiDou D1 navigation message (MEO/IGSO): the ephemeris of subframes 1–3 of one frame
//! (BDS-SIS-ICD B1I 5.2.4), field positions in the parity-free bits of
//! [`super::beidou_subframe`].

use super::beidou_subframe::{from_bdt_sow, BdsSubframe, BDS_VALIDITY_S};
use super::bits::{pow2, Bits};
use super::nav_error::NavDataError;
use crate::gnss::ephemeris::{GpsTime, GroupDelay, KeplerianEphemeris, NavSource};
use crate::gnss::SatId;

/// Ephemeris from D1 subframes 1, 2, 3 of one frame (seconds of week t, t+6, t+12);
/// None while they are of different frames. `reference` (GPST within days) resolves the
/// week.
///
/// Errors: [`NavDataError::IssueMismatch`] when, within one frame, the clock's toc
/// (subframe 1) differs from the orbit's toe (subframes 2–3), which BDS broadcasts
/// equal; [`NavDataError::MissingField`] when a field lies beyond the bits.
pub fn decode_d1_ephemeris(
    sat: SatId,
    sf1: &BdsSubframe,
    sf2: &BdsSubframe,
    sf3: &BdsSubframe,
    reference: &GpsTime,
) -> Result<Option<KeplerianEphemeris>, NavDataError> {
    let missing = NavDataError::MissingField { sat };
    let (d1, d2, d3) = (&sf1.data, &sf2.data, &sf3.data);
    // toe: 2 MSBs at the end of subframe 2, 15 LSBs at the start of subframe 3.
    let toe_code =
        (d2.u(222, 2).ok_or(missing.clone())? << 15) | d3.u(38, 15).ok_or(missing.clone())?;
    let toc_code = d1.u(61, 17).ok_or(missing.clone())?;
    let same_frame = (sf1.id, sf2.id, sf3.id) == (1, 2, 3)
        && sf2.sow_s.checked_sub(sf1.sow_s) == Some(6)
        && sf3.sow_s.checked_sub(sf1.sow_s) == Some(12);
    if !same_frame {
        return Ok(None);
    }
    if toe_code != toc_code {
        return Err(NavDataError::IssueMismatch { sat });
    }
    elements(sat, d1, d2, d3, toe_code as f64 * 8.0, reference)
        .map(Some)
        .ok_or(missing)
}

/// The elements of subframes 1–3 with toe = toc = `toe_sow` (BDT seconds of week).
fn elements(
    sat: SatId,
    d1: &Bits,
    d2: &Bits,
    d3: &Bits,
    toe_sow: f64,
    reference: &GpsTime,
) -> Option<KeplerianEphemeris> {
    let sc = std::f64::consts::PI;
    let f = |v: Option<i64>, scale: f64| v.map(|x| x as f64 * scale);
    let g = |v: Option<u64>, scale: f64| v.map(|x| x as f64 * scale);
    Some(KeplerianEphemeris {
        sat,
        source: NavSource::BeidouD1,
        toe: from_bdt_sow(toe_sow, reference),
        toc: from_bdt_sow(toe_sow, reference),
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
        validity_s: BDS_VALIDITY_S,
    })
}
