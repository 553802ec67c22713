//! The `gnss_ins_node` binary over DDS: a second participant publishes a simulated static
//! receiver and checks the node's Odometry against the truth, and its `/tf` (run with
//! `publish_tf` and a `base_frame` of its own) against the Odometry.
//!
//! DDS traffic must stay on this machine: each test re-executes itself inside a private
//! network namespace that has only loopback (`unshare -n`, needs root), where RustDDS
//! discovery still works between processes of the namespace.

mod netns_support;
mod static_node_support;

use std::process::Command;
use std::time::{Duration, Instant};

use adaptive_gnss_ins::earth::{self, Llh};
use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::outbound;
use adaptive_gnss_ins::sim::SimEvent;
use netns_support::reexec_in_private_netns;
use static_node_support::{
    collect_outputs, diagnostic_value, start_node, static_scenario, Outputs, Peer,
};

const DOMAIN_ID: u16 = 17;
/// Position budget of the ekf preset on a static receiver after a minute of 1 Hz GNSS,
/// the same as tests/engine_static.rs (three times the filter's own 3D sigma).
const MAX_STATIC_POSITION_ERR_M: f64 = 7.0;
/// Scenario seconds streamed, and how much faster than real time.
const STREAM_S: f64 = 60.0;
const SPEED_UP: f64 = 20.0;

