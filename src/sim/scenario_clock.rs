//! Where a scenario lies in real time: the ROS stamp (UTC) and the GPS week of each
//! scenario time, so that a simulated bag is stamped like a recording of this decade and
//! its GNSS epochs' week and time of week name the same instant as their stamps.
//!
//! Choice: the constellation keeps its internal reference epoch (the 1993 slot table's,
//! GPS time of week [`REFERENCE_EPOCH_GPS_TOW_S`]); a scenario places that epoch in GPS
//! week [`GnssSpec::constellation_gps_week`](crate::sim::scenario_spec::GnssSpec), whole
//! weeks later. The time of week, and so the geometry, the satellite clocks and the
//! ionosphere's local time, stay what the scenario always had; only the week number and
//! the stamps follow from the real date. Scenario time 0 is GPS time
//! `week · 604800 s + REFERENCE_EPOCH_GPS_TOW_S + start_gps_s` after the GPS epoch, and
//! its stamp is that instant in UTC, GPS − UTC = [`DEFAULT_GPS_UTC_LEAP_S`] earlier (the
//! convention of ROS drivers such as ublox_dgnss; valid from 2017, hence the weeks the
//! spec accepts).

use crate::gnss::time_scale::{DEFAULT_GPS_UTC_LEAP_S, GPS_EPOCH_SINCE_1970_S, SECONDS_PER_WEEK};
use crate::sim::constellation::REFERENCE_EPOCH_GPS_TOW_S;
use crate::sim::scenario_spec::GnssSpec;

const NS_PER_S: i64 = 1_000_000_000;

/// The real time of a scenario's time line. Real times are whole nanoseconds since
/// 1970-01-01 in UTC, what a ROS stamp holds (the ROS layer makes them stamps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScenarioClock {
    /// GPS week of the constellation's reference epoch.
    reference_week: u16,
    /// GPS time of scenario time 0 after the constellation's reference epoch (s).
    start_gps_s: f64,
    /// UTC of scenario time 0, ns since 1970-01-01.
    start_utc_ns: i64,
}

impl ScenarioClock {
    /// The clock of a scenario's GNSS spec (its week and `start_gps_s`).
    pub fn new(gnss: &GnssSpec) -> Self {
        let week = i64::from(gnss.constellation_gps_week);
        // Every term but start_gps_s is a whole number of seconds.
        let whole_utc_s = GPS_EPOCH_SINCE_1970_S as i64
            + week * SECONDS_PER_WEEK as i64
            + REFERENCE_EPOCH_GPS_TOW_S as i64
            - DEFAULT_GPS_UTC_LEAP_S as i64;
        Self {
            reference_week: gnss.constellation_gps_week,
            start_gps_s: gnss.start_gps_s,
            start_utc_ns: whole_utc_s * NS_PER_S + nearest_ns(gnss.start_gps_s),
        }
    }

    /// UTC of scenario time 0 (ns since 1970-01-01): the first stamp of a simulated bag.
    pub fn start_utc_ns(&self) -> i64 {
        self.start_utc_ns
    }

    /// UTC (ns since 1970-01-01) of scenario time `t_s`, to the nearest nanosecond of
    /// `t_s`: the stamp of an event at `t_s`.
    pub fn utc_ns(&self, t_s: f64) -> i64 {
        self.start_utc_ns + nearest_ns(t_s)
    }

    /// Scenario time (s) of a UTC time in ns since 1970 (a stamp): the inverse of
    /// [`Self::utc_ns`], exactly for the times it gave (the difference is taken in
    /// nanoseconds, then made `whole + nanoseconds / 1e9` seconds, as a ROS stamp is read).
    pub fn scenario_time_of_utc_ns(&self, utc_ns: i64) -> f64 {
        let ns = utc_ns - self.start_utc_ns;
        ns.div_euclid(NS_PER_S) as f64 + ns.rem_euclid(NS_PER_S) as f64 / NS_PER_S as f64
    }

