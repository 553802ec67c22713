//! `gnss_ins_node` with a genuine ROS 2 Jazzy peer: rclpy on Fast DDS (rmw_fastrtps_cpp,
//! Jazzy's default middleware), from the ROS 2 Jazzy wheels on PyPI pinned in
//! tools/requirements-test-peers.txt. The peers (tools/jazzy_*.py) use rclpy's own message
//! types, serialization, QoS, parameter client and discovery, so what they send and expect
//! is what a Jazzy system sends and expects:
//! - a loosely-coupled bag played by rclpy with its time on /clock: every Odometry and
//!   NavSatFix equals `gnss_ins replay`'s to the bit, /diagnostics and /rosout carry the
//!   /clock times sent;
//! - rclpy's parameter client lists, gets, types, describes and sets the parameters;
//! - a 200 Hz Imu stamped at x.0025 s (and odd nanoseconds): one output per sample, near its
//!   stamp, with the stamp mismatch and the latency reported.
//!
//! Needs the venv made by `scripts/setup_test_peers.sh` (the README's test command and CI
//! run it first); without it the tests fail and say so. Everything runs inside a private
//! network namespace with only loopback.

mod netns_support;
mod venv_support;

use std::path::Path;
use std::process::{Command, Stdio};

use serde_json::Value;

use netns_support::{reexec_in_private_netns, KillOnDrop};

const DOMAIN_ID: &str = "26";
const NAMESPACE: &str = "/jazzy";
const NODE: &str = "ins";
/// The node and the peer: Fast DDS's service layout, and the only middleware the venv has.
const RMW: &str = "rmw_fastrtps_cpp";

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn start_node(args: &[&str]) -> KillOnDrop {
    let node = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .args(["--ros-args", "-r", &format!("__ns:={NAMESPACE}")])
        .args(["-r", &format!("__node:={NODE}")])
        .args(args)
        .env("ROS_DOMAIN_ID", DOMAIN_ID)
        .env("RMW_IMPLEMENTATION", RMW)
        .env("RUST_LOG", "info,rustdds=error,ros2_client=error")
        .stdin(Stdio::null())
        .spawn()
        .expect("start gnss_ins_node");
    KillOnDrop(node)
}

/// Runs `tools/<script>` against the node; returns its JSON summary after asserting that
/// none of its checks failed.
fn run_peer(python: &Path, script: &str, args: &[&str]) -> Value {
    let out = Command::new(python)
        .arg(manifest_dir().join("tools").join(script))
        .args(["--namespace", NAMESPACE, "--node", NODE])
        .args(args)
        .env("ROS_DOMAIN_ID", DOMAIN_ID)
        .env("RMW_IMPLEMENTATION", RMW)
        .stdin(Stdio::null())
        .output()
        .expect("run the rclpy peer");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{script} summary:\n{stdout}\n{stderr}");
    assert!(
        out.status.success(),
        "the rclpy peer found problems:\n{stderr}"
    );
    let summary: Value = serde_json::from_str(&stdout).expect("JSON summary");
    assert_eq!(summary["rmw"], RMW, "the peer's middleware");
    summary
}

fn gnss_ins(args: &[&str]) {
    let status = Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .args(args)
        .stdout(Stdio::null())
        .status()
        .expect("run gnss_ins");
    assert!(status.success(), "gnss_ins {args:?}: {status}");
}

/// The fixture's scenario simulated with receiver fixes and velocities, replayed loosely
/// coupled, and the same bag played by rclpy into the node with the same parameter file:
/// the peer finds every one of replay's Odometry and NavSatFix messages, equal to the bit,
/// and the node's /diagnostics and /rosout stamped with the /clock times it sent.
#[test]
fn jazzy_rclpy_plays_a_bag_and_receives_the_replay_solution() {
    let python = venv_support::python();
    if reexec_in_private_netns("jazzy_rclpy_plays_a_bag_and_receives_the_replay_solution") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let (bag, replayed, params) = (path("loose.mcap"), path("replay.mcap"), path("loose.yaml"));
    // A `/**` parameter file for both: the defaults but loose coupling.
    std::fs::write(
        &params,
        "/**:\n  ros__parameters:\n    filter:\n      coupling: loose\n",
    )
    .unwrap();
    let scenario = manifest_dir().join("tests/data/fixture_small.yaml");
    let scenario = scenario.to_str().unwrap();
    gnss_ins(&[
        "simulate",
        "--scenario",
        scenario,
        "--velocity",
        "--out",
        &bag,
    ]);
    gnss_ins(&["replay", &bag, "--params", &params, "--out", &replayed]);

    let _node = start_node(&["--params-file", &params, "-p", "use_sim_time:=true"]);
    let summary = run_peer(
        &python,
        "jazzy_bag_peer.py",
        &["--bag", &bag, "--replay", &replayed, "--sim-time"],
    );
    // The peer's own checks passed; make sure it did check something.
    assert!(summary["odometry"]["received"].as_u64().unwrap_or(0) > 2000);
    assert!(
        summary["sim_time"]["diagnostics_on_clock"]
            .as_u64()
            .unwrap_or(0)
            >= 3
    );
}

/// rclpy's AsyncParameterClient (what `ros2 param` uses) against the node's parameter
/// services in Fast DDS's request/reply layout: lists, values, types, a description for
/// every parameter, an accepted set, sets refused with their reasons (read-only, out of
/// range, wrong type) and an all-or-nothing atomic set; each accepted set is announced on
/// `/parameter_events` with its value, a refused one not at all.
#[test]
fn jazzy_parameter_client_lists_describes_and_sets_parameters() {
    let python = venv_support::python();
    if reexec_in_private_netns("jazzy_parameter_client_lists_describes_and_sets_parameters") {
        return;
    }
    let _node = start_node(&[]);
    let summary = run_peer(
        &python,
        "jazzy_parameters.py",
        &["--require-parameter-events"],
    );
    // One /parameter_events message per accepted set, with the value set (issue 16).
    let events = &summary["parameter_events"];
    assert_eq!(events["events"], 2, "{summary}");
    assert_eq!(events["announced"][0][0][1], 12.5, "{summary}");
    assert!(summary["listed"].as_u64().unwrap_or(0) > 50, "{summary}");
    let reason = summary["refused_read_only"].as_str().unwrap_or_default();
    assert!(reason.contains("read-only"), "{reason}");
}

/// A 200 Hz Imu at rest from rclpy, stamped in 2025 at x.0025 s and (every other sample)
/// one nanosecond later, with a 5 Hz fix, into the loosely-coupled node: every sample from
/// the start on gets one Odometry and one NavSatFix carrying exactly its stamp
/// (`--exact-stamps`; issue 16, item 3); the latency is printed.
#[test]
fn jazzy_imu_at_200_hz_gets_one_output_per_sample_at_its_stamp() {
    let python = venv_support::python();
    if reexec_in_private_netns("jazzy_imu_at_200_hz_gets_one_output_per_sample_at_its_stamp") {
        return;
    }
    let _node = start_node(&[
        "-p",
        "filter.coupling:=loose",
        "-p",
        "init.heading_deg:=90.0",
    ]);
    let summary = run_peer(
        &python,
        "jazzy_stamps.py",
        &["--duration-s", "8", "--exact-stamps"],
    );
    assert!(summary["odometry_stamps"]["count"].as_u64().unwrap_or(0) > 1000);
}
