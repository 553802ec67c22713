//! Latency of the UbxAdapter, RAWX in -> GnssMeasurements out (issue 13: 30 satellites
//! at 10 Hz, p99 < 1 ms), and its memory over a long run. A timed run, not criterion:
//! the figure asked for is a percentile of single-message latencies.
//!
//! Input: the walk_0827 log as ublox_dgnss publishes it, with every satellite's
//! subframes and measurement blocks also sent under three more satellite numbers (svId
//! plus 60, 120 and 180), so that once the ephemerides are in an epoch uses ~30 satellites
//! (dual-frequency, ionosphere-free: ~70 signals each), and the log played `LOOPS`
//! times, one GPS week apart. Each epoch is timed from its CDR payload to the CDR
//! payload of its GnssMeasurements (decode, adapter, encode), as the node would.
//!
//! The whole run is repeated `REPEATS` times with fresh adapters (the same work each
//! time): the percentiles are given over all timings (what a loaded host gives, other
//! processes preempting) and over each epoch's fastest repeat (the work itself).
//!
//! Run with `cargo bench --bench ubx_adapter_latency`.

#[path = "../tests/ubx_robot_support/mod.rs"]
mod ubx_robot_support;

use std::hint::black_box;
use std::time::Instant;

use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{GnssMeasurements, UbxRxmRawx, UbxRxmSfrbx};
use adaptive_gnss_ins::ros::ubx_adapter::{UbxAdapter, UbxAdapterParams};
use ubx_robot_support::{driver_messages, walk_log, DriverMessage};

/// Times the log is played per run.
const LOOPS: u16 = 4;
/// Runs.
const REPEATS: usize = 5;
/// svId offsets of the copies of each satellite.
const COPIES: [u8; 4] = [0, 60, 120, 180];

/// The walk's driver messages with every satellite copied under more svIds.
fn multiplied() -> Vec<(u64, DriverMessage)> {
    let (log, tag) = walk_log();
    driver_messages(&log, &tag)
        .into_iter()
        .flat_map(|(ns, m)| match m {
            DriverMessage::Rawx(mut r) => {
                let own = r.rawx_data.clone();
                r.rawx_data = COPIES
                    .iter()
                    .flat_map(|offset| {
                        own.iter().map(move |d| {
                            let mut d = *d;
                            d.sv_id = d.sv_id.saturating_add(*offset);
                            d
                        })
                    })
                    .filter(|d| d.gnss_id != 1 && d.gnss_id != 6)
                    .take(255)
                    .collect();
                r.num_meas = r.rawx_data.len() as u8;
                vec![(ns, DriverMessage::Rawx(r))]
            }
            DriverMessage::Sfrbx(s) => COPIES
                .iter()
                .map(|offset| {
                    let mut s = s.clone();
                    s.sv_id = s.sv_id.saturating_add(*offset);
                    (ns, DriverMessage::Sfrbx(s))
                })
                .collect(),
        })
        .collect()
}

fn rss_kib() -> Option<u64> {
    std::fs::read_to_string("/proc/self/status")
        .ok()?
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

/// One run: the latency (s) of each epoch published with `min_satellites` or more, in
/// order, and the satellites per published epoch; prints the run's counts and memory.
fn run(payloads: &[(u64, bool, Vec<u8>)], min_satellites: usize) -> (Vec<f64>, Vec<usize>) {
    let mut adapter = UbxAdapter::new(UbxAdapterParams::default()).unwrap();
    let mut latencies_s = Vec::new();
    let mut satellites = Vec::new();
    let mut rss = Vec::new();
    for round in 0..LOOPS {
        for (ns, is_rawx, payload) in payloads {
            let arrival_s = *ns as f64 * 1e-9 + f64::from(round) * 604_800.0;
            if !is_rawx {
                let msg: UbxRxmSfrbx = cdr::decode(payload).unwrap();
                adapter.on_sfrbx(&msg);
                continue;
            }
            let t0 = Instant::now();
            let mut msg: UbxRxmRawx = cdr::decode(black_box(payload)).unwrap();
            msg.week += round;
            msg.header.stamp.sec += i32::from(round) * 604_800;
            let out: Option<GnssMeasurements> = adapter.on_rawx(&msg, arrival_s);
            let bytes = out.as_ref().map(|m| cdr::encode(m).unwrap());
            let dt = t0.elapsed().as_secs_f64();
            black_box(bytes);
            if let Some(m) = out {
                if m.satellites.len() >= min_satellites {
                    latencies_s.push(dt);
                }
                satellites.push(m.satellites.len());
            }
        }
        rss.push(rss_kib().unwrap_or(0));
    }
    let c = adapter.counts();
    println!(
        "run: {} epochs published of {} RAWX in {LOOPS} plays; RSS after each play (KiB): \
         {rss:?}",
        c.published, c.rawx
    );
    (latencies_s, satellites)
}

fn main() {
    let messages = multiplied();
    // As received over DDS: CDR payloads.
    let payloads: Vec<(u64, bool, Vec<u8>)> = messages
        .iter()
        .map(|(ns, m)| match m {
            DriverMessage::Rawx(r) => (*ns, true, cdr::encode(r).unwrap()),
            DriverMessage::Sfrbx(s) => (*ns, false, cdr::encode(s).unwrap()),
        })
        .collect();
    let min_satellites = 28;
    let runs: Vec<(Vec<f64>, Vec<usize>)> = (0..REPEATS)
        .map(|_| run(&payloads, min_satellites))
        .collect();
    let mut satellites = runs[0].1.clone();
    satellites.sort_unstable();
    let mut all: Vec<f64> = runs.iter().flat_map(|(l, _)| l.iter().copied()).collect();
    all.sort_by(f64::total_cmp);
    let mut fastest: Vec<f64> = (0..runs[0].0.len())
        .map(|k| runs.iter().map(|(l, _)| l[k]).fold(f64::INFINITY, f64::min))
        .collect();
    fastest.sort_by(f64::total_cmp);
    println!(
        "satellites per published epoch: median {}, max {}; {} epochs with >= \
         {min_satellites} satellites per run",
        satellites[satellites.len() / 2],
        satellites.last().unwrap(),
        fastest.len()
    );
    let ms = |v: f64| v * 1e3;
    for (name, l) in [("all timings", &all), ("fastest of each epoch", &fastest)] {
        println!(
            "RAWX CDR in -> GnssMeasurements CDR out, {name}: p50 {:.3} ms, p99 {:.3} ms, \
             max {:.3} ms",
            ms(percentile(l, 0.5)),
            ms(percentile(l, 0.99)),
            ms(*l.last().unwrap())
        );
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("load average: {}", load.trim());
}
