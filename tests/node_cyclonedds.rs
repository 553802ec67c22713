//! Interoperability of `gnss_ins_node` with an independent DDS implementation: Eclipse
//! Cyclone DDS (PyPI `cyclonedds`, pinned in tools/requirements-test-peers.txt) plays the
//! committed fixture bag into the node and checks everything the node publishes
//! (tools/cyclonedds_peer.py; its types are written by hand in
//! tools/cyclonedds_ros_types.py, not derived from the node's structs), and uses the
//! node's parameter services as an rmw_cyclonedds client would (tools/parameter_client.py).
//!
//! Needs the venv made by `scripts/setup_test_peers.sh` (the README's test command and CI
//! run it first); without it the test fails and says so. Everything runs inside a private
//! network namespace with only loopback.

mod netns_support;
mod venv_support;

use std::path::Path;
use std::process::{Command, Stdio};

use serde_json::Value;

use netns_support::{reexec_in_private_netns, KillOnDrop};

const DOMAIN_ID: &str = "23";
const NODE: &str = "ins";
/// Playback speed of the 36 s fixture (about 9 s of wall time).
const SPEED_UP: &str = "4";
/// The GNSS epoch the peer sends late (tools/cyclonedds_peer.py --late-epoch): the
/// fixture's 16th, 5 s after the one the filter starts with.
const LATE_EPOCH: &str = "15";

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The datum of the fixture's truth, from the scenario the bag was simulated from.
fn fixture_datum() -> String {
    let text = std::fs::read_to_string(manifest_dir().join("tests/data/fixture_small.yaml"))
        .expect("fixture scenario");
    let spec: serde_yaml::Value = serde_yaml::from_str(&text).expect("fixture scenario YAML");
    let t = &spec["trajectory"];
    let number = |key: &str| {
        t[key]
            .as_f64()
            .unwrap_or_else(|| panic!("trajectory.{key}"))
    };
    format!(
        "output.datum_llh_deg_m:=[{}, {}, {}]",
        number("start_lat_deg"),
        number("start_lon_deg"),
        number("start_height_m")
    )
}

fn start_node(namespace: &str, extra_args: &[&str]) -> KillOnDrop {
    let node = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .args(["--ros-args", "-r", &format!("__ns:={namespace}")])
        .args(["-r", &format!("__node:={NODE}")])
        .args(["-p", &fixture_datum()])
        .args(extra_args)
        .env("ROS_DOMAIN_ID", DOMAIN_ID)
        .env("RMW_IMPLEMENTATION", "rmw_cyclonedds_cpp")
        .env("RUST_LOG", "info,rustdds=error,ros2_client=error")
        .stdin(Stdio::null())
        .spawn()
        .expect("start gnss_ins_node");
    KillOnDrop(node)
}

/// Runs `tools/<script>` against the node in `namespace`; returns its JSON summary after
/// asserting that none of its checks failed.
fn run_peer(python: &Path, script: &str, namespace: &str, extra_args: &[&str]) -> Value {
    let out = Command::new(python)
        .arg(manifest_dir().join("tools").join(script))
        .arg("--bag")
        .arg(manifest_dir().join("tests/data/fixture_small.mcap"))
        .args([
            "--namespace",
            namespace,
            "--node",
            NODE,
            "--speed",
            SPEED_UP,
        ])
        .args(extra_args)
        .env("ROS_DOMAIN_ID", DOMAIN_ID)
        .stdin(Stdio::null())
        .output()
        .expect("run the Cyclone DDS peer");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{script} summary:\n{stdout}\n{stderr}");
    assert!(
        out.status.success(),
        "the Cyclone DDS peer found problems:\n{stderr}"
    );
    serde_json::from_str(&stdout).expect("JSON summary")
}

/// The peer first lists, reads, describes and sets parameters through the node's
/// parameter services (leaving them as they were; each accepted set announced on
/// /parameter_events), then plays the bag with its time on
/// /clock (the node runs with use_sim_time) and checks every output, /rosout too, and
/// that every solution equals `gnss_ins replay`'s (tests/data/fixture_small_solution.csv)
/// but those the node published before a measurement that came late (after the IMU had
/// passed its stamp: DDS has no order across topics) arrived, as in tests/late_delivery.rs.
#[test]
fn cyclonedds_peer_sets_parameters_and_plays_a_bag_into_the_node() {
    let python = venv_support::python();
    if reexec_in_private_netns("cyclonedds_peer_sets_parameters_and_plays_a_bag_into_the_node") {
        return;
    }
    let _node = start_node("/interop", &["-p", "use_sim_time:=true"]);
    let golden = manifest_dir().join("tests/data/fixture_small_solution.csv");
    let golden = golden.to_str().expect("UTF-8 path");
    let summary = run_peer(
        &python,
        "cyclonedds_peer.py",
        "/interop",
        &[
            "--parameters",
            "--sim-time",
            "--golden",
            golden,
            "--late-epoch",
            LATE_EPOCH,
        ],
    );
    // The peer's own checks passed; make sure it did check something.
    assert!(summary["odometry"]["count"].as_u64().unwrap_or(0) > 2000);
    assert!(summary["golden"]["matched"].as_u64().unwrap_or(0) > 2000);
    // The held-back epoch came late and was applied by a roll-back.
    assert!(
        summary["golden"]["late_runs"].as_u64().unwrap_or(0) >= 1,
        "{}",
        summary["golden"]
    );
    assert!(summary["parameters"]["listed"].as_u64().unwrap_or(0) > 50);
    let announced = &summary["parameters"]["parameter_events"]["announced"];
    assert_eq!(
        announced.as_array().map(Vec::len),
        Some(2),
        "one /parameter_events event per accepted set: {announced}"
    );
}

/// Undecodable payloads, wrong array sizes, NaN, repeated and backward stamps, GNSS before
/// any IMU and a second IMU publisher with another frame: all counted in /diagnostics,
/// the node keeps running and publishes no NaN (tools/cyclonedds_bad_inputs.py).
#[test]
fn cyclonedds_peer_bad_inputs_are_counted_and_the_node_carries_on() {
    let python = venv_support::python();
    if reexec_in_private_netns("cyclonedds_peer_bad_inputs_are_counted_and_the_node_carries_on") {
        return;
    }
    let _node = start_node("/bad", &[]);
    let summary = run_peer(&python, "cyclonedds_bad_inputs.py", "/bad", &[]);
    assert!(summary["odometry"].as_u64().unwrap_or(0) > 2000);
    let sent = &summary["bad_samples_sent"];
    assert!(sent["foreign_frame"].as_u64().unwrap_or(0) > 5, "{sent}");
}
