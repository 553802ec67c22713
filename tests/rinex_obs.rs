//! The RINEX 3 observation reader: the walk_1730.obs file made by convbin, records of
//! every epoch flag, malformed lines with their line numbers, mutated input that must
//! never panic, and the conversion into the epochs the UBX path builds.

mod walk_0827_support;

use adaptive_gnss_ins::gnss::ephemeris::{EphemerisStore, GpsTime};
use adaptive_gnss_ins::gnss::rinex_nav::parse_rinex_nav;
use adaptive_gnss_ins::gnss::rinex_obs::{
    build_rinex_epoch, parse_rinex_obs, ObsCode, RinexObsError, SkippedRecord, TimeSystem,
};
use adaptive_gnss_ins::gnss::spp::{solve_spp, SppConfig};
use adaptive_gnss_ins::gnss::ubx::{build_epoch, read_ubx_log};
use adaptive_gnss_ins::gnss::{Constellation, SatId};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn code(text: &str) -> ObsCode {
    ObsCode::parse(text).unwrap()
}

fn gps(prn: u16) -> SatId {
    SatId {
        constellation: Constellation::Gps,
        prn,
    }
}

fn store() -> EphemerisStore {
    let nav = parse_rinex_nav(&walk_0827_support::read_text("walk_1730.nav")).unwrap();
    let mut store = EphemerisStore::new();
    for e in nav.ephemerides {
        store.insert(e);
    }
    store
}

#[test]
fn walk_1730_header_and_records() {
    let obs = parse_rinex_obs(&walk_0827_support::read_text("walk_1730.obs")).unwrap();
    let h = &obs.header;
    assert_eq!(h.version, 3.04);
    assert_eq!(h.file_system, 'M');
    assert_eq!(h.time_system, TimeSystem::Gps);
    let types = |s: char| -> Vec<String> {
        h.obs_types[&s]
            .iter()
            .map(|c| c.as_str().to_string())
            .collect()
    };
    assert_eq!(
        types('G'),
        ["C1C", "L1C", "D1C", "S1C", "C2L", "L2L", "D2L", "S2L"]
    );
    assert_eq!(types('E'), ["C1C", "L1C", "D1C", "S1C"]);
    assert_eq!(types('S'), ["C1C", "L1C", "D1C", "S1C"]);
    let p = h.approx_position_ecef_m.unwrap();
    assert_eq!(
        (p.x, p.y, p.z),
        (-1276965.2487, -4717231.7278, 4087230.1460)
    );
    // 2025-08-28 17:30:39.748 GPST: Thursday of GPS week 2381.
    let first = h.time_of_first_obs.unwrap();
    assert_eq!(first.week, 2381);
    assert!((first.tow_s - (4.0 * 86_400.0 + 17.0 * 3600.0 + 30.0 * 60.0 + 39.748)).abs() < 1e-9);

    let s = &obs.stats;
    assert_eq!(obs.epochs.len(), 536, "one epoch line per RAWX message");
    assert_eq!(s.epochs, 536);
    assert!(s.errors.is_empty(), "{:?}", s.errors);
    assert!(s.skipped.is_empty());
    assert_eq!((s.unsupported_satellites, s.stray_lines), (0, 0));
    let e0 = &obs.epochs[0];
    assert_eq!(e0.line, 25);
    assert_eq!(e0.time, first);
    assert_eq!(e0.satellites.len(), 17);
    assert!(!e0.power_failure);
    assert_eq!(e0.receiver_clock_offset_s, None);
    let g10 = &e0.satellites[0];
    assert_eq!(g10.sat, gps(10));
    assert_eq!(g10.get(code("C1C")).unwrap().value, 20576396.770);
    let l1 = g10.get(code("L1C")).unwrap();
    assert_eq!((l1.value, l1.lli, l1.ssi), (108129693.934, Some(1), None));
    assert_eq!(g10.get(code("D1C")).unwrap().value, 1064.326);
    assert_eq!(g10.get(code("S2L")).unwrap().value, 40.0);
    // G18 has no L2L phase: absent, not zero.
    let g18 = &e0.satellites[1];
    assert_eq!(g18.sat, gps(18));
    assert!(g18.get(code("L2L")).is_none());
    assert_eq!(g18.get(code("C2L")).unwrap().value, 21875371.688);
    // Epochs every 0.25 s.
    for pair in obs.epochs.windows(2) {
        let dt = pair[1].time.seconds_since(&pair[0].time);
        assert!((dt - 0.25).abs() < 1e-6, "{dt}");
    }
}

