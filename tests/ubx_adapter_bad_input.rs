//! The UbxAdapter under the bad input of issue 13, on the real walk_0827 data as the
//! u-blox drivers publish it: random bytes and truncated frames in the stream, bad
//! checksums, SFRBX with a wrong word count or parity, a GPS clock subframe whose IODC
//! does not match the IODE of its orbit, RAWX with 0 and 200 signals, GPS week rollovers,
//! a receiver clock running backwards, a stray epoch ahead, duplicated epochs. Each is
//! counted, nothing panics, and nothing published differs from the clean run: an epoch
//! is left out, or a satellite, but never changed.

mod ubx_robot_support;

use adaptive_gnss_ins::gnss::ephemeris::{EphemerisStore, GpsTime};
use adaptive_gnss_ins::gnss::ionosphere::IonosphereMode;
use adaptive_gnss_ins::gnss::ubx::{
    build_epoch_with, lnav_subframe, read_ubx_log, sat_id, signal, RawMeasurement, RawX,
    TrackingStatus,
};
use adaptive_gnss_ins::gnss::{Constellation, SatId};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{DiagnosticStatus, GnssMeasurements, RawxData, UbxRxmRawx};
use adaptive_gnss_ins::ros::ubx_adapter::{UbxAdapter, UbxAdapterParams};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ubx_robot_support::{driver_messages, stream_chunk, walk_log, DriverMessage};

/// Node arrival time of a message stamped `ns` (its stamp: no transport delay).
fn arrival_s(ns: u64) -> f64 {
    ns as f64 * 1e-9
}

/// Runs the driver messages through a fresh adapter: its outputs, and the adapter.
fn run(messages: &[(u64, DriverMessage)]) -> (Vec<GnssMeasurements>, UbxAdapter) {
    let mut adapter = UbxAdapter::new(UbxAdapterParams::default()).unwrap();
    let mut out = Vec::new();
    for (ns, m) in messages {
        match m {
            DriverMessage::Rawx(m) => out.extend(adapter.on_rawx(m, arrival_s(*ns))),
            DriverMessage::Sfrbx(m) => adapter.on_sfrbx(m),
        }
    }
    (out, adapter)
}

/// The clean run.
fn clean() -> (Vec<(u64, DriverMessage)>, Vec<GnssMeasurements>) {
    let (log, tag) = walk_log();
    let messages = driver_messages(&log, &tag);
    let (out, adapter) = run(&messages);
    assert!(out.len() > 300);
    assert_eq!(adapter.counts().published as usize, out.len());
    (messages, out)
}

/// Every published epoch is one of the clean run's, and every satellite in it is
/// exactly as there (bytes of its CDR encoding). Returns how many satellites were left
/// out against the clean run.
fn assert_never_wrong(out: &[GnssMeasurements], reference: &[GnssMeasurements]) -> usize {
    let mut left_out = 0;
    for m in out {
        let r = reference
            .iter()
            .find(|r| r.header.stamp == m.header.stamp)
            .unwrap_or_else(|| panic!("epoch {:?} is not in the clean run", m.header.stamp));
        assert_eq!(
            (m.gps_week, m.gps_time_of_week_s),
            (r.gps_week, r.gps_time_of_week_s)
        );
        assert_eq!(
            cdr::encode(&m.klobuchar_alpha).unwrap(),
            cdr::encode(&r.klobuchar_alpha).unwrap()
        );
        for s in &m.satellites {
            let rs = r
                .satellites
                .iter()
                .find(|x| (x.constellation, x.prn) == (s.constellation, s.prn))
                .unwrap_or_else(|| {
                    panic!(
                        "satellite {} {} not in the clean epoch",
                        s.constellation, s.prn
                    )
                });
            assert_eq!(cdr::encode(s).unwrap(), cdr::encode(rs).unwrap());
        }
        left_out += r.satellites.len() - m.satellites.len();
    }
    left_out
}

fn diagnostics_value(status: &DiagnosticStatus, key: &str) -> String {
    status
        .values
        .iter()
        .find(|kv| kv.key == key)
        .map(|kv| kv.value.clone())
        .unwrap_or_else(|| panic!("no {key} on /diagnostics"))
}

