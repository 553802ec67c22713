//! GPS time (GPST) and the UTC stamps of ROS.
//!
//! Time values here are seconds since 1970-01-01 00:00:00 counted in a given scale:
//! "GPST seconds" count GPS time (no leap seconds; the form RTKLIB's time-tag files use),
//! ROS stamps count UTC (UNIX time). Between them lie the GPS − UTC leap seconds, 18 s
//! since 2017-01-01 (the next change, if any, is announced six months ahead in IERS
//! Bulletin C; the GPS navigation message carries it too).

/// GPS − UTC in 2017..2025 (s): the default of the `--leap-seconds` arguments.
pub const DEFAULT_GPS_UTC_LEAP_S: f64 = 18.0;

/// GPS epoch 1980-01-06 00:00:00 in seconds since 1970-01-01 (both in the GPS scale).
pub const GPS_EPOCH_SINCE_1970_S: f64 = 315_964_800.0;

/// Seconds in a GPS week.
pub const SECONDS_PER_WEEK: f64 = 604_800.0;

/// GPST seconds since 1970 of GPS week `week` and time of week `tow_s`.
pub fn gpst_of_week_tow(week: i32, tow_s: f64) -> f64 {
    GPS_EPOCH_SINCE_1970_S + f64::from(week) * SECONDS_PER_WEEK + tow_s
}

/// GPS week and time of week of GPST seconds since 1970 (None before the GPS epoch or
/// when not finite).
pub fn week_tow_of_gpst(gpst_s: f64) -> Option<(u16, f64)> {
    let since = gpst_s - GPS_EPOCH_SINCE_1970_S;
    if !since.is_finite() || since < 0.0 {
        return None;
    }
    let week = (since / SECONDS_PER_WEEK).floor();
    let tow = since - week * SECONDS_PER_WEEK;
    u16::try_from(week as i64).ok().map(|w| (w, tow))
}

/// UTC (ROS) seconds of GPST seconds, with `leap_s` = GPS − UTC.
pub fn utc_of_gpst(gpst_s: f64, leap_s: f64) -> f64 {
    gpst_s - leap_s
}

/// Seconds since 1970-01-01 of a calendar date and time in the same scale (proleptic
/// Gregorian; `second` may carry a fraction). None for an impossible month or day.
pub fn seconds_of_calendar(
    year: i32,
    month: u32,
    day: u32,
    hour: u32,
    minute: u32,
    second: f64,
) -> Option<f64> {
    if !(1..=12).contains(&month) || !(1..=31).contains(&day) || hour > 23 || minute > 59 {
        return None;
    }
    if !(0.0..61.0).contains(&second) {
        return None;
    }
    // Days from 1970-01-01 by the civil-from-days inverse (March-based years, so the leap
    // day is the last day of the year).
    let y = i64::from(year) - i64::from(month <= 2);
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(month);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(day) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days as f64 * 86_400.0 + f64::from(hour * 3600 + minute * 60) + second)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_and_week_conversions_agree() {
        // The GPS epoch, a leap day, and the walk_0827 start (GPS week 2381).
        assert_eq!(
            seconds_of_calendar(1980, 1, 6, 0, 0, 0.0),
            Some(GPS_EPOCH_SINCE_1970_S)
        );
        assert_eq!(
            seconds_of_calendar(2024, 3, 1, 0, 0, 0.0).map(|s| s - 86_400.0),
            seconds_of_calendar(2024, 2, 29, 0, 0, 0.0)
        );
        let t = seconds_of_calendar(2025, 8, 28, 17, 30, 39.75).unwrap();
        let (week, tow) = week_tow_of_gpst(t).unwrap();
        assert_eq!(week, 2381);
        assert!((tow - (4.0 * 86_400.0 + 17.0 * 3600.0 + 30.0 * 60.0 + 39.75)).abs() < 1e-6);
        assert!((gpst_of_week_tow(2381, tow) - t).abs() < 1e-6);
        assert_eq!(seconds_of_calendar(2025, 13, 1, 0, 0, 0.0), None);
        assert_eq!(utc_of_gpst(100.0, DEFAULT_GPS_UTC_LEAP_S), 82.0);
    }
}