    /// Scenario time (s) of a time in UNIX seconds as the engine holds a stamp (`f64`
    /// seconds since 1970, e.g. a replay's report): the nearest scenario time, within the
    /// 238 ns an `f64` resolves today.
    pub fn scenario_time_of_unix_s(&self, unix_s: f64) -> f64 {
        let whole_s = self.start_utc_ns.div_euclid(NS_PER_S);
        let fraction_s = self.start_utc_ns.rem_euclid(NS_PER_S) as f64 / NS_PER_S as f64;
        (unix_s - whole_s as f64) - fraction_s
    }

    /// GPS week of scenario time `t_s` (the constellation's time of week,
    /// [`GpsConstellation::gps_time_of_week_s`](crate::sim::constellation::GpsConstellation::gps_time_of_week_s),
    /// carries into the following weeks).
    pub fn gps_week(&self, t_s: f64) -> u16 {
        let weeks = ((REFERENCE_EPOCH_GPS_TOW_S + self.start_gps_s + t_s) / SECONDS_PER_WEEK)
            .floor()
            .max(0.0);
        self.reference_week.saturating_add(weeks as u16)
    }
}

/// The nearest whole nanoseconds of `t_s` seconds: the whole seconds split off first (the
/// fraction is then exact) and only the fraction rounded, as a ROS stamp is made. Times
/// are those of a validated scenario, far inside an `i64`.
fn nearest_ns(t_s: f64) -> i64 {
    let whole_s = t_s.floor();
    whole_s as i64 * NS_PER_S + ((t_s - whole_s) * NS_PER_S as f64).round() as i64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::time_scale::{seconds_of_calendar, week_tow_of_gpst};
    use crate::sim::constellation::GpsConstellation;

    fn gnss(week: u16, start_gps_s: f64) -> GnssSpec {
        GnssSpec {
            constellation_gps_week: week,
            start_gps_s,
            ..GnssSpec::default()
        }
    }

    #[test]
    fn the_reference_epoch_is_thursday_midnight_gps_time_of_its_week() {
        // Week 2386 began on Sunday 2025-09-28; its Thursday 00:00:09 GPST is 00:00:00 +
        // 9 s − 18 s UTC, i.e. 2025-10-01 23:59:51 UTC.
        let clock = ScenarioClock::new(&gnss(2386, 0.0));
        let utc_s = seconds_of_calendar(2025, 10, 1, 23, 59, 51.0).unwrap();
        assert_eq!(clock.start_utc_ns(), utc_s as i64 * NS_PER_S);
        assert_eq!(clock.gps_week(0.0), 2386);
        assert_eq!(clock.gps_week(604_800.0 - 345_609.0 - 1e-3), 2386);
        assert_eq!(clock.gps_week(604_800.0 - 345_609.0), 2387);
    }

    #[test]
    fn stamps_name_the_instant_of_the_week_and_time_of_week() {
        // An odd nanosecond in the start and an IMU time of x.0025 s.
        let clock = ScenarioClock::new(&gnss(2386, 10_800.000_000_001));
        let t_s = 1234.0025;
        let utc_ns = clock.utc_ns(t_s);
        let (sec, nanosec) = (utc_ns.div_euclid(NS_PER_S), utc_ns.rem_euclid(NS_PER_S));
        assert_eq!(nanosec % 10_000_000, 2_500_001);
        assert_eq!(clock.scenario_time_of_utc_ns(utc_ns), t_s);
        let gps_s = 10_800.000_000_001 + t_s;
        let tow_s = GpsConstellation::gps_time_of_week_s(gps_s);
        let gpst_s = sec as f64 + DEFAULT_GPS_UTC_LEAP_S;
        let (week, whole_tow_s) = week_tow_of_gpst(gpst_s).unwrap();
        assert_eq!(week, clock.gps_week(t_s));
        let tow_ns = (tow_s * 1e9).round() as i64;
        assert_eq!(tow_ns, whole_tow_s as i64 * NS_PER_S + nanosec);
    }

    #[test]
    fn unix_seconds_map_back_to_the_nearest_scenario_time() {
        let clock = ScenarioClock::new(&gnss(2386, 10_800.0));
        let utc_ns = clock.utc_ns(145.0);
        let unix_s = utc_ns as f64 / NS_PER_S as f64;
        let t_s = clock.scenario_time_of_unix_s(unix_s);
        assert!((t_s - 145.0).abs() < 2.4e-7, "{t_s}");
    }
}