#[test]
fn random_bytes_truncated_frames_and_bad_checksums_in_the_stream() {
    let (_, reference) = clean();
    let (log, _) = walk_log();
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let mut adapter = UbxAdapter::new(UbxAdapterParams::default()).unwrap();
    let mut out = Vec::new();
    let (mut start, mut t_s) = (0, 1_756_402_230.0);
    let (mut garbage, mut cut, mut flipped) = (0, 0, 0);
    while start < log.len() {
        let end = (start + rng.random_range(1..3_000usize)).min(log.len());
        let mut chunk = log[start..end].to_vec();
        match rng.random_range(0..10) {
            // Random bytes (with sync patterns among them) before the chunk.
            0 => {
                let mut noise: Vec<u8> = (0..rng.random_range(1..200))
                    .map(|_| rng.random())
                    .collect();
                noise.extend_from_slice(&[0xB5, 0x62, 0x02, 0x15]);
                noise.extend(chunk);
                chunk = noise;
                garbage += 1;
            }
            // The end of the chunk lost: the frame it was in is truncated.
            1 => {
                chunk.truncate(chunk.len() / 2);
                cut += 1;
            }
            // One byte corrupted: its frame fails the checksum.
            2 => {
                let i = rng.random_range(0..chunk.len());
                chunk[i] ^= 1 << rng.random_range(0..8);
                flipped += 1;
            }
            _ => {}
        }
        t_s += 0.03;
        out.extend(adapter.on_stream_chunk(&stream_chunk(&chunk), t_s));
        start = end;
    }
    // The stream ends in the middle of a RAWX frame.
    let rawx_at = log
        .windows(4)
        .position(|w| w == [0xB5, 0x62, 0x02, 0x15])
        .unwrap();
    out.extend(adapter.on_stream_chunk(&stream_chunk(&log[rawx_at..rawx_at + 100]), t_s));
    out.extend(adapter.finish_stream(t_s));
    // Random bytes on the message topics too: payloads that do not decode.
    for _ in 0..100 {
        let mut payload: Vec<u8> = vec![0, 1, 0, 0];
        payload.extend((0..rng.random_range(0..64)).map(|_| rng.random::<u8>()));
        if let Err(e) = cdr::decode::<UbxRxmRawx>(&payload) {
            adapter.on_undecodable("ubx_rxm_rawx", &e.to_string());
        }
    }
    let c = *adapter.counts();
    assert!(c.undecodable > 90, "{}", c.undecodable);
    println!("{garbage} garbage, {cut} cut, {flipped} flipped chunks: {c:?}");
    assert!(garbage > 50 && cut > 50 && flipped > 50);
    assert!(c.frames.bad_checksum > 50, "{:?}", c.frames);
    assert!(c.frames.truncated >= 1, "{:?}", c.frames);
    assert!(
        c.frames.skipped_bytes > 136_199,
        "garbage beyond the log's own NMEA"
    );
    assert!(c.published > 100, "most epochs survive");
    let left_out = assert_never_wrong(&out, &reference);
    println!(
        "{} of {} epochs published, {left_out} satellites left out",
        out.len(),
        reference.len()
    );
    let status = adapter.diagnostics("ubx");
    assert_eq!(
        diagnostics_value(&status, "frames_bad_checksum"),
        c.frames.bad_checksum.to_string()
    );
}

/// The subframe id and HOW TOW count of a GPS SFRBX, if it passes parity.
fn gps_subframe(m: &DriverMessage) -> Option<(SatId, u8, u64)> {
    let DriverMessage::Sfrbx(s) = m else {
        return None;
    };
    let sat = sat_id(s.gnss_id, s.sv_id).filter(|sat| sat.constellation == Constellation::Gps)?;
    let sf = lnav_subframe(sat, &s.dwrd).ok()?;
    Some((sat, sf.id, sf.data.u(24, 17)?))
}

