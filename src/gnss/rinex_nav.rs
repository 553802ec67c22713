//! A small RINEX 3 navigation-file reader (text in, ephemerides out): GPS, QZSS, Galileo
//! and BeiDou Keplerian records, and the GPS Klobuchar coefficients of the header
//! (`IONOSPHERIC CORR` GPSA/GPSB). GLONASS, SBAS, NavIC records are skipped and counted.
//!
//! Layout (RINEX 3.04, Table A6 ff.): a record's first line holds the satellite, the
//! clock epoch (toc) and a_f0, a_f1, a_f2; seven "broadcast orbit" lines follow with four
//! D19.12 fields each from column 5. BeiDou epochs are in BDT; Galileo weeks are
//! continuous with GPS weeks.

use thiserror::Error;

use crate::gnss::ephemeris::{GpsTime, GroupDelay, KeplerianEphemeris, NavSource};
use crate::gnss::{Constellation, Klobuchar, SatId};

/// Broadcast-orbit lines after the first line of a Keplerian record.
const ORBIT_LINES: usize = 7;
/// Broadcast-orbit lines of GLONASS/SBAS records (skipped).
const SHORT_RECORD_LINES: usize = 3;
/// Width of one numeric field.
const FIELD_WIDTH: usize = 19;
/// Days from 0000-03-01 (proleptic Gregorian) to 1980-01-06, in [`days_from_civil`]'s
/// count.
pub(crate) const GPS_EPOCH_DAYS: i64 = 723_125;

/// Errors of the RINEX navigation reader, with the 1-based line number.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum RinexNavError {
    /// No `END OF HEADER` line.
    #[error("no END OF HEADER line")]
    NoHeaderEnd,
    /// A field that should be a number is not.
    #[error("line {line}: cannot read {what}")]
    BadField { line: usize, what: &'static str },
    /// The file ends inside a record.
    #[error("line {line}: record truncated")]
    Truncated { line: usize },
}

/// Contents of a RINEX navigation file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RinexNav {
    /// Keplerian ephemerides (GPS, QZSS, Galileo, BeiDou).
    pub ephemerides: Vec<KeplerianEphemeris>,
    /// GPS Klobuchar coefficients from the header, if both GPSA and GPSB are present.
    pub klobuchar: Option<Klobuchar>,
    /// Records of other systems that were skipped.
    pub skipped_records: usize,
}

/// Parses the text of a RINEX 3 navigation file.
pub fn parse_rinex_nav(text: &str) -> Result<RinexNav, RinexNavError> {
    let lines: Vec<&str> = text.lines().collect();
    let header_end = lines
        .iter()
        .position(|l| l.get(60..).is_some_and(|s| s.trim_end() == "END OF HEADER"))
        .ok_or(RinexNavError::NoHeaderEnd)?;
    let mut nav = RinexNav {
        klobuchar: header_klobuchar(lines.get(..header_end).unwrap_or(&[])),
        ..RinexNav::default()
    };
    let mut i = header_end + 1;
    while let Some(line) = lines.get(i) {
        if line.trim().is_empty() {
            i += 1;
            continue;
        }
        let system = line.chars().next().unwrap_or(' ');
        let constellation = match system {
            'G' => Some(Constellation::Gps),
            'J' => Some(Constellation::Qzss),
            'E' => Some(Constellation::Galileo),
            'C' => Some(Constellation::Beidou),
            _ => None,
        };
        let Some(constellation) = constellation else {
            let extra = if matches!(system, 'R' | 'S') {
                SHORT_RECORD_LINES
            } else {
                ORBIT_LINES
            };
            nav.skipped_records += 1;
            i += 1 + extra;
            continue;
        };
        let record = lines
            .get(i..i + 1 + ORBIT_LINES)
            .ok_or(RinexNavError::Truncated { line: i + 1 })?;
        nav.ephemerides
            .push(parse_record(constellation, record, i + 1)?);
        i += 1 + ORBIT_LINES;
    }
    Ok(nav)
}