/// A small file in RINEX 3.04 layout with one record of every kind.
fn synthetic() -> String {
    let header = [
        format!(
            "{:<20}{:<20}{:<20}RINEX VERSION / TYPE",
            "     3.04", "OBSERVATION DATA", "M"
        ),
        format!("{:<60}SYS / # / OBS TYPES", "G    2 C1C D1C"),
        format!("{:<60}SYS / # / OBS TYPES", "I    1 C5A"),
        format!(
            "{:<60}TIME OF FIRST OBS",
            "  2025     8    28    17    30   39.7480000     GPS"
        ),
        format!("{:<60}END OF HEADER", ""),
    ];
    let comment = format!("{:<60}COMMENT", "a comment");
    let marker = format!("{:<60}MARKER NAME", "SITE");
    // An event record's time may be blank: flag in column 32, count in 33–35.
    let header_event = format!(">{:>31}{:>3}", 4, 2);
    let body = [
        // 6: a normal epoch, with a receiver clock offset (F15.12 in columns 42–56).
        "> 2025 08 28 17 30 39.7480000  0  2       0.000000012345",
        "G10  20576396.770        1064.326  ",
        "I02  25000000.000  ",
        // 9: power failure since the last epoch (kept, marked).
        "> 2025 08 28 17 30 40.0000000  1  1",
        "G10  20576400.000  ",
        // 11: header information follows (two special records).
        header_event.as_str(),
        comment.as_str(),
        marker.as_str(),
        // 14: external event.
        "> 2025 08 28 17 30 40.1000000  5  0",
        // 15: cycle-slip records.
        "> 2025 08 28 17 30 40.2500000  6  1",
        "G10  20576401.000  ",
        // 17: a bad satellite line (value) and one of an undeclared system.
        "> 2025 08 28 17 30 40.5000000  0  3",
        "G10  2057640x.000  ",
        "E11  20576401.000  ",
        "G23  20675528.834  ",
        // 21: a bad epoch line, its lines skipped up to the next epoch line.
        "> 2025 13 28 17 30 40.7500000  0  1",
        "G10  20576402.000  ",
        // 23: a truncated record: two lines announced, one found.
        "> 2025 08 28 17 30 41.0000000  0  2",
        "G10  20576403.000  ",
        // 25: a good epoch with a bad LLI, then a stray line.
        "> 2025 08 28 17 30 41.2500000  0  1",
        "G10  20576404.000x ",
        "garbage",
    ];
    let mut text = header.join("\n");
    for line in body {
        text.push('\n');
        text.push_str(line);
    }
    text.push('\n');
    text
}

#[test]
fn every_epoch_flag_and_malformed_line_is_handled() {
    let obs = parse_rinex_obs(&synthetic()).unwrap();
    let s = &obs.stats;
    let lines: Vec<usize> = obs.epochs.iter().map(|e| e.line).collect();
    assert_eq!(lines, [6, 9, 17, 25]);
    assert_eq!(s.epochs, 4);
    assert_eq!(s.power_failure_epochs, 1);
    assert!(obs.epochs[1].power_failure);
    assert_eq!(obs.epochs[0].receiver_clock_offset_s, Some(0.000000012345));
    // The NavIC satellite is read past and counted.
    assert_eq!(obs.epochs[0].satellites.len(), 1);
    assert_eq!(s.unsupported_satellites, 1);
    assert_eq!(
        obs.epochs[0].satellites[0].get(code("D1C")).unwrap().value,
        1064.326
    );
    let skipped: Vec<(SkippedRecord, usize)> = s.skipped.iter().map(|(k, n)| (*k, *n)).collect();
    assert_eq!(
        skipped,
        [
            (SkippedRecord::HeaderInformation, 1),
            (SkippedRecord::ExternalEvent, 1),
            (SkippedRecord::CycleSlips, 1),
        ]
    );
    // Only G23 survives in the epoch of line 17.
    let sats: Vec<SatId> = obs.epochs[2].satellites.iter().map(|r| r.sat).collect();
    assert_eq!(sats, [gps(23)]);
    assert_eq!(obs.epochs[3].satellites.len(), 0, "bad LLI drops G10");
    assert_eq!(s.stray_lines, 1);
    assert_eq!(
        s.errors,
        [
            RinexObsError::BadField {
                line: 18,
                what: "observation value"
            },
            RinexObsError::UndeclaredSystem {
                line: 19,
                system: 'E'
            },
            RinexObsError::BadField {
                line: 21,
                what: "epoch time"
            },
            RinexObsError::Truncated {
                line: 23,
                announced: 2,
                found: 1
            },
            RinexObsError::BadField {
                line: 26,
                what: "loss-of-lock indicator"
            },
        ]
    );
}

