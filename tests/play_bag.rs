//! `gnss_ins play` over DDS: a subscriber in this process receives every Imu and
//! GnssMeasurements message of the fixture bag, unchanged and in order, and /clock
//! follows the bag's time; and the bag played into `gnss_ins_node --record` gives the
//! Odometry that `gnss_ins replay` computes from the same bag, tightly coupled and (on a
//! simulated bag with `/gnss/velocity`) loosely coupled with receiver velocities, and in
//! `tf_mode` `map_to_odom` (a bag with a base controller's `/tf`) the same `map → odom`.
//!
//! DDS traffic stays on this machine: the test re-executes itself inside a private
//! network namespace that has only loopback (`unshare -n`, needs root).

mod netns_support;
mod odometry_support;
mod tf_support;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::convert::time_to_seconds;
use adaptive_gnss_ins::ros::msg::{
    Clock, DiagnosticArray, GnssMeasurements, Imu, NavSatFix, Odometry, RosMessage, TFMessage,
    Time, TransformStamped,
};
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::bag_run::BagRun;
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::{simulate_with, SimulateOptions};
use netns_support::reexec_in_private_netns;
use odometry_support::{assert_live_matches_replay, decoded, largest_difference, SAME};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile,
    Subscription,
};

const DOMAIN_ID: u16 = 23;
/// Playing speed: the 36 s fixture plays in 9 s.
const RATE: f64 = 4.0;
/// `--delay` of the player, seconds. `--wait-for` only knows that the player's writer has
/// matched the subscriber; the subscriber's side of the match completes on its own, and
/// a message that arrives before it is dropped there and repaired only while the
/// player's history still holds it. A loaded CI machine once lost the first Imu message
/// that way, so the player waits as a user of `ros2 bag play --delay` would.
const PLAYER_DELAY_S: &str = "2";

fn fixture() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixture_small.mcap")
}

/// The recorded payloads of `topic` (encapsulation header + CDR body), in log-time order.
fn recorded(topic: &str) -> Vec<Vec<u8>> {
    let reader = BagReader::open(fixture()).unwrap();
    reader
        .messages()
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.topic == topic)
        .map(|m| m.data)
        .collect()
}

/// Received messages encoded again: byte equality with the recorded payloads (a field
/// comparison would fail on the NaN that marks an unavailable value).
fn encoded<M: RosMessage>(messages: &[M]) -> Vec<Vec<u8>> {
    messages.iter().map(|m| cdr::encode(m).unwrap()).collect()
}

fn subscribe<M: RosMessage + 'static>(node: &mut Node, topic: &str) -> Subscription<M> {
    let parts: Vec<&str> = M::TYPE_NAME.split('/').collect();
    let qos = QosProfile::subscription_default()
        .history(ros2_client::qos::History::KeepLast { depth: 10_000 });
    let topic = node
        .create_topic(
            &Name::parse(topic).unwrap(),
            MessageTypeName::new(parts[0], parts[2]),
            &qos,
        )
        .unwrap();
    node.create_subscription::<M>(&topic, Some(qos)).unwrap()
}

fn drain<M: RosMessage + 'static>(subscription: &Subscription<M>, into: &mut Vec<M>) {
    while let Ok(Some((message, _))) = subscription.take() {
        into.push(message);
    }
}

/// Received payloads equal the recorded ones; a failure names the first difference.
fn assert_same_messages(what: &str, got: &[Vec<u8>], want: &[Vec<u8>]) {
    let first_difference = got.iter().zip(want).position(|(g, w)| g != w);
    assert!(
        got.len() == want.len() && first_difference.is_none(),
        "{what}: received {} of {} messages, first difference at index {:?}",
        got.len(),
        want.len(),
        first_difference.or((got.len() != want.len()).then_some(got.len().min(want.len())))
    );
}