#[test]
fn subframes_with_wrong_word_counts_parity_or_issue_of_data() {
    let (mut messages, reference) = clean();
    // A GPS clock subframe (1) of satellite X replaced by that of satellite Y, sent in the
    // same frame (X's subframes 2 and 3 of that frame received too): its IODC is Y's,
    // the orbit subframes are X's.
    let subframes: Vec<(usize, SatId, u8, u64)> = messages
        .iter()
        .enumerate()
        .filter_map(|(i, (_, m))| gps_subframe(m).map(|(sat, id, tow)| (i, sat, id, tow)))
        .collect();
    let has =
        |sat: SatId, id: u8, tow: u64| subframes.iter().any(|s| (s.1, s.2, s.3) == (sat, id, tow));
    let sf1: Vec<&(usize, SatId, u8, u64)> = subframes.iter().filter(|s| s.2 == 1).collect();
    let (x, y) = sf1
        .iter()
        .filter(|x| has(x.1, 2, x.3 + 1) && has(x.1, 3, x.3 + 2))
        .flat_map(|x| sf1.iter().map(move |y| (*x, *y)))
        .find(|(x, y)| x.3 == y.3 && x.1 != y.1)
        .expect("two GPS satellites' subframe 1 of one complete frame");
    let DriverMessage::Sfrbx(y_words) = &messages[y.0].1 else {
        unreachable!()
    };
    let y_words = y_words.dwrd.clone();
    let DriverMessage::Sfrbx(x_msg) = &mut messages[x.0].1 else {
        unreachable!()
    };
    x_msg.dwrd = y_words;
    let mut forged = 0;
    let mut k = 0;
    for (_, m) in messages.iter_mut() {
        let DriverMessage::Sfrbx(s) = m else { continue };
        k += 1;
        match k % 25 {
            // A GPS/BeiDou subframe with a word missing (count consistent) ...
            0 if s.dwrd.len() == 10 => {
                s.dwrd.pop();
                s.num_words = 9;
            }
            // ... one whose count disagrees with its words ...
            5 => s.num_words = s.num_words.wrapping_add(1),
            // ... and a bit flipped in a word of a GPS LNAV or BeiDou D1 subframe.
            10 if matches!((s.gnss_id, s.sig_id), (0, 0) | (3, 0 | 2 | 4))
                && s.sv_id > 5
                && s.dwrd.len() == 10 =>
            {
                s.dwrd[4] ^= 1 << 7;
                forged += 1;
            }
            _ => {}
        }
    }
    let (out, adapter) = run(&messages);
    let c = adapter.counts();
    let n = &c.nav.decoder;
    println!("{c:?}");
    assert!(n.rejected_word_count > 0, "{n:?}");
    assert!(
        n.rejected_parity == forged && forged > 0,
        "{forged} forged: {n:?}"
    );
    assert!(c.malformed > 0);
    assert!(n.issue_mismatch >= 1, "{n:?}");
    assert_never_wrong(&out, &reference);
    let status = adapter.diagnostics("ubx");
    assert_eq!(
        diagnostics_value(&status, "ephemeris_issue_mismatch"),
        n.issue_mismatch.to_string()
    );
}

/// The RAWX messages of the clean run, in order, with their stamps.
fn rawx_messages(messages: &[(u64, DriverMessage)]) -> Vec<(u64, UbxRxmRawx)> {
    messages
        .iter()
        .filter_map(|(ns, m)| match m {
            DriverMessage::Rawx(r) => Some((*ns, r.clone())),
            DriverMessage::Sfrbx(_) => None,
        })
        .collect()
}

#[test]
fn rawx_with_0_or_200_signals() {
    let (mut messages, reference) = clean();
    let late: Vec<usize> = messages
        .iter()
        .enumerate()
        .filter(|(_, (_, m))| matches!(m, DriverMessage::Rawx(_)))
        .map(|(i, _)| i)
        .skip(400)
        .collect();
    // Epoch A: no signal at all.
    let DriverMessage::Rawx(a) = &mut messages[late[0]].1 else {
        unreachable!()
    };
    a.rawx_data.clear();
    a.num_meas = 0;
    // Epoch B: 200 signals: its own, then GLONASS signals (not used).
    let DriverMessage::Rawx(b) = &mut messages[late[10]].1 else {
        unreachable!()
    };
    let b_tow = b.rcv_tow;
    let template = b.rawx_data[0];
    let glonass = |k: usize| RawxData {
        pr_mes: 2.2e7 + k as f64,
        gnss_id: 6,
        sv_id: (k % 24 + 1) as u8,
        sig_id: (k / 24) as u8,
        ..template
    };
    let own = b.rawx_data.len();
    b.rawx_data.extend((0..200 - own).map(glonass));
    b.num_meas = 200;
    // Epoch C: 200 signals, its own repeated with other pseudo-ranges: every satellite
    // has a duplicated signal.
    let DriverMessage::Rawx(c) = &mut messages[late[20]].1 else {
        unreachable!()
    };
    let c_tow = c.rcv_tow;
    let copies: Vec<RawxData> = c
        .rawx_data
        .iter()
        .cycle()
        .take(200 - c.rawx_data.len())
        .map(|d| RawxData {
            pr_mes: d.pr_mes + 100.0,
            ..*d
        })
        .collect();
    c.rawx_data.extend(copies);
    c.num_meas = 200;
    let (out, adapter) = run(&messages);
    let counts = adapter.counts();
    assert_never_wrong(&out, &reference);
    assert_eq!(out.len(), reference.len() - 2, "A and C left out");
    let epoch_at = |ms: &[GnssMeasurements], tow: f64| {
        ms.iter().find(|m| m.gps_time_of_week_s == tow).cloned()
    };
    let b_out = epoch_at(&out, b_tow).expect("B published");
    let b_ref = epoch_at(&reference, b_tow).unwrap();
    assert_eq!(cdr::encode(&b_out).unwrap(), cdr::encode(&b_ref).unwrap());
    assert!(epoch_at(&out, c_tow).is_none());
    assert!(counts.satellites.duplicate_signals > 10, "{counts:?}");
    assert!(counts.empty_epochs >= 2);
}

