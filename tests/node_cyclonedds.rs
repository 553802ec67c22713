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

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use netns_support::{reexec_in_private_netns, KillOnDrop};

const DOMAIN_ID: &str = "23";
const NAMESPACE: &str = "/interop";
const NODE: &str = "ins";
/// Playback speed of the 36 s fixture (about 9 s of wall time).
const SPEED_UP: &str = "4";

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The Python interpreter of the test-peer venv; fails (does not skip) without it.
fn venv_python() -> PathBuf {
    let python = manifest_dir().join(".venv/bin/python");
    assert!(
        python.exists(),
        "FAILED, not skipped: {} is missing. Run `bash scripts/setup_test_peers.sh` first \
         (it creates the venv with the pinned cyclonedds and rosbags packages).",
        python.display()
    );
    python
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

fn start_node(extra_args: &[&str]) -> KillOnDrop {
    let node = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .args(["--ros-args", "-r", &format!("__ns:={NAMESPACE}")])
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

fn run_peer(python: &Path, extra_args: &[&str]) {
    let data = manifest_dir().join("tests/data");
    let out = Command::new(python)
        .arg(manifest_dir().join("tools/cyclonedds_peer.py"))
        .arg("--bag")
        .arg(data.join("fixture_small.mcap"))
        .arg("--golden")
        .arg(data.join("fixture_small_solution.csv"))
        .args([
            "--namespace",
            NAMESPACE,
            "--node",
            NODE,
            "--speed",
            SPEED_UP,
        ])
        .args(extra_args)
        .env("ROS_DOMAIN_ID", DOMAIN_ID)
        .stdin(Stdio::null())
        .output()
        .expect("run tools/cyclonedds_peer.py");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("cyclonedds_peer.py summary:\n{stdout}\n{stderr}");
    assert!(
        out.status.success(),
        "the Cyclone DDS peer found problems:\n{stderr}"
    );
    let summary: serde_json::Value = serde_json::from_str(&stdout).expect("JSON summary");
    // The peer's own checks passed; make sure it did check something.
    assert!(summary["odometry"]["count"].as_u64().unwrap_or(0) > 2000);
    assert!(summary["golden"]["matched"].as_u64().unwrap_or(0) > 2000);
    if extra_args.contains(&"--parameters") {
        assert!(summary["parameters"]["listed"].as_u64().unwrap_or(0) > 50);
    }
}

/// The peer first lists, reads, describes and sets parameters through the node's
/// parameter services (leaving them as they were), then plays the bag with its time on
/// /clock (the node runs with use_sim_time) and checks /rosout too.
#[test]
fn cyclonedds_peer_sets_parameters_and_plays_a_bag_into_the_node() {
    let python = venv_python();
    if reexec_in_private_netns("cyclonedds_peer_sets_parameters_and_plays_a_bag_into_the_node") {
        return;
    }
    let _node = start_node(&["-p", "use_sim_time:=true"]);
    run_peer(&python, &["--parameters", "--sim-time"]);
}