#[test]
fn play_publishes_the_bag_unchanged() {
    if reexec_in_private_netns("play_publishes_the_bag_unchanged") {
        return;
    }
    let context = Context::with_options(ContextOptions::new().domain_id(DOMAIN_ID)).unwrap();
    let mut node = context
        .new_node(
            NodeName::new("/", "play_listener").unwrap(),
            NodeOptions::new()
                .enable_rosout(false)
                .start_parameter_services(false),
        )
        .unwrap();
    let imu_sub = subscribe::<Imu>(&mut node, "/imu");
    let gnss_sub = subscribe::<GnssMeasurements>(&mut node, "/gnss/measurements");
    let clock_sub = subscribe::<Clock>(&mut node, "/clock");

    let mut player = Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .arg("play")
        .arg(fixture())
        .args(["--rate", &RATE.to_string(), "--clock"])
        .args(["--wait-for", "/imu", "--wait-for", "/gnss/measurements"])
        .args(["--delay", PLAYER_DELAY_S])
        .env("ROS_DOMAIN_ID", DOMAIN_ID.to_string())
        .env("RUST_LOG", "warn,rustdds=error")
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();

    let (mut imu, mut gnss, mut clock) = (Vec::new(), Vec::new(), Vec::new());
    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        drain(&imu_sub, &mut imu);
        drain(&gnss_sub, &mut gnss);
        drain(&clock_sub, &mut clock);
        if let Some(status) = player.try_wait().unwrap() {
            break status;
        }
        assert!(Instant::now() < deadline, "gnss_ins play did not finish");
        std::thread::sleep(Duration::from_millis(5));
    };
    assert!(status.success(), "gnss_ins play failed: {status}");
    // Reliable delivery: what is still in flight arrives shortly after the player ends.
    let want_imu = recorded("/imu");
    let want_gnss = recorded("/gnss/measurements");
    let settle = Instant::now() + Duration::from_secs(5);
    while (imu.len() < want_imu.len() || gnss.len() < want_gnss.len()) && Instant::now() < settle {
        drain(&imu_sub, &mut imu);
        drain(&gnss_sub, &mut gnss);
        std::thread::sleep(Duration::from_millis(10));
    }
    drain(&clock_sub, &mut clock);

    assert_same_messages("Imu", &encoded(&imu), &want_imu);
    assert_same_messages("GnssMeasurements", &encoded(&gnss), &want_gnss);

    let seconds = |c: &Clock| time_to_seconds(&c.clock).unwrap();
    let first_imu = &imu[0].header.stamp;
    let last_imu = &imu[imu.len() - 1].header.stamp;
    let bag_start = f64::from(first_imu.sec) + f64::from(first_imu.nanosec) * 1e-9;
    let bag_end = f64::from(last_imu.sec) + f64::from(last_imu.nanosec) * 1e-9;
    // 40 Hz of bag time over a 36 s bag, less what was published before the subscriber
    // matched (none: the player waited for the IMU subscriber on the same node).
    assert!(clock.len() > 1000, "{} /clock messages", clock.len());
    assert!(
        clock.windows(2).all(|w| seconds(&w[1]) > seconds(&w[0])),
        "/clock goes backwards"
    );
    let (c0, c1) = (seconds(&clock[0]), seconds(&clock[clock.len() - 1]));
    assert!(
        (c0 - bag_start).abs() < 1.0 && (c1 - bag_end).abs() < 1.0,
        "/clock spans {c0}..{c1}, the bag's IMU {bag_start}..{bag_end}"
    );
}

#[test]
fn node_records_the_replay_solution_of_a_played_bag() {
    if reexec_in_private_netns("node_records_the_replay_solution_of_a_played_bag") {
        return;
    }
    node_records_the_replay_solution(&fixture(), &[], &["/imu", "/gnss/measurements"], 1);
}