#[test]
fn duplicated_epochs_a_clock_running_back_and_a_1024_week_rollover() {
    let (messages, reference) = clean();
    let rawx = rawx_messages(&messages);
    // Every message twice: each RAWX repeated is dropped as a duplicate.
    let doubled: Vec<(u64, DriverMessage)> = messages
        .iter()
        .flat_map(|m| [m.clone(), m.clone()])
        .collect();
    let (out, adapter) = run(&doubled);
    assert_eq!(adapter.counts().duplicate_epochs as usize, rawx.len());
    assert_eq!(out.len(), reference.len());
    assert_never_wrong(&out, &reference);

    // After the run, a stray epoch an hour ahead (within the ephemerides' validity) and
    // an old epoch again (both dropped), then the receiver's time 10 s back for good:
    // followed from the third such epoch on.
    let (last_ns, _) = rawx.last().unwrap();
    // The last five epochs again, changed by `change`, received from `after_ns` on.
    let last_five = |after_ns: u64, change: &dyn Fn(&mut UbxRxmRawx)| {
        rawx[rawx.len() - 5..]
            .iter()
            .enumerate()
            .map(|(k, (_, r))| {
                let mut r = r.clone();
                change(&mut r);
                (after_ns + k as u64 * 250_000_000, DriverMessage::Rawx(r))
            })
            .collect::<Vec<_>>()
    };
    let mut ahead = rawx[rawx.len() - 1].1.clone();
    ahead.rcv_tow += 3_600.0;
    let mut tail = vec![
        (last_ns + 100_000_000, DriverMessage::Rawx(ahead)),
        (
            last_ns + 250_000_000,
            DriverMessage::Rawx(rawx[300].1.clone()),
        ),
    ];
    tail.extend(last_five(last_ns + 500_000_000, &|r| r.rcv_tow -= 10.0));
    // The receiver's week 1024 weeks back (a 10-bit rollover bug): no ephemeris is valid
    // then, nothing is published.
    tail.extend(last_five(last_ns + 2_000_000_000, &|r| r.week -= 1024));
    let mut all = messages.clone();
    all.extend(tail);
    let (out, adapter) = run(&all);
    let c = adapter.counts();
    println!("{c:?}");
    assert_eq!(c.time_jumps_ahead, 1);
    assert_eq!(c.time_backwards, 1 + 2 + 2);
    assert_eq!(c.timeline_restarts, 2);
    // The reset epochs are published at their new times (3 of the 5: after the restart).
    assert_eq!(out.len(), reference.len() + 3);
    assert_never_wrong(&out[..reference.len()], &reference);
    let last = out.last().unwrap();
    let (_, r) = &rawx[rawx.len() - 1];
    assert!((last.gps_time_of_week_s - (r.rcv_tow - 10.0)).abs() < 1e-9);
    assert!(c.satellites.no_ephemeris > 0 && c.empty_epochs >= 3);
}

/// A measurement of `sat` on L1 C/A with `pr_m`, everything valid.
fn l1(sat: SatId, pr_m: f64) -> RawMeasurement {
    RawMeasurement {
        pseudorange_m: pr_m,
        carrier_phase_cycles: 0.0,
        doppler_hz: 500.0,
        gnss_id: 0,
        sv_id: sat.prn as u8,
        sig_id: 0,
        freq_id: 0,
        lock_time_s: 10.0,
        cn0_dbhz: 45.0,
        pseudorange_sigma_m: 0.5,
        carrier_phase_sigma_cycles: 0.01,
        doppler_sigma_hz: 0.05,
        tracking: TrackingStatus {
            pr_valid: true,
            cp_valid: true,
            half_cycle_valid: true,
            half_cycle_subtracted: false,
        },
    }
}