#[test]
fn node_estimates_a_static_receiver() {
    if reexec_in_private_netns("node_estimates_a_static_receiver") {
        return;
    }
    let scenario = static_scenario();
    let spec = &scenario.spec().trajectory;
    let truth = Llh::from_degrees(spec.start_lat_deg, spec.start_lon_deg, spec.start_height_m);
    let _node = start_node(
        DOMAIN_ID,
        &scenario,
        &[
            "-r",
            "imu:=imu/data",
            "-p",
            "publish_tf:=true",
            "-p",
            "base_frame:=imu_link",
        ],
    );
    let peer = Peer::matched(DOMAIN_ID, "stream_player", "/test/imu/data", false);
    // One bad IMU sample and an empty GNSS epoch first: counted and dropped, the node
    // stays up.
    let (bad_counted, _) = peer.wait_until_inputs_heard();
    let Peer {
        node: _peer,
        imu: imu_pub,
        gnss: gnss_pub,
        odometry: odom_sub,
        diagnostics: diag_sub,
        tf: tf_sub,
        ..
    } = peer;
    let stream = |until_s: f64| {
        let start = Instant::now();
        let (mut imu_sent, mut gnss_sent) = (0u64, 0u64);
        for event in scenario.events() {
            let event = event.unwrap();
            let t_s = event.t_s();
            if t_s > until_s {
                break;
            }
            let due = Duration::from_secs_f64(t_s / SPEED_UP);
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
            let stamp = seconds_to_time(t_s).unwrap();
            match event {
                SimEvent::Imu(s) => {
                    imu_sent += 1;
                    imu_pub
                        .publish(outbound::imu(&s, stamp, "imu_link"))
                        .unwrap()
                }
                SimEvent::Gnss { epoch, .. } => {
                    gnss_sent += 1;
                    gnss_pub
                        .publish(outbound::gnss_measurements(&epoch, 0, stamp, "gnss"))
                        .unwrap()
                }
                _ => {}
            }
        }
        (imu_sent, gnss_sent)
    };
    let (imu_sent, gnss_sent) = stream(STREAM_S);

    // Collect what the node published.
    let Outputs {
        odometry,
        transforms,
        last_diagnostics,
    } = collect_outputs(&odom_sub, &tf_sub, &diag_sub, 3);
    // One Odometry per IMU sample from the initialization at 1 s: about 5900.
    assert!(
        odometry.len() > 5000,
        "only {} Odometry messages received",
        odometry.len()
    );
    for o in &odometry {
        let p = &o.pose.pose.position;
        assert!(
            [p.x, p.y, p.z]
                .iter()
                .chain(o.pose.covariance.iter())
                .all(|v| v.is_finite()),
            "non-finite Odometry {o:?}"
        );
        assert_eq!(o.header.frame_id, "map");
        assert_eq!(o.child_frame_id, "imu_link");
    }
    // /tf: map -> imu_link at each Odometry's stamp, translated to its position.
    assert!(
        transforms.len() > 5000,
        "only {} transforms received",
        transforms.len()
    );
    let mut matched = 0;
    for t in &transforms {
        assert_eq!(t.header.frame_id, "map");
        assert_eq!(t.child_frame_id, "imu_link");
        if let Some(o) = odometry.iter().find(|o| o.header.stamp == t.header.stamp) {
            let p = &o.pose.pose.position;
            let tr = &t.transform.translation;
            assert_eq!(
                [tr.x, tr.y, tr.z],
                [p.x, p.y, p.z],
                "at {:?}",
                t.header.stamp
            );
            assert_eq!(t.transform.rotation, o.pose.pose.orientation);
            matched += 1;
        }
    }
    eprintln!(
        "{} transforms, {matched} matched to an Odometry",
        transforms.len()
    );
    assert!(matched > 5000, "{matched} transforms matched an Odometry");
    let last = odometry.last().unwrap();
    let p = &last.pose.pose.position;
    let truth_enu = earth::llh_to_enu(&truth, &truth);
    let error_m = (nalgebra::Vector3::new(p.x, p.y, p.z) - truth_enu).norm();
    eprintln!(
        "{} Odometry messages; last at t = {} s, position error {error_m:.2} m",
        odometry.len(),
        last.header.stamp.sec
    );
    assert!(
        error_m < MAX_STATIC_POSITION_ERR_M,
        "position error {error_m} m"
    );
    assert!(
        last.header.stamp.sec as f64 > STREAM_S - 2.0,
        "stream not followed to its end"
    );

    let diagnostics = last_diagnostics.expect("no /diagnostics received");
    let value = |key: &str| diagnostic_value(&diagnostics, key);
    eprintln!("diagnostics: {:?}", diagnostics.status[0].values);
    assert_eq!(value("phase").as_deref(), Some("running"));
    let unconvertible: u64 = value("unconvertible_imu").unwrap().parse().unwrap();
    let received: u64 = value("imu_received").unwrap().parse().unwrap();
    assert!(unconvertible >= bad_counted, "the bad samples are counted");
    assert_eq!(
        received - unconvertible,
        imu_sent,
        "every good IMU sample arrived"
    );
    let empty_rejected: u64 = value("rejected_gnss_no_satellites")
        .unwrap()
        .parse()
        .unwrap();
    let gnss_received: u64 = value("gnss_received").unwrap().parse().unwrap();
    assert_eq!(
        gnss_received - empty_rejected,
        gnss_sent,
        "every GNSS epoch arrived"
    );
    assert_eq!(value("time_jump_resets").as_deref(), Some("0"));

    // The bag plays again from its start: the node resets once and carries on.
    stream(5.0);
    let deadline = Instant::now() + Duration::from_secs(3);
    let mut resets = None;
    let mut after = 0;
    while Instant::now() < deadline {
        while let Ok(Some((o, _))) = odom_sub.take() {
            assert!(o.pose.pose.position.x.is_finite(), "{o:?}");
            after += 1;
        }
        while let Ok(Some((d, _))) = diag_sub.take() {
            resets = diagnostic_value(&d, "time_jump_resets");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    eprintln!("{after} Odometry messages after the time jump");
    assert_eq!(resets.as_deref(), Some("1"));
    assert!(after > 0, "no Odometry after the reset");
}

#[test]
fn unknown_argument_is_rejected_with_a_clear_message() {
    let out = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .args(["--ros-args", "--bogus"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("unknown argument `--bogus`"), "{stderr}");
}

/// Issue 16: `gnss_ins_node --help` was an error.
#[test]
fn help_prints_the_usage() {
    for flag in ["--help", "-h"] {
        let out = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
            .arg(flag)
            .output()
            .unwrap();
        assert!(out.status.success(), "{flag}: {out:?}");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.starts_with("Usage: gnss_ins_node"), "{stdout}");
        assert!(
            stdout.contains("--params-file") && stdout.contains("--log-level"),
            "{stdout}"
        );
    }
}

#[test]
fn params_file_for_another_node_is_rejected() {
    // The shipped presets are keyed `/**` (every node); this file names its node.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("named.yaml");
    std::fs::write(
        &file,
        "gnss_ins_node:\n  ros__parameters:\n    filter.variant: ermakf\n",
    )
    .unwrap();
    let params = file.to_str().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .args(["--ros-args", "--params-file", params, "-r", "__node:=other"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("does not address node `/other`"),
        "{stderr}"
    );
}
