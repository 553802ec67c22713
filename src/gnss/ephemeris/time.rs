//! GPS time as (week, seconds of week), and the offsets of the Galileo and BeiDou time
//! scales against it.

/// Seconds in a GNSS week.
pub const SECONDS_PER_WEEK: f64 = 604_800.0;
/// BDT = GPST − 14 s (BDS ICD: BDT started 2006-01-01 00:00:00 UTC, when GPST − UTC = 14 s).
pub const BDT_MINUS_GPST_S: f64 = -14.0;
/// BDT week 0 began at GPS week 1356 (2006-01-01).
pub const BDT_WEEK_OFFSET: i32 = 1356;
/// Galileo System Time week 0 began at GPS week 1024 (1999-08-22); GST and GPST share the
/// second (the GGTO of a few ns is ignored here, see `EphemerisStore`).
pub const GST_WEEK_OFFSET: i32 = 1024;

/// A time in the GPS time scale: full week number (since 1980-01-06) and seconds of week.
///
/// Choice: differences are formed as (Δweek · 604 800 + Δtow) so a difference of two
/// nearby times keeps the full f64 resolution of the seconds of week (sub-nanosecond),
/// which seconds since 1980 in one f64 would not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpsTime {
    /// GPS week number, not truncated to 10 or 13 bits.
    pub week: i32,
    /// Seconds of week, in [0, 604 800) once normalized.
    pub tow_s: f64,
}

impl GpsTime {
    /// A GPS time, normalized so that `tow_s` is in [0, 604 800).
    pub fn new(week: i32, tow_s: f64) -> Self {
        Self { week, tow_s }.normalized()
    }

    /// A BeiDou time (BDT week, seconds of BDT week) expressed in GPST.
    pub fn from_bdt(bdt_week: i32, bdt_sow_s: f64) -> Self {
        Self::new(
            bdt_week.saturating_add(BDT_WEEK_OFFSET),
            bdt_sow_s - BDT_MINUS_GPST_S,
        )
    }

    /// A Galileo System Time (GST week, seconds of week) expressed in GPST.
    pub fn from_gst(gst_week: i32, gst_tow_s: f64) -> Self {
        Self::new(gst_week.saturating_add(GST_WEEK_OFFSET), gst_tow_s)
    }

    /// `self − other` in seconds.
    pub fn seconds_since(&self, other: &GpsTime) -> f64 {
        (f64::from(self.week) - f64::from(other.week)) * SECONDS_PER_WEEK
            + (self.tow_s - other.tow_s)
    }

    /// This time shifted by `dt_s` seconds.
    pub fn add_seconds(&self, dt_s: f64) -> GpsTime {
        GpsTime::new(self.week, self.tow_s + dt_s)
    }

    /// Whether the seconds of week are finite.
    pub fn is_finite(&self) -> bool {
        self.tow_s.is_finite()
    }

    fn normalized(self) -> Self {
        if !self.tow_s.is_finite() {
            return self;
        }
        let whole_weeks = (self.tow_s / SECONDS_PER_WEEK).floor();
        // Choice: weeks beyond ±i32 cannot come from real data; saturate rather than wrap.
        let shift = whole_weeks.clamp(f64::from(i32::MIN / 2), f64::from(i32::MAX / 2)) as i32;
        Self {
            week: self.week.saturating_add(shift),
            tow_s: self.tow_s - f64::from(shift) * SECONDS_PER_WEEK,
        }
    }
}

/// The full week number nearest to `reference_week` whose value modulo 2^`bits` is
/// `truncated` (GPS LNAV broadcasts 10 bits, BDS D1 13 bits, Galileo 12 bits).
pub fn resolve_week(truncated: u32, bits: u32, reference_week: i32) -> i32 {
    let modulus = 1i64 << bits.min(30);
    let reference = i64::from(reference_week);
    let base = reference - reference.rem_euclid(modulus);
    let candidates = [base - modulus, base, base + modulus];
    let target = i64::from(truncated) % modulus;
    let best = candidates
        .iter()
        .map(|c| c + target)
        .min_by_key(|w| (w - reference).abs())
        .unwrap_or(reference);
    i32::try_from(best).unwrap_or(reference_week)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn differences_and_normalization() {
        let a = GpsTime::new(2381, 604_799.5);
        let b = a.add_seconds(1.0);
        assert_eq!(b.week, 2382);
        assert!((b.tow_s - 0.5).abs() < 1e-12);
        assert!((b.seconds_since(&a) - 1.0).abs() < 1e-12);
        let c = GpsTime::new(2382, -0.25);
        assert_eq!(c.week, 2381);
        assert!((c.tow_s - 604_799.75).abs() < 1e-9);
    }

    #[test]
    fn beidou_and_galileo_time_scales() {
        // BDT week 1025, SOW 406 800 = GPS week 2381, TOW 406 814.
        let t = GpsTime::from_bdt(1025, 406_800.0);
        assert_eq!(t.week, 2381);
        assert!((t.tow_s - 406_814.0).abs() < 1e-12);
        let g = GpsTime::from_gst(1357, 10.0);
        assert_eq!(g.week, 2381);
    }

    #[test]
    fn week_rollover_resolution() {
        // 2381 mod 1024 = 333.
        assert_eq!(resolve_week(333, 10, 2381), 2381);
        assert_eq!(resolve_week(333, 10, 2390), 2381);
        // Just across a rollover boundary (2048): truncated 1023 near week 2049 → 2047.
        assert_eq!(resolve_week(1023, 10, 2049), 2047);
        assert_eq!(resolve_week(0, 10, 2047), 2048);
    }
}