#[test]
fn an_ephemeris_serves_across_the_end_of_the_gps_week() {
    // A real GPS ephemeris of the walk, its reference times moved 600 s before the end
    // of the week: epochs 0.1 s before and after the rollover use it, and the satellite
    // moves on by 0.2 s of its orbit.
    let log = read_ubx_log(&ubx_robot_support::walk_file("gnss_1730.ubx"));
    let sat = SatId {
        constellation: Constellation::Gps,
        prn: 32,
    };
    let mut eph = log.store.ephemerides(sat)[0];
    eph.toe = GpsTime::new(2381, 604_200.0);
    eph.toc = eph.toe;
    let mut store = EphemerisStore::new();
    store.insert(eph);
    let epoch = |week: u16, tow_s: f64| {
        let raw = RawX::new(tow_s, week, 18, 1, 1, vec![l1(sat, 2.2e7)]);
        build_epoch_with(&raw, &store, None, IonosphereMode::Broadcast)
    };
    let before = epoch(2381, 604_799.9);
    let after = epoch(2382, 0.1);
    assert_eq!((before.stats.used, after.stats.used), (1, 1));
    let (a, b) = (&before.epoch.satellites[0], &after.epoch.satellites[0]);
    // Displacement = 0.2 s times the mean velocity, to the orbit's jerk (< 0.1 mm).
    let moved = b.sat_pos_ecef_m - a.sat_pos_ecef_m;
    let expected = 0.1 * (a.sat_vel_ecef_mps + b.sat_vel_ecef_mps);
    assert!((moved - expected).norm() < 1e-4, "{moved} vs {expected}");
    assert!(moved.norm() > 500.0);
    assert!((b.sat_clock_bias_s - a.sat_clock_bias_s - 0.2 * a.sat_clock_drift_s_s).abs() < 1e-15);
    // GPS seconds of ~1.4e9 s resolve 0.24 µs.
    assert!((after.epoch.t_s - before.epoch.t_s - 0.2).abs() < 1e-6);
}

/// The live path fills the carrier fields through the same code as `convert`: the first
/// signal's phase (GPS L1 C/A, Galileo E1 in the default ionosphere-free mode; a
/// satellite without a pair, kept for its phase alone, has no range and its single
/// signal's phase) in cycles of its wavelength, with the receiver's σ and lock time, as
/// the RAWX block says.
#[test]
fn published_epochs_carry_the_receivers_carrier_phase() {
    let (bytes, _) = walk_log();
    let log = read_ubx_log(&bytes);
    let (_, out) = clean();
    let l1_m = 299_792_458.0 / 1_575.42e6;
    let (mut with_phase, mut satellites, mut phase_only) = (0, 0, 0);
    for m in &out {
        let raw = log
            .rawx
            .iter()
            .find(|r| (r.rcv_tow_s - m.gps_time_of_week_s).abs() < 1e-6)
            .expect("the RAWX of a published epoch");
        for s in &m.satellites {
            satellites += 1;
            if s.carrier_phase_cycles.is_nan() {
                continue;
            }
            with_phase += 1;
            if s.pseudorange_m.is_nan() {
                phase_only += 1;
            } else {
                assert!((s.carrier_wavelength_m - l1_m).abs() < 1e-12, "{s:?}");
            }
            assert!((0.0..=64.5).contains(&s.carrier_lock_time_s), "{s:?}");
            assert!(s.carrier_phase_sigma_cycles > 0.0, "{s:?}");
            let block = raw
                .measurements
                .iter()
                .find(|b| {
                    sat_id(b.gnss_id, b.sv_id).is_some_and(|id| {
                        (id.constellation.code(), id.prn) == (s.constellation, s.prn)
                    }) && b.carrier_phase_cycles == s.carrier_phase_cycles
                })
                .unwrap_or_else(|| panic!("no RAWX block with the phase of {s:?}"));
            assert!(block.tracking.cp_valid);
            assert_eq!(block.lock_time_s, s.carrier_lock_time_s);
            let block_signal = signal(block.gnss_id, block.sig_id).unwrap();
            assert!((s.carrier_wavelength_m - block_signal.wavelength_m()).abs() < 1e-12);
        }
    }
    println!(
        "{with_phase} of {satellites} satellite epochs with a carrier phase, {phase_only} \
         of them without a range"
    );
    assert!(phase_only > 0 && phase_only < with_phase);
    assert!(
        with_phase * 10 > satellites * 9,
        "{with_phase} of {satellites}"
    );
}