#[test]
fn header_errors_are_typed_with_line_numbers() {
    let text = synthetic();
    assert_eq!(
        parse_rinex_obs("garbage\n"),
        Err(RinexObsError::NotObservationFile { line: 1 })
    );
    let nav_header = text.replacen("OBSERVATION DATA", "N: GNSS NAV DATA", 1);
    assert!(matches!(
        parse_rinex_obs(&nav_header),
        Err(RinexObsError::NotObservationFile { .. })
    ));
    let v2 = text.replacen("     3.04", "     2.11", 1);
    assert!(matches!(
        parse_rinex_obs(&v2),
        Err(RinexObsError::UnsupportedVersion { line: 1, .. })
    ));
    let glonass_time = text.replacen("39.7480000     GPS", "39.7480000     GLO", 1);
    assert!(matches!(
        parse_rinex_obs(&glonass_time),
        Err(RinexObsError::UnsupportedTimeSystem { line: 4, .. })
    ));
    let bad_count = text.replacen("G    2 C1C", "G    x C1C", 1);
    assert_eq!(
        parse_rinex_obs(&bad_count),
        Err(RinexObsError::BadField {
            line: 2,
            what: "number of observation types"
        })
    );
    let no_end = text.replacen("END OF HEADER", "END OF HEADEX", 1);
    assert_eq!(parse_rinex_obs(&no_end), Err(RinexObsError::NoHeaderEnd));
    // BeiDou time: epochs 14 s later in GPST.
    let bdt = text.replacen("39.7480000     GPS", "39.7480000     BDT", 1);
    let gps_epochs = parse_rinex_obs(&text).unwrap().epochs;
    let bdt_epochs = parse_rinex_obs(&bdt).unwrap().epochs;
    let shift = bdt_epochs[0].time.seconds_since(&gps_epochs[0].time);
    assert!((shift - 14.0).abs() < 1e-9, "{shift}");
}

/// A random edit of `text` that keeps it UTF-8: a byte-range cut, a replaced or inserted
/// character (ASCII, digits, `>`, multi-byte), a deleted, duplicated or shortened line.
fn mutate(text: &str, rng: &mut ChaCha8Rng) -> String {
    const ALPHABET: [char; 12] = ['>', ' ', '0', '9', '.', '-', 'D', 'G', 'x', 'é', '€', '\n'];
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let edits = rng.random_range(1..6);
    for _ in 0..edits {
        if lines.is_empty() {
            break;
        }
        let i = rng.random_range(0..lines.len());
        match rng.random_range(0..6) {
            0 => {
                let chars: Vec<char> = lines[i].chars().collect();
                let cut = rng.random_range(0..=chars.len());
                lines[i] = chars[..cut].iter().collect();
            }
            1 => {
                let mut chars: Vec<char> = lines[i].chars().collect();
                if !chars.is_empty() {
                    let k = rng.random_range(0..chars.len());
                    chars[k] = ALPHABET[rng.random_range(0..ALPHABET.len())];
                }
                lines[i] = chars.into_iter().collect();
            }
            2 => {
                let mut chars: Vec<char> = lines[i].chars().collect();
                let k = rng.random_range(0..=chars.len());
                chars.insert(k, ALPHABET[rng.random_range(0..ALPHABET.len())]);
                lines[i] = chars.into_iter().collect();
            }
            3 => {
                lines.remove(i);
            }
            4 => {
                let copy = lines[i].clone();
                lines.insert(i, copy);
            }
            _ => {
                let garbage: String = (0..rng.random_range(0..90))
                    .map(|_| ALPHABET[rng.random_range(0..ALPHABET.len())])
                    .collect();
                lines.insert(i, garbage);
            }
        }
    }
    lines.join("\n")
}