/// The loosely-coupled node with receiver velocities has its offline twin: the fixture's
/// scenario simulated with `/gnss/velocity`, played into the loosely-coupled node (the
/// `ekf_loose` preset: the defaults but `filter.coupling`), gives the Odometry of
/// `gnss_ins replay` (which joins each velocity with its fix by the node's code, whichever
/// of the two arrives first).
#[test]
fn loose_node_with_velocities_records_the_replay_solution() {
    if reexec_in_private_netns("loose_node_with_velocities_records_the_replay_solution") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("velocity.mcap");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let yaml = std::fs::read_to_string(root.join("tests/data/fixture_small.yaml")).unwrap();
    let scenario = Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), 1).unwrap();
    let summary = simulate_with(&scenario, &bag, SimulateOptions { velocity: true }).unwrap();
    assert!(summary.velocities > 30, "{summary:?}");
    let replayed = node_records_the_replay_solution(
        &bag,
        &[("filter.coupling", "loose")],
        &["/imu", "/gnss/fix", "/gnss/velocity"],
        2,
    );
    assert_eq!(replayed.velocities().paired, summary.velocities as u64);
}

/// Starts `gnss_ins_node --record recorded --ros-args node_args` on domain `domain`, plays
/// `bag` into it with `play_args` (after the player's `--delay`), and stops the node with
/// SIGINT, as Ctrl-C: it completes the recording and must exit cleanly.
fn record_node_playing(
    bag: &Path,
    recorded: &Path,
    node_args: &[String],
    play_args: &[&str],
    domain: &str,
) {
    let node = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .arg("--record")
        .arg(recorded)
        .arg("--ros-args")
        .args(node_args)
        .env("ROS_DOMAIN_ID", domain)
        .env("RUST_LOG", "info,rustdds=error,ros2_client=warn")
        .spawn()
        .unwrap();
    let status = Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .arg("play")
        .arg(bag)
        .args(play_args)
        .args(["--delay", PLAYER_DELAY_S])
        .env("ROS_DOMAIN_ID", domain)
        .env("RUST_LOG", "warn,rustdds=error")
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "gnss_ins play failed: {status}");
    std::thread::sleep(Duration::from_secs(1));
    let kill = Command::new("kill")
        .args(["-INT", &node.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let mut node = node;
    let exit = node.wait().unwrap();
    assert!(exit.success(), "the node did not stop cleanly: {exit}");
}

/// Plays `bag` into `gnss_ins_node --record` (the default parameters but `overrides`,
/// domain `DOMAIN_ID + domain_offset`) and checks its Odometry against `gnss_ins replay`
/// of the bag with the same parameters; returns the replay's result.
fn node_records_the_replay_solution(
    bag: &Path,
    overrides: &[(&str, &str)],
    wait_for: &[&str],
    domain_offset: u16,
) -> BagRun {
    let dir = tempfile::tempdir().unwrap();
    let recorded = dir.path().join("node.mcap");
    let replayed = dir.path().join("replay.mcap");
    let domain = (DOMAIN_ID + domain_offset).to_string();
    let mut node_args = vec!["-r".to_owned(), "__node:=recorder_test".to_owned()];
    for (name, value) in overrides {
        node_args.extend(["-p".to_owned(), format!("{name}:={value}")]);
    }
    let mut play_args = vec!["--rate", "2"];
    play_args.extend(wait_for.iter().flat_map(|t| ["--wait-for", t]));
    record_node_playing(bag, &recorded, &node_args, &play_args, &domain);

    let topics: Vec<String> = BagReader::open(&recorded)
        .unwrap()
        .topics()
        .iter()
        .map(|t| t.topic.clone())
        .collect();
    for want in [
        "/odometry",
        "/fix/filtered",
        "/gnss_ins_node/noise_estimates",
        "/diagnostics",
    ] {
        let want = want.replace("gnss_ins_node", "recorder_test");
        assert!(topics.contains(&want), "{want} not recorded: {topics:?}");
    }

    let mut config = Config::default();
    for (name, value) in overrides {
        config.set_parameter(name, value).unwrap();
    }
    let result = replay(
        bag,
        &config,
        TruthSource::None,
        &ReplayOptions {
            out_bag: Some(&replayed),
            ..ReplayOptions::default()
        },
        |_| {},
    )
    .unwrap();
    let live = decoded::<Odometry>(&recorded, "/odometry");
    let offline = decoded::<Odometry>(&replayed, "/odometry");
    let counts = last_counts(&recorded);
    let late = last_diagnostic(&recorded, "late_measurements");
    let what = format!("node vs replay (the node's last counts: {counts})");
    let compared =
        assert_live_matches_replay(&live, &offline, &measurement_stamps_s(bag), late, &what);
    println!("{what}: {compared:?}");
    result
}

/// The stamps (s) of the GNSS inputs of `bag` (`/gnss/measurements`, `/gnss/fix`), sorted.
fn measurement_stamps_s(bag: &Path) -> Vec<f64> {
    let seconds = |t: &Time| time_to_seconds(t).unwrap();
    let mut stamps: Vec<f64> = decoded::<GnssMeasurements>(bag, "/gnss/measurements")
        .iter()
        .map(|m| seconds(&m.header.stamp))
        .chain(
            decoded::<NavSatFix>(bag, "/gnss/fix")
                .iter()
                .map(|f| seconds(&f.header.stamp)),
        )
        .collect();
    stamps.sort_by(f64::total_cmp);
    stamps
}

/// The value of `key` in the node's last /diagnostics in `recorded`.
fn last_diagnostic(recorded: &Path, key: &str) -> u64 {
    let last = decoded::<DiagnosticArray>(recorded, "/diagnostics")
        .pop()
        .expect("no /diagnostics recorded");
    let value = last
        .status
        .iter()
        .flat_map(|s| &s.values)
        .find(|kv| kv.key == key);
    value
        .unwrap_or_else(|| panic!("no {key} on /diagnostics"))
        .value
        .parse()
        .unwrap()
}

/// The input counts (received, paired, rejected) of the node's last /diagnostics in
/// `recorded`, the non-zero ones, to tell a sample lost in transport from a difference in
/// the processing.
fn last_counts(recorded: &Path) -> String {
    let Some(last) = decoded::<DiagnosticArray>(recorded, "/diagnostics").pop() else {
        return "no /diagnostics recorded".to_owned();
    };
    last.status
        .iter()
        .flat_map(|status| &status.values)
        .filter(|kv| {
            ["received", "paired", "rejected"]
                .iter()
                .any(|word| kv.key.contains(word))
                && kv.value != "0"
        })
        .map(|kv| format!("{}={}", kv.key, kv.value))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The node's `/tf` in `tf_mode` `map_to_odom` has its offline twin (issue 16, item 2): a
/// bag of the static receiver with a stand-in base controller's `odom → base_link` on
/// `/tf` (logged ahead of the IMU, tests/tf_support), played into the node started with
/// a parameter file, gives the `map → odom` that `gnss_ins replay` of the bag with the same
/// file writes: the same transforms at the same stamps, equal within 1e-9.
#[test]
fn node_records_the_replay_tf_in_map_to_odom_mode() {
    if reexec_in_private_netns("node_records_the_replay_tf_in_map_to_odom_mode") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("controller.mcap");
    let scenario = tf_support::static_scenario();
    tf_support::write_controller_bag(&bag, &scenario, 20.0, 200_000_000);
    let node_file = dir.path().join("node.yaml");
    let map_to_odom = "    publish_tf: true\n    tf_mode: map_to_odom\n";
    tf_support::write_node_parameters(&node_file, &scenario, map_to_odom);
    let recorded = dir.path().join("node.mcap");
    let replayed = dir.path().join("replay.mcap");
    let node_args: Vec<String> = [
        "-r",
        "__node:=tf_test",
        "--params-file",
        tf_support::PRESET,
        "--params-file",
        node_file.to_str().unwrap(),
    ]
    .map(str::to_owned)
    .to_vec();
    let play_args = [
        "--rate",
        "2",
        "--wait-for",
        "/imu",
        "--wait-for",
        "/gnss/measurements",
        "--wait-for",
        "/tf",
    ];
    record_node_playing(
        &bag,
        &recorded,
        &node_args,
        &play_args,
        &(DOMAIN_ID + 4).to_string(),
    );
    let status = Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .arg("replay")
        .arg(&bag)
        .args(["--params", tf_support::PRESET, "--params"])
        .arg(&node_file)
        .arg("--out")
        .arg(&replayed)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "replay failed: {status}");

    let live = decoded::<Odometry>(&recorded, "/odometry");
    let offline = decoded::<Odometry>(&replayed, "/odometry");
    let late = last_diagnostic(&recorded, "late_measurements");
    let compared = assert_live_matches_replay(
        &live,
        &offline,
        &measurement_stamps_s(&bag),
        late,
        "node vs replay",
    );
    println!("{compared:?}");
    let transforms = |bag: &Path| -> Vec<TransformStamped> {
        decoded::<TFMessage>(bag, "/tf")
            .into_iter()
            .flat_map(|m| m.transforms)
            .filter(|t| t.header.frame_id == "map")
            .collect()
    };
    let (live_tf, offline_tf) = (transforms(&recorded), transforms(&replayed));
    assert!(live.len() > 1500, "{} Odometry recorded", live.len());
    assert_eq!(live_tf.len(), live.len(), "one map -> odom per Odometry");
    assert_eq!(
        live_tf.len(),
        offline_tf.len(),
        "map -> odom: node vs replay"
    );
    let mut worst_tf = 0.0f64;
    for (k, (a, b)) in live_tf.iter().zip(&offline_tf).enumerate() {
        assert_eq!(a.header, b.header);
        if largest_difference(&live[k], &offline[k]) > SAME {
            continue; // published before a late measurement arrived (checked above)
        }
        assert_eq!(a.child_frame_id, b.child_frame_id);
        let d = tf_support::transform_of(a).inverse() * tf_support::transform_of(b);
        worst_tf = worst_tf
            .max(d.translation.vector.norm())
            .max(d.rotation.angle());
    }
    println!(
        "node vs replay: {} map -> odom, largest difference {worst_tf:e}",
        live_tf.len()
    );
    assert!(
        worst_tf <= SAME,
        "node and replay map -> odom differ by {worst_tf}"
    );
}

/// A drive for joining in its middle: 10 s at rest, then 10 m/s in a steady turn of 3 deg/s
/// from 20 to 60 s, cruising and turning again; tactical IMU, 1 Hz GNSS, open sky.
const MID_DRIVE_SCENARIO: &str = "
name: mid_drive
trajectory:
  start_lat_deg: 39.10
  start_lon_deg: 117.20
  start_height_m: 10.0
  start_yaw_deg: 90.0
  transition_s: 2.0
  segments:
    - { kind: stationary, duration_s: 10.0 }
    - { kind: speed_to, duration_s: 10.0, speed_m_s: 10.0 }
    - { kind: turn, duration_s: 40.0, yaw_change_deg: 120.0 }
    - { kind: cruise, duration_s: 40.0 }
    - { kind: turn, duration_s: 20.0, yaw_change_deg: -60.0 }
    - { kind: cruise, duration_s: 20.0 }
truth_rate_hz: 5.0
imu:
  rate_hz: 100.0
gnss:
  rate_hz: 1.0
  start_gps_s: 10800.0
environments: []
";
/// Where the player joins the drive: in the steady turn at 10 m/s.
const JOIN_AT_S: &str = "30";
/// How long after the first played message the node must have converged (issue 11).
const CONVERGED_AFTER_S: f64 = 60.0;

fn yaw_rad(o: &Odometry) -> f64 {
    let q = &o.pose.pose.orientation;
    (2.0 * (q.w * q.z + q.x * q.y)).atan2(1.0 - 2.0 * (q.y * q.y + q.z * q.z))
}

fn stamp_ns(o: &Odometry) -> i64 {
    i64::from(o.header.stamp.sec) * 1_000_000_000 + i64::from(o.header.stamp.nanosec)
}

/// Issue 11: a bag played into the node from its middle (a re-launch during a drive:
/// moving at 10 m/s in a turn, no rest to level on) converges as a start at rest does:
/// from 60 s after the first message on, every solution at a truth epoch is within 3
/// sigma of the truth in position and within 1 deg in yaw.
#[test]
fn node_joining_a_drive_in_its_middle_converges_to_the_truth() {
    if reexec_in_private_netns("node_joining_a_drive_in_its_middle_converges_to_the_truth") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("mid_drive.mcap");
    let recorded = dir.path().join("node.mcap");
    let scenario = Scenario::new(ScenarioSpec::from_yaml(MID_DRIVE_SCENARIO).unwrap(), 5).unwrap();
    simulate_with(&scenario, &bag, SimulateOptions { velocity: false }).unwrap();
    let spec = &scenario.spec().trajectory;
    let datum = format!(
        "output.datum_llh_deg_m:=[{}, {}, {}]",
        spec.start_lat_deg, spec.start_lon_deg, spec.start_height_m
    );
    let domain = (DOMAIN_ID + 3).to_string();
    let node_args = ["-r", "__node:=mid_drive_test", "-p", &datum].map(str::to_owned);
    record_node_playing(
        &bag,
        &recorded,
        &node_args,
        &[
            "--rate",
            "5",
            "--start-offset",
            JOIN_AT_S,
            "--wait-for",
            "/imu",
            "--wait-for",
            "/gnss/measurements",
        ],
        &domain,
    );

    let truth: std::collections::HashMap<i64, Odometry> =
        decoded::<Odometry>(&bag, "/ground_truth")
            .into_iter()
            .map(|o| (stamp_ns(&o), o))
            .collect();
    let live = decoded::<Odometry>(&recorded, "/odometry");
    // The player's offset counts from the bag's start, the scenario's.
    let join_ns = scenario.clock().utc_ns(JOIN_AT_S.parse::<f64>().unwrap());
    let first_ns = stamp_ns(live.first().expect("the node published no Odometry"));
    assert!(
        first_ns >= join_ns,
        "a solution before the join: {first_ns} ns"
    );
    let (mut judged, mut worst_sigmas, mut worst_yaw_deg) = (0, 0.0f64, 0.0f64);
    for o in &live {
        let t_ns = stamp_ns(o);
        if t_ns < join_ns + (CONVERGED_AFTER_S * 1e9) as i64 {
            continue;
        }
        let Some(true_o) = truth.get(&t_ns) else {
            continue;
        };
        let (p, q) = (&o.pose.pose.position, &true_o.pose.pose.position);
        let error_m = ((p.x - q.x).powi(2) + (p.y - q.y).powi(2) + (p.z - q.z).powi(2)).sqrt();
        let c = &o.pose.covariance;
        let sigma_m = (c[0] + c[7] + c[14]).sqrt();
        let yaw_deg = (yaw_rad(o) - yaw_rad(true_o))
            .sin()
            .atan2((yaw_rad(o) - yaw_rad(true_o)).cos())
            .to_degrees()
            .abs();
        worst_sigmas = worst_sigmas.max(error_m / sigma_m);
        worst_yaw_deg = worst_yaw_deg.max(yaw_deg);
        judged += 1;
    }
    println!(
        "joined at {JOIN_AT_S} s: {} solutions, {judged} judged from {CONVERGED_AFTER_S} s \
         on; worst position error {worst_sigmas:.2} sigma, worst yaw error {worst_yaw_deg:.3} deg",
        live.len()
    );
    assert!(judged > 200, "only {judged} solutions at truth epochs");
    assert!(worst_sigmas <= 3.0, "position {worst_sigmas} sigma off");
    assert!(worst_yaw_deg < 1.0, "yaw {worst_yaw_deg} deg off");
}
