//! `gnss_ins convert` from RINEX 3 observation and navigation files (walk_1730.obs/.nav of
//! ../shared/data/walk_0827): every epoch with a usable satellite becomes a
//! GnssMeasurements message carrying the file's pseudo-ranges and the satellite states,
//! and the modes RINEX cannot serve are refused with a clear error.

mod walk_0827_support;

use adaptive_gnss_ins::gnss::ionosphere::IonosphereMode;
use adaptive_gnss_ins::gnss::rinex_obs::parse_rinex_obs;
use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::GnssMeasurements;
use adaptive_gnss_ins::tools::convert::{
    convert, ConvertError, ConvertOptions, EphemerisMode, GnssSource, TruthInput,
};

fn options(ionosphere: IonosphereMode, truth: TruthInput) -> ConvertOptions {
    ConvertOptions {
        gnss: GnssSource::Rinex {
            obs: walk_0827_support::path("walk_1730.obs"),
            nav: walk_0827_support::path("walk_1730.nav"),
        },
        imu: None,
        truth,
        leap_seconds: 18.0,
        ephemeris: EphemerisMode::WholeLog,
        ionosphere,
    }
}

#[test]
fn rinex_epochs_become_gnss_measurements() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("rinex.mcap");
    let summary = convert(&options(IonosphereMode::Broadcast, TruthInput::None), &bag).unwrap();

    let text = std::fs::read_to_string(walk_0827_support::path("walk_1730.obs")).unwrap();
    let obs = parse_rinex_obs(&text).unwrap();
    assert_eq!(summary.gnss_epochs + summary.empty_epochs, obs.epochs.len());
    // The navigation file holds 4 GPS ephemerides: most epochs see all four.
    assert!(summary.gnss_epochs > 500, "{summary:?}");

    let messages: Vec<GnssMeasurements> = BagReader::open(&bag)
        .unwrap()
        .messages()
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.topic == "/gnss/measurements")
        .map(|m| cdr::decode(&m.data).unwrap())
        .collect();
    assert_eq!(messages.len(), summary.gnss_epochs);
    let first = &messages[0];
    // The first epoch of the file: 2025-08-28 17:30:39 GPST is week 2381, TOW 408639.
    assert_eq!(first.gps_week, 2381);
    assert!((first.gps_time_of_week_s - 408_639.0).abs() < 1.0);
    for m in &messages {
        for s in &m.satellites {
            assert!((2.0e7..2.6e7).contains(&s.pseudorange_m), "{s:?}");
            let r = s.satellite_position_ecef_m;
            let radius_m = (r.x * r.x + r.y * r.y + r.z * r.z).sqrt();
            assert!(
                (2.6e7..2.7e7).contains(&radius_m),
                "GPS orbit radius {radius_m}"
            );
            // Broadcast mode leaves the ionosphere to the engine (no Klobuchar here).
            assert!(s.ionosphere_delay_m.is_nan());
        }
    }
}

#[test]
fn modes_rinex_cannot_serve_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("x.mcap");
    let iono_free = convert(&options(IonosphereMode::IonoFree, TruthInput::None), &bag);
    assert!(matches!(iono_free, Err(ConvertError::RinexIonoFree)));
    let nav_pvt = convert(&options(IonosphereMode::None, TruthInput::UbxNavPvt), &bag);
    assert!(matches!(nav_pvt, Err(ConvertError::TruthNeedsUbx)));
}
