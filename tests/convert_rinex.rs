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

/// The carrier phases `convert` takes from RINEX (`L1C` and its LLI) are the receiver's:
/// convbin wrote walk_1730.obs from the same log, and the RINEX-built epochs carry the
/// RAWX-built epochs' phases to the file's three decimals, with the same wavelength.
#[test]
fn rinex_carrier_phases_are_the_receivers() {
    use adaptive_gnss_ins::gnss::rinex_obs::build_rinex_epoch;
    use adaptive_gnss_ins::gnss::ubx::{build_epoch, read_ubx_log};

    let log = read_ubx_log(&walk_0827_support::read("gnss_1730.ubx"));
    let text = std::fs::read_to_string(walk_0827_support::path("walk_1730.obs")).unwrap();
    let obs = parse_rinex_obs(&text).unwrap();
    let (mut compared, mut lock_lost, mut half_cycle) = (0, 0, 0);
    for raw in &log.rawx {
        let ubx = build_epoch(raw, &log.store, None);
        let tow_s = ubx.receive_time.tow_s;
        let Some(rinex) = obs
            .epochs
            .iter()
            .find(|e| (e.time.tow_s - tow_s).abs() < 1e-3)
        else {
            continue;
        };
        let rinex = build_rinex_epoch(rinex, &log.store, None);
        for sat in &rinex.epoch.satellites {
            let Some(phase) = sat.carrier_phase else {
                continue;
            };
            lock_lost += usize::from(phase.loss_of_lock);
            half_cycle += usize::from(phase.half_cycle_unresolved);
            assert_eq!((phase.sigma_cycles, phase.lock_time_s), (None, None));
            let theirs = ubx
                .epoch
                .satellites
                .iter()
                .find(|s| s.sat == sat.sat)
                .and_then(|s| s.carrier_phase)
                .unwrap_or_else(|| panic!("{} at {tow_s}: no RAWX phase", sat.sat));
            assert!(
                (phase.cycles - theirs.cycles).abs() <= 5e-4 + 1e-9,
                "{} at {tow_s}: {} against {}",
                sat.sat,
                phase.cycles,
                theirs.cycles
            );
            assert_eq!(phase.wavelength_m, theirs.wavelength_m);
            assert!(theirs.lock_time_s.is_some() && theirs.sigma_cycles.is_some());
            compared += 1;
        }
    }
    println!("{compared} phases compared; LLI loss of lock {lock_lost}, half cycle {half_cycle}");
    assert!(compared > 2500, "{compared}");
}
