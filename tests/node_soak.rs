//! Issue 12's soak of the live `gnss_ins_node`, run by hand (numbers in
//! docs/benchmarks.md):
//!
//! `GNSS_INS_SOAK_S=86400 cargo test --release --test node_soak -- --ignored --nocapture`
//!
//! A ros2-client peer streams a simulated static receiver, 1 kHz IMU and 10 Hz GNSS, and
//! once a minute of stream time one bad message of each kind. The stream runs forward
//! (stamps and satellites move on) or, with `GNSS_INS_SOAK_LOOP_S`, repeats its first
//! that many seconds as `ros2 bag play --loop` does (each pass a time jump back, which
//! resets the filter); `GNSS_INS_SOAK_RATE` plays it faster than real time. The node's
//! resident memory is read every 30 s and its /diagnostics followed. Asserted at the
//! end: after the first two minutes memory stays within 5 % of its value then; no reset
//! but one per loop restart (a single outlying stamp is dropped, not a reset:
//! src/ros/adapter/time_line.rs); each bad message counted where the node says it drops
//! it; the node alive and still publishing finite Odometry.
//!
//! DDS traffic stays on this machine: the test re-executes itself inside a private
//! network namespace that has only loopback (tests/netns_support).

mod netns_support;
mod static_node_support;

use std::time::{Duration, Instant};

use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::{DiagnosticArray, Imu, Time};
use adaptive_gnss_ins::ros::outbound;
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec, Segment, SimEvent};
use nalgebra::Vector3;
use netns_support::{reexec_in_private_netns, rss_kb};
use ros2_client::Name;
use static_node_support::{diagnostic_count, start_node, type_name, Peer};

const DOMAIN_ID: u16 = 37;
/// Length of the soak in stream time (s), default 10 minutes.
const DURATION_ENV: &str = "GNSS_INS_SOAK_S";
const DEFAULT_DURATION_S: u64 = 600;
/// Length of one pass of a looped stream (s, a whole number of minutes); unset: forward.
const LOOP_ENV: &str = "GNSS_INS_SOAK_LOOP_S";
/// Stream seconds per second of wall time, default 1.
const RATE_ENV: &str = "GNSS_INS_SOAK_RATE";
/// Memory is judged against its value this long after the start (buffers grown,
/// DDS discovery done).
const SETTLE: Duration = Duration::from_secs(120);
const RSS_PERIOD: Duration = Duration::from_secs(30);
/// The bad messages go out at this second of every minute of scenario time.
const BAD_AT_S: f64 = 30.0;
const BAD_PERIOD_S: f64 = 60.0;
/// Every counter the node reports of a reset.
const RESET_KEYS: [&str; 5] = [
    "time_jump_resets",
    "divergence_resets",
    "frame_switches_imu",
    "frame_switches_gnss",
    "frame_switches_fix",
];

/// A payload no input type decodes: two bytes after the CDR header.
#[derive(Debug, serde::Serialize)]
struct Garbage {
    bytes: [u8; 2],
}

/// What the peer heard from the node.
#[derive(Default)]
struct Heard {
    /// The latest /diagnostics report.
    diagnostics: Option<DiagnosticArray>,
    odometry: u64,
    odometry_since_sample: u64,
    /// Odometry messages with a non-finite position or covariance.
    non_finite: u64,
    last_odometry_s: f64,
}

impl Heard {
    /// Takes what arrived since the last call.
    fn drain(&mut self, peer: &Peer) {
        while let Ok(Some((o, _))) = peer.odometry.take() {
            let p = &o.pose.pose.position;
            let finite = [p.x, p.y, p.z]
                .iter()
                .chain(o.pose.covariance.iter())
                .all(|v| v.is_finite());
            self.non_finite += u64::from(!finite);
            self.odometry += 1;
            self.odometry_since_sample += 1;
            let t = &o.header.stamp;
            self.last_odometry_s = t.sec as f64 + 1e-9 * t.nanosec as f64;
        }
        while let Ok(Some((d, _))) = peer.diagnostics.take() {
            self.diagnostics = Some(d);
        }
        while let Ok(Some(_)) = peer.tf.take() {}
    }
}