#[test]
fn mutated_and_truncated_input_never_panics() {
    let full = walk_0827_support::read_text("walk_1730.obs");
    // The header and the first 20 epochs (about 380 lines).
    let sample: String = full
        .lines()
        .take(24 + 20 * 18)
        .collect::<Vec<_>>()
        .join("\n");
    let store = store();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut parsed = 0;
    let mut errors = 0;
    for _ in 0..3000 {
        let text = mutate(&sample, &mut rng);
        let Ok(obs) = parse_rinex_obs(&text) else {
            continue;
        };
        parsed += 1;
        errors += obs.stats.errors.len();
        for epoch in obs.epochs.iter().take(3) {
            let built = build_rinex_epoch(epoch, &store, None);
            let _ = solve_spp(&built.epoch, &SppConfig::default());
        }
    }
    println!("3000 mutations: {parsed} parsed, {errors} line errors reported");
    // Most mutations hit records, which are read past; the line errors are reported.
    assert!(parsed > 2500, "{parsed}");
    assert!(errors > 3000, "{errors}");
    // Every cut of the synthetic file, at every character.
    let text = synthetic();
    for (cut, _) in text.char_indices() {
        let _ = parse_rinex_obs(&text[..cut]);
    }
}

#[test]
fn rinex_epochs_equal_the_ubx_epochs_they_were_converted_from() {
    let obs = parse_rinex_obs(&walk_0827_support::read_text("walk_1730.obs")).unwrap();
    let store = store();
    let log = read_ubx_log(&walk_0827_support::read("gnss_1730.ubx"));
    let mut compared = 0;
    assert_eq!(obs.epochs.len(), log.rawx.len());
    for (epoch, raw) in obs.epochs.iter().zip(&log.rawx) {
        // convbin writes the RAWX time rounded to 0.1 µs.
        let raw_time = GpsTime::new(i32::from(raw.week), raw.rcv_tow_s);
        assert!(epoch.time.seconds_since(&raw_time).abs() < 1e-6);
        let built = build_rinex_epoch(epoch, &store, None);
        let s = built.stats;
        // 17 satellites: 6 GPS (4 with an ephemeris), 8 Galileo (no ephemeris in the
        // file), 3 SBAS (not used).
        assert_eq!(s.satellites, epoch.satellites.len());
        assert_eq!(
            s.used + s.no_ephemeris + s.unsupported + s.ephemeris_errors,
            s.satellites
        );
        assert_eq!(s.ephemeris_errors, 0);
        assert!(built
            .epoch
            .satellites
            .iter()
            .all(|o| o.sat.constellation == Constellation::Gps));
        // The same measurements through UBX, with the RINEX file's ephemerides.
        let again = build_epoch(raw, &store, None);
        // UBX also has the BeiDou B1I measurements convbin left out.
        for a in &built.epoch.satellites {
            let b = again
                .epoch
                .satellites
                .iter()
                .find(|b| b.sat == a.sat)
                .unwrap_or_else(|| panic!("{}: in RINEX, not in UBX", a.sat));
            // RINEX keeps 1 mm of pseudo-range and 1 mHz of Doppler.
            assert!((a.pseudorange_m.unwrap() - b.pseudorange_m.unwrap()).abs() <= 0.5e-3 + 1e-9);
            let rate_tolerance = 0.5e-3 * 0.1903 + 1e-9;
            let (ra, rb) = (
                a.pseudorange_rate_mps.unwrap(),
                b.pseudorange_rate_mps.unwrap(),
            );
            assert!((ra - rb).abs() <= rate_tolerance, "{ra} {rb}");
            assert!((a.sat_pos_ecef_m - b.sat_pos_ecef_m).norm() < 1e-3);
            assert!((a.sat_clock_bias_s - b.sat_clock_bias_s).abs() < 1e-12);
            assert_eq!(a.cn0_dbhz, b.cn0_dbhz.map(f64::round));
        }
        compared += built.epoch.satellites.len();
    }
    assert!(compared > 2000, "{compared}");
}
