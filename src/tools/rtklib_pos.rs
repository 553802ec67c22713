//! RTKLIB solution files (`.pos`), pure parsing: time (calendar "YYYY/MM/DD HH:MM:SS.sss"
//! or "week tow", in the file's time scale, GPST here), latitude and longitude in degrees,
//! height, quality Q, satellites, σ north/east/up and their covariances, age, ratio, then
//! optionally the velocity north/east/up and its σ.
//!
//! Heights are what RTKLIB wrote: ellipsoidal, or above mean sea level when it was asked
//! for geodetic heights; the caller adds the geoid separation. Lines that are not a
//! solution are skipped and counted; lines starting with `%` are the header.

use std::collections::BTreeMap;

use nalgebra::Vector3;

use crate::gnss::time_scale::{gpst_of_week_tow, seconds_of_calendar};

/// RTKLIB's quality flag Q.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum PosQuality {
    /// 1: RTK with the integer ambiguities fixed.
    Fixed,
    /// 2: RTK float.
    Float,
    /// Anything else (3 SBAS, 4 DGPS, 5 single, 6 PPP, 7 dead reckoning).
    Other(u8),
}

impl PosQuality {
    fn of_code(q: u8) -> Self {
        match q {
            1 => Self::Fixed,
            2 => Self::Float,
            other => Self::Other(other),
        }
    }

    /// A label for reports: `rtk_fixed`, `rtk_float`, `q<N>`.
    pub fn label(self) -> String {
        match self {
            Self::Fixed => "rtk_fixed".to_owned(),
            Self::Float => "rtk_float".to_owned(),
            Self::Other(q) => format!("q{q}"),
        }
    }
}

/// One solution line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosRecord {
    /// Seconds since 1970 in the file's time scale (GPST: GPS scale, no leap seconds).
    pub time_s: f64,
    pub lat_deg: f64,
    pub lon_deg: f64,
    /// Height as written (see the module documentation).
    pub height_m: f64,
    pub quality: PosQuality,
    /// σ east, north, up (m).
    pub sigma_enu_m: Vector3<f64>,
    /// Velocity east, north, up (m/s), when the file has it.
    pub velocity_enu_mps: Option<Vector3<f64>>,
}

/// The solutions of a file and what was skipped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PosFile {
    pub records: Vec<PosRecord>,
    /// Skipped lines by reason.
    pub skipped: BTreeMap<&'static str, usize>,
}

/// Parses the text of a `.pos` file.
pub fn parse_pos(text: &str) -> PosFile {
    let mut out = PosFile::default();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('%') {
            continue;
        }
        match parse_line(line) {
            Ok(r) => out.records.push(r),
            Err(reason) => *out.skipped.entry(reason).or_insert(0) += 1,
        }
    }
    out
}

fn parse_line(line: &str) -> Result<PosRecord, &'static str> {
    let fields: Vec<&str> = line.split_whitespace().collect();
    if fields.len() < 10 {
        return Err("too few fields");
    }
    let time_s = if fields[0].contains('/') {
        calendar(fields[0], fields[1]).ok_or("bad date or time")?
    } else {
        let week: i32 = fields[0].parse().map_err(|_| "bad GPS week")?;
        let tow: f64 = fields[1].parse().map_err(|_| "bad time of week")?;
        gpst_of_week_tow(week, tow)
    };
    let num = |i: usize| -> Result<f64, &'static str> {
        let v: f64 = fields[i].parse().map_err(|_| "not a number")?;
        v.is_finite().then_some(v).ok_or("not finite")
    };
    let q = num(5)?;
    if !(0.0..=255.0).contains(&q) || q.fract() != 0.0 {
        return Err("bad quality flag");
    }
    // Columns: 0-1 time, 2 lat, 3 lon, 4 height, 5 Q, 6 ns, 7 sdn, 8 sde, 9 sdu,
    // 10-12 sdne sdeu sdun, 13 age, 14 ratio, 15-17 vn ve vu.
    let velocity_enu_mps = if fields.len() >= 18 {
        Some(Vector3::new(num(16)?, num(15)?, num(17)?))
    } else {
        None
    };
    let (lat_deg, lon_deg) = (num(2)?, num(3)?);
    if lat_deg.abs() > 90.0 || lon_deg.abs() > 360.0 {
        return Err("latitude or longitude out of range");
    }
    Ok(PosRecord {
        time_s,
        lat_deg,
        lon_deg,
        height_m: num(4)?,
        quality: PosQuality::of_code(q as u8),
        sigma_enu_m: Vector3::new(num(8)?, num(7)?, num(9)?),
        velocity_enu_mps,
    })
}

fn calendar(date: &str, time: &str) -> Option<f64> {
    let d: Vec<&str> = date.split('/').collect();
    let t: Vec<&str> = time.split(':').collect();
    if d.len() != 3 || t.len() != 3 {
        return None;
    }
    seconds_of_calendar(
        d[0].parse().ok()?,
        d[1].parse().ok()?,
        d[2].parse().ok()?,
        t[0].parse().ok()?,
        t[1].parse().ok()?,
        t[2].parse().ok()?,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_calendar_and_week_lines_and_counts_bad_ones() {
        let text = "% header\n\
            2025/08/28 17:30:39.749 40.0966916 -105.1471665 1601.4350000 1.0000000 25.0000000 0.0098995 0.0098995 0.0100000 0.0 0.0 0.0 0.0 0.0 0.0010000 -0.0020000 0.0270000 0.05 0.05 0.05 0 0 0\n\
            2381 408639.999 40.0966916 -105.1471665 1601.4 2 25 0.02 0.03 0.04\n\
            2025/08/28 17:30:40.249 40.0 -105.0\n\
            2025/13/28 17:30:40.249 40.0966916 -105.1471665 1601.4 2 25 0.02 0.03 0.04\n";
        let pos = parse_pos(text);
        assert_eq!(pos.records.len(), 2);
        assert_eq!(pos.skipped.get("too few fields"), Some(&1));
        assert_eq!(pos.skipped.get("bad date or time"), Some(&1));
        let a = &pos.records[0];
        assert_eq!(a.quality, PosQuality::Fixed);
        assert_eq!(a.velocity_enu_mps, Some(Vector3::new(-0.002, 0.001, 0.027)));
        assert_eq!(a.sigma_enu_m[2], 0.01);
        let b = &pos.records[1];
        assert_eq!(b.quality.label(), "rtk_float");
        assert_eq!(b.velocity_enu_mps, None);
        assert!((b.time_s - a.time_s - 0.25).abs() < 1e-6);
    }
}