fn stamp(t_s: f64) -> Time {
    seconds_to_time(t_s).unwrap()
}

/// The scenario: the built-in static receiver at 1 kHz IMU and 10 Hz GNSS, standing
/// still for `duration_s` and a minute more.
fn soak_scenario(duration_s: f64) -> Scenario {
    let mut spec = ScenarioSpec::builtin("static").unwrap();
    spec.imu.rate_hz = 1000.0;
    spec.gnss.rate_hz = 10.0;
    spec.trajectory.segments = vec![Segment::Stationary {
        duration_s: duration_s + 60.0,
    }];
    Scenario::new(spec, 3).unwrap()
}

/// The IMU messages of one round of bad input sent just after the good sample `s`: a NaN,
/// a specific force of 1e6 m/s², a stamp 1 s back, a stamp 1000 s ahead, and a good
/// sample from a foreign frame.
fn bad_imu(s: &ImuSample) -> [Imu; 5] {
    let between = s.t_s + 0.0005;
    let mut nan = *s;
    nan.w_ib_b_rad_s.x = f64::NAN;
    let mut huge = *s;
    huge.f_ib_b_m_s2 = Vector3::new(1e6, 0.0, 0.0);
    [
        outbound::imu(&nan, stamp(between), "imu_link"),
        outbound::imu(&huge, stamp(between), "imu_link"),
        outbound::imu(s, stamp(s.t_s - 1.0), "imu_link"),
        outbound::imu(s, stamp(s.t_s + 1000.0), "imu_link"),
        outbound::imu(s, stamp(between), "spoofed_link"),
    ]
}

/// The variable `name` parsed, or `default` when it is unset.
fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).map_or(default, |v| {
        v.parse()
            .unwrap_or_else(|_| panic!("{name}: cannot parse {v:?}"))
    })
}