/// A numeric field in RINEX notation ('D' or 'E' exponent).
fn number(
    line: &str,
    start: usize,
    line_no: usize,
    what: &'static str,
) -> Result<f64, RinexNavError> {
    let bad = RinexNavError::BadField {
        line: line_no,
        what,
    };
    let end = (start + FIELD_WIDTH).min(line.len());
    let field = line.get(start..end).ok_or(bad.clone())?;
    field
        .trim()
        .replace(['D', 'd'], "E")
        .parse::<f64>()
        .map_err(|_| bad)
}

/// The four fields of broadcast-orbit line `k` (1–7) of a record.
fn orbit(record: &[&str], k: usize, first_line: usize) -> Result<[f64; 4], RinexNavError> {
    let line_no = first_line + k;
    let line = record
        .get(k)
        .ok_or(RinexNavError::Truncated { line: line_no })?;
    let mut out = [0.0; 4];
    for (j, v) in out.iter_mut().enumerate() {
        // Trailing fields may be blank (spares): read as zero.
        let start = 4 + FIELD_WIDTH * j;
        *v = match line.get(start..).map(str::trim) {
            None | Some("") => 0.0,
            Some(_) => number(line, start, line_no, "broadcast orbit field")?,
        };
    }
    Ok(out)
}

fn parse_record(
    constellation: Constellation,
    record: &[&str],
    line_no: usize,
) -> Result<KeplerianEphemeris, RinexNavError> {
    let first = record
        .first()
        .ok_or(RinexNavError::Truncated { line: line_no })?;
    let bad = |what| RinexNavError::BadField {
        line: line_no,
        what,
    };
    let prn: u16 = first
        .get(1..3)
        .and_then(|s| s.trim().parse().ok())
        .ok_or(bad("satellite number"))?;
    let int = |a: usize, b: usize, what| -> Result<i64, RinexNavError> {
        first
            .get(a..b)
            .and_then(|s| s.trim().parse().ok())
            .ok_or(bad(what))
    };
    let (year, month, day) = (
        int(4, 8, "year")?,
        int(9, 11, "month")?,
        int(12, 14, "day")?,
    );
    let (hour, minute, second) = (
        int(15, 17, "hour")?,
        int(18, 20, "minute")?,
        int(21, 23, "second")?,
    );
    let af0_s = number(first, 23, line_no, "a_f0")?;
    let af1_s_s = number(first, 42, line_no, "a_f1")?;
    let af2_s_s2 = number(first, 61, line_no, "a_f2")?;
    let days = days_from_civil(year, month, day) - GPS_EPOCH_DAYS;
    let week = i32::try_from(days.div_euclid(7)).map_err(|_| bad("epoch"))?;
    let sow = (days.rem_euclid(7) * 86_400 + hour * 3_600 + minute * 60 + second) as f64;

    let o1 = orbit(record, 1, line_no)?;
    let o2 = orbit(record, 2, line_no)?;
    let o3 = orbit(record, 3, line_no)?;
    let o4 = orbit(record, 4, line_no)?;
    let o5 = orbit(record, 5, line_no)?;
    let o6 = orbit(record, 6, line_no)?;
    let o7 = orbit(record, 7, line_no)?;
    let [issue, crs_m, delta_n, m0] = o1;
    let [cuc_rad, eccentricity, cus_rad, sqrt_a] = o2;
    let [toe_sow, cic_rad, raan_rad, cis_rad] = o3;
    let [i0, crc_m, arg_perigee_rad, raan_rate] = o4;
    let [i_dot, data_sources, eph_week, _] = o5;
    let [_, health, gd1, gd2] = o6;
    let eph_week = eph_week as i32;
    let (source, toc, toe, group_delay, validity_s) = match constellation {
        Constellation::Beidou => (
            // Choice: PRN 1–5 and 59–63 are GEOs broadcasting D2.
            if matches!(prn, 1..=5 | 59..=63) {
                NavSource::BeidouD2
            } else {
                NavSource::BeidouD1
            },
            GpsTime::from_bdt(
                week.saturating_sub(crate::gnss::ephemeris::BDT_WEEK_OFFSET),
                sow,
            ),
            GpsTime::from_bdt(eph_week, toe_sow),
            GroupDelay::Beidou {
                tgd1_s: gd1,
                tgd2_s: gd2,
            },
            3_600.0,
        ),
        Constellation::Galileo => {
            // Data-source bit 1: F/NAV E5a-I.
            let fnav = (data_sources as u32) & 0b10 != 0;
            (
                if fnav {
                    NavSource::GalileoFnav
                } else {
                    NavSource::GalileoInav
                },
                GpsTime::new(week, sow),
                GpsTime::new(eph_week, toe_sow),
                GroupDelay::Galileo {
                    bgd_e1_e5a_s: gd1,
                    bgd_e1_e5b_s: (!fnav).then_some(gd2),
                },
                14_400.0,
            )
        }
        _ => {
            let fit_h = o7[1];
            (
                if constellation == Constellation::Qzss {
                    NavSource::QzssLnav
                } else {
                    NavSource::GpsLnav
                },
                GpsTime::new(week, sow),
                GpsTime::new(eph_week, toe_sow),
                GroupDelay::Gps { tgd_s: gd1 },
                if fit_h > 4.0 { 14_400.0 } else { 7_200.0 },
            )
        }
    };
    Ok(KeplerianEphemeris {
        sat: SatId { constellation, prn },
        source,
        toe,
        toc,
        sqrt_a_sqrt_m: sqrt_a,
        eccentricity,
        inclination_rad: i0,
        inclination_rate_rad_s: i_dot,
        raan_rad,
        raan_rate_rad_s: raan_rate,
        arg_perigee_rad,
        mean_anomaly_rad: m0,
        mean_motion_diff_rad_s: delta_n,
        cuc_rad,
        cus_rad,
        crc_m,
        crs_m,
        cic_rad,
        cis_rad,
        af0_s,
        af1_s_s,
        af2_s_s2,
        group_delay,
        issue_of_data: issue as u16,
        health: health as u16,
        validity_s,
    })
}

