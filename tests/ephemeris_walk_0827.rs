//! Broadcast ephemerides of the walk_0827 log: the UBX-SFRBX decoding against convbin's
//! RINEX navigation file, and satellite positions against RTKLIB.

mod walk_0827_support;

use adaptive_gnss_ins::gnss::ephemeris::{GpsTime, GroupDelay, KeplerianEphemeris};
use adaptive_gnss_ins::gnss::rinex_nav::parse_rinex_nav;
use adaptive_gnss_ins::gnss::ubx::read_ubx_log;
use adaptive_gnss_ins::gnss::{Constellation, SatId};

fn rinex() -> Vec<KeplerianEphemeris> {
    let text = walk_0827_support::read_text("walk_1730.nav");
    let nav = parse_rinex_nav(&text).unwrap();
    assert_eq!(nav.skipped_records, 5, "SBAS records");
    assert_eq!(nav.klobuchar, None);
    nav.ephemerides
}

/// RINEX writes 12 significant digits: relative rounding ≤ 5·10⁻¹², so 10⁻¹¹ relative.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-11 * b.abs().max(a.abs())
}

fn parameters(e: &KeplerianEphemeris) -> Vec<(&'static str, f64)> {
    let mut v = vec![
        ("sqrtA", e.sqrt_a_sqrt_m),
        ("e", e.eccentricity),
        ("i0", e.inclination_rad),
        ("idot", e.inclination_rate_rad_s),
        ("omega0", e.raan_rad),
        ("omegadot", e.raan_rate_rad_s),
        ("w", e.arg_perigee_rad),
        ("M0", e.mean_anomaly_rad),
        ("dn", e.mean_motion_diff_rad_s),
        ("cuc", e.cuc_rad),
        ("cus", e.cus_rad),
        ("crc", e.crc_m),
        ("crs", e.crs_m),
        ("cic", e.cic_rad),
        ("cis", e.cis_rad),
        ("af0", e.af0_s),
        ("af1", e.af1_s_s),
        ("af2", e.af2_s_s2),
        (
            "toe week s",
            f64::from(e.toe.week) * 604_800.0 + e.toe.tow_s,
        ),
        (
            "toc week s",
            f64::from(e.toc.week) * 604_800.0 + e.toc.tow_s,
        ),
        ("issue", f64::from(e.issue_of_data)),
        ("health", f64::from(e.health)),
        ("validity", e.validity_s),
    ];
    match e.group_delay {
        GroupDelay::Gps { tgd_s } => v.push(("tgd", tgd_s)),
        GroupDelay::Beidou { tgd1_s, tgd2_s } => {
            v.push(("tgd1", tgd1_s));
            v.push(("tgd2", tgd2_s));
        }
        GroupDelay::Galileo { bgd_e1_e5a_s, .. } => v.push(("bgd e1e5a", bgd_e1_e5a_s)),
    }
    v
}

#[test]
fn rinex_file_holds_four_gps_and_eight_beidou_ephemerides() {
    let ephs = rinex();
    let count = |c| ephs.iter().filter(|e| e.sat.constellation == c).count();
    assert_eq!(count(Constellation::Gps), 4);
    assert_eq!(count(Constellation::Beidou), 8);
    let g32 = ephs
        .iter()
        .find(|e| e.sat.prn == 32 && e.sat.constellation == Constellation::Gps)
        .unwrap();
    assert_eq!(g32.toe, GpsTime::new(2381, 410_400.0));
    assert_eq!(g32.issue_of_data, 83);
    assert!(close(g32.sqrt_a_sqrt_m, 0.515364527702e4));
    // BeiDou toe 406 800 s of BDT week 1025 = GPST week 2381, 406 814 s.
    let c21 = ephs
        .iter()
        .find(|e| e.sat.prn == 21 && e.sat.constellation == Constellation::Beidou)
        .unwrap();
    assert_eq!(c21.toe, GpsTime::new(2381, 406_814.0));
}

#[test]
fn ubx_decoded_ephemerides_equal_the_rinex_ones() {
    let log = read_ubx_log(&walk_0827_support::read("gnss_1730.ubx"));
    let mut compared = 0;
    for r in rinex() {
        let decoded = log
            .store
            .ephemerides(r.sat)
            .iter()
            .find(|e| e.toe.seconds_since(&r.toe).abs() < 1e-6)
            .unwrap_or_else(|| panic!("{}: no decoded ephemeris with toe {:?}", r.sat, r.toe));
        assert_eq!(decoded.source, r.source, "{}", r.sat);
        for ((name, a), (_, b)) in parameters(decoded).into_iter().zip(parameters(&r)) {
            assert!(close(a, b), "{} {name}: UBX {a:e} vs RINEX {b:e}", r.sat);
        }
        compared += 1;
    }
    assert_eq!(compared, 12);
}

#[test]
fn satellite_positions_and_clocks_match_rtklib() {
    let ephs = rinex();
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/rtklib_gps_satpos_walk_1730.txt"),
    )
    .unwrap();
    let mut checked = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let f: Vec<&str> = line.split_whitespace().collect();
        // 2025-08-28 is day 4 of GPS week 2381.
        let hms: Vec<f64> = f[1].split(':').map(|x| x.parse().unwrap()).collect();
        let tow = 4.0 * 86_400.0 + hms[0] * 3_600.0 + hms[1] * 60.0 + hms[2];
        let sat = SatId {
            constellation: Constellation::Gps,
            prn: f[2].parse().unwrap(),
        };
        let reference: Vec<f64> = f[3..7].iter().map(|x| x.parse().unwrap()).collect();
        let eph = ephs.iter().find(|e| e.sat == sat).unwrap();
        let s = eph.state_at(&GpsTime::new(2381, tow)).unwrap();
        for (k, (got, want)) in s.pos_ecef_m.iter().zip(&reference).enumerate() {
            // RTKLIB prints mm and the time to 1 µs (≤ 4 mm of motion).
            assert!((got - want).abs() < 0.01, "{sat} axis {k}: {got} vs {want}");
        }
        assert!(
            (s.clock_bias_s * 1e9 - reference[3]).abs() < 0.002,
            "{sat} clock {} ns vs {} ns",
            s.clock_bias_s * 1e9,
            reference[3]
        );
        checked += 1;
    }
    assert_eq!(checked, 8);
}