#[test]
#[ignore = "a soak run by hand (GNSS_INS_SOAK_S seconds, default 600)"]
fn node_memory_is_flat_and_bad_messages_cause_no_reset() {
    if reexec_in_private_netns("node_memory_is_flat_and_bad_messages_cause_no_reset") {
        return;
    }
    let duration_s: u64 = env_or(DURATION_ENV, DEFAULT_DURATION_S);
    let loop_s: Option<u64> = std::env::var(LOOP_ENV).ok().map(|_| env_or(LOOP_ENV, 0));
    let rate: f64 = env_or(RATE_ENV, 1.0);
    assert!(
        duration_s as f64 / rate >= 180.0,
        "the soak needs 3 minutes of wall time at least (memory settles for 2)"
    );
    assert!(
        loop_s.is_none_or(|s| s >= 120 && s % 60 == 0),
        "{LOOP_ENV}: whole minutes, at least 2 (the bad messages come at second 30 of each)"
    );
    assert!(rate > 0.0 && rate <= 20.0, "{RATE_ENV} in (0, 20]");
    // A pass: the whole stream, or the loop's length.
    let pass_s = loop_s.unwrap_or(duration_s) as f64;
    let scenario = soak_scenario(pass_s);
    // With /tf (Peer::matched waits for it), as a robot would run it.
    let node = start_node(
        DOMAIN_ID,
        &scenario,
        &["-p", "publish_tf:=true", "-p", "base_frame:=imu_link"],
    );
    let pid = node.0.id();
    let mut peer = Peer::matched(DOMAIN_ID, "soak_player", "/test/imu", false);
    let garbage_topic = peer
        .node
        .create_topic(
            &Name::parse("/test/imu").unwrap(),
            type_name::<Imu>(),
            &ros2_client::QosProfile::publisher_default(),
        )
        .unwrap();
    let garbage = peer
        .node
        .create_publisher::<Garbage>(&garbage_topic, None)
        .unwrap();
    let (handshake_imu, handshake_gnss) = peer.wait_until_inputs_heard();

    let started = Instant::now();
    let mut heard = Heard::default();
    let mut rss_samples: Vec<(Duration, u64)> = Vec::new();
    let (mut imu_sent, mut gnss_sent, mut rounds) = (0u64, 0u64, 0u64);
    let mut next_bad_s = BAD_AT_S;
    let mut gnss_bad_pending = false;
    let mut next_drain = Duration::ZERO;
    let mut last_t_s = 0.0;
    // Passes begun: a loop restart is a time jump back.
    let mut passes = 0u64;
    let pass_count = loop_s.map_or(1, |loop_s| duration_s.div_ceil(loop_s));
    'stream: for pass in 0..pass_count {
        let pass_start_s = pass as f64 * pass_s;
        for event in scenario.events() {
            let event = event.unwrap();
            let t_s = event.t_s();
            // A looped pass ends before its last instant, which is the next pass's first.
            if t_s > pass_s || (loop_s.is_some() && t_s >= pass_s) {
                break;
            }
            let stream_s = pass_start_s + t_s;
            if stream_s > duration_s as f64 {
                break 'stream;
            }
            passes = pass + 1;
            last_t_s = t_s;
            if let Some(wait) =
                Duration::from_secs_f64(stream_s / rate).checked_sub(started.elapsed())
            {
                std::thread::sleep(wait);
            }
            match event {
                SimEvent::Imu(s) => {
                    imu_sent += 1;
                    peer.imu
                        .publish(outbound::imu(&s, stamp(t_s), "imu_link"))
                        .unwrap();
                    if stream_s >= next_bad_s {
                        for bad in bad_imu(&s) {
                            peer.imu.publish(bad).unwrap();
                        }
                        garbage.publish(Garbage { bytes: [0xff; 2] }).unwrap();
                        rounds += 1;
                        gnss_bad_pending = true;
                        next_bad_s += BAD_PERIOD_S;
                    }
                }
                SimEvent::Gnss { epoch, .. } => {
                    gnss_sent += 1;
                    let good = outbound::gnss_measurements(&epoch, 0, stamp(t_s), "gnss");
                    if gnss_bad_pending {
                        // This epoch arrives corrupted (one pseudo-range NaN), then a copy of
                        // it stamped 1000 s ahead.
                        let mut nan = good.clone();
                        nan.satellites[0].pseudorange_m = f64::NAN;
                        peer.gnss.publish(nan).unwrap();
                        let mut ahead = good;
                        ahead.header.stamp = stamp(t_s + 1000.0);
                        peer.gnss.publish(ahead).unwrap();
                        gnss_bad_pending = false;
                    } else {
                        peer.gnss.publish(good).unwrap();
                    }
                }
                _ => {}
            }
            let elapsed = started.elapsed();
            if elapsed >= next_drain {
                heard.drain(&peer);
                next_drain = elapsed + Duration::from_millis(500);
            }
            if elapsed >= RSS_PERIOD * (rss_samples.len() as u32 + 1) {
                let kb = rss_kb(pid);
                let d = heard.diagnostics.as_ref();
                let count = |key| d.and_then(|d| diagnostic_count(d, key));
                eprintln!(
                    "t = {:>5.0} s  RSS {kb} kB  Odometry {} in the last {} s  \
                     resets {:?}",
                    elapsed.as_secs_f64(),
                    heard.odometry_since_sample,
                    RSS_PERIOD.as_secs(),
                    RESET_KEYS.map(count)
                );
                assert!(
                    heard.odometry_since_sample > 0,
                    "no Odometry in the last {RSS_PERIOD:?}"
                );
                heard.odometry_since_sample = 0;
                rss_samples.push((elapsed, kb));
            }
        }
    }
    let streamed = started.elapsed();
    let deadline = Instant::now() + Duration::from_secs(3);
    while Instant::now() < deadline {
        heard.drain(&peer);
        std::thread::sleep(Duration::from_millis(50));
    }
    let Heard {
        diagnostics,
        odometry,
        non_finite,
        last_odometry_s,
        ..
    } = heard;
    let diagnostics = diagnostics.expect("no /diagnostics received");
    eprintln!(
        "streamed {imu_sent} IMU samples and {gnss_sent} GNSS epochs in {:.0} s ({passes} \
         passes), {rounds} rounds of bad messages; {odometry} Odometry received, the last \
         at {last_odometry_s:.3} s",
        streamed.as_secs_f64()
    );
    eprintln!("diagnostics: {:?}", diagnostics.status[0].values);

    let settled = rss_samples
        .iter()
        .find(|(t, _)| *t >= SETTLE)
        .expect("no RSS sample after the settling time")
        .1;
    let max_after = rss_samples
        .iter()
        .filter(|(t, _)| *t >= SETTLE)
        .map(|(_, kb)| *kb)
        .max()
        .unwrap();
    let last = rss_samples.last().unwrap().1;
    eprintln!(
        "RSS samples (s, kB): {:?}",
        rss_samples
            .iter()
            .map(|(t, kb)| (t.as_secs(), *kb))
            .collect::<Vec<_>>()
    );
    eprintln!("RSS at 2 min {settled} kB, at the end {last} kB, max after 2 min {max_after} kB");
    let mut node = node;
    assert!(node.0.try_wait().unwrap().is_none(), "the node exited");
    assert_eq!(non_finite, 0, "non-finite Odometry published");
    assert!(
        last_odometry_s > last_t_s - 2.0,
        "the last Odometry is at {last_odometry_s} s, the last sample at {last_t_s} s"
    );
    let count = |key: &str| {
        diagnostic_count(&diagnostics, key).unwrap_or_else(|| panic!("no `{key}` on /diagnostics"))
    };
    // Each loop restart is a time jump back, followed by a reset; nothing else resets.
    for key in RESET_KEYS {
        let expected = if key == "time_jump_resets" {
            passes - 1
        } else {
            0
        };
        assert_eq!(count(key), expected, "{key}");
    }
    assert_eq!(
        static_node_support::diagnostic_value(&diagnostics, "phase").as_deref(),
        Some("running")
    );
    // Each bad message of a round is counted where the node says it drops it.
    assert_eq!(count("undecodable"), rounds, "garbage payloads");
    assert_eq!(
        count("unconvertible_imu"),
        handshake_imu + rounds,
        "NaN samples"
    );
    assert_eq!(count("imu_stamp_outliers"), rounds, "IMU 1000 s ahead");
    assert_eq!(count("foreign_frame_imu"), rounds, "foreign frame");
    assert_eq!(count("rejected_imu_out_of_range"), rounds, "IMU 1e6 m/s²");
    assert_eq!(count("rejected_imu_out_of_order"), rounds, "IMU 1 s back");
    assert_eq!(
        count("unconvertible_gnss"),
        rounds,
        "GNSS with a NaN pseudo-range"
    );
    assert_eq!(
        count("rejected_measurement_too_new"),
        rounds,
        "GNSS 1000 s ahead"
    );
    assert_eq!(
        count("imu_received") - count("unconvertible_imu") - count("foreign_frame_imu"),
        imu_sent + 3 * rounds,
        "every good IMU sample arrived, with the 1e6 m/s², 1 s back and 1000 s ahead ones"
    );
    assert_eq!(
        count("gnss_received"),
        handshake_gnss + gnss_sent + rounds,
        "every GNSS epoch arrived, with the copies stamped ahead"
    );

    assert!(
        (max_after as f64) <= settled as f64 * 1.05,
        "RSS grew from {settled} to {max_after} kB"
    );
}