/// GPSA/GPSB `IONOSPHERIC CORR` header lines → Klobuchar.
fn header_klobuchar(header: &[&str]) -> Option<Klobuchar> {
    let coefficients = |tag: &str| -> Option<[f64; 4]> {
        let line = header.iter().find(|l| {
            l.starts_with(tag)
                && l.get(60..)
                    .is_some_and(|s| s.starts_with("IONOSPHERIC CORR"))
        })?;
        let mut out = [0.0; 4];
        for (j, v) in out.iter_mut().enumerate() {
            let start = 5 + 12 * j;
            *v = line
                .get(start..start + 12)?
                .trim()
                .replace(['D', 'd'], "E")
                .parse()
                .ok()?;
        }
        Some(out)
    };
    Some(Klobuchar {
        alpha: coefficients("GPSA")?,
        beta: coefficients("GPSB")?,
    })
}

/// Days since 0000-03-01 of a proleptic Gregorian date (H. Hinnant's civil-days
/// algorithm, re-derived: years start in March so the leap day is last).
pub(crate) fn days_from_civil(year: i64, month: i64, day: i64) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (month + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_days_put_the_gps_epoch_at_week_zero() {
        assert_eq!(days_from_civil(1980, 1, 6), GPS_EPOCH_DAYS);
        // 2025-08-28 is a Thursday of GPS week 2381 (day 4).
        let d = days_from_civil(2025, 8, 28) - GPS_EPOCH_DAYS;
        assert_eq!((d / 7, d % 7), (2381, 4));
    }

    #[test]
    fn missing_header_and_truncated_record_are_errors() {
        assert_eq!(
            parse_rinex_nav("garbage\n"),
            Err(RinexNavError::NoHeaderEnd)
        );
        let text = format!(
            "{:60}END OF HEADER\nG01 2025 08 28 18 00 00 1.0D-03 0.0D+00 0.0D+00\n",
            ""
        );
        assert!(matches!(
            parse_rinex_nav(&text),
            Err(RinexNavError::Truncated { .. })
        ));
    }
}
