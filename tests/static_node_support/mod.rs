//! The set-up of the DDS tests that stream the simulated static receiver into the
//! `gnss_ins_node` binary (node_ros, node_tf): the node on the ekf preset with the datum
//! at the scenario's start and a known heading, and a ros2-client peer with the node's
//! inputs and outputs, matched within 20 s. Call from inside the private network
//! namespace (netns_support).
#![allow(dead_code)]

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use adaptive_gnss_ins::ros::convert::seconds_to_time;
use adaptive_gnss_ins::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, Odometry, RosMessage, TFMessage,
};
use adaptive_gnss_ins::ros::outbound;
use adaptive_gnss_ins::sim::Scenario;
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, Publisher, QosProfile,
    Subscription,
};

use crate::netns_support::KillOnDrop;

/// The scenario the node is started for.
pub fn static_scenario() -> Scenario {
    Scenario::builtin("static", 3).unwrap()
}

/// The node in namespace /test on `domain_id` for `scenario`, with `extra` ROS arguments
/// (`-r`, `-p`) after the preset's.
pub fn start_node(domain_id: u16, scenario: &Scenario, extra: &[&str]) -> KillOnDrop {
    let spec = &scenario.spec().trajectory;
    let params = concat!(env!("CARGO_MANIFEST_DIR"), "/params/defaults.yaml");
    let datum = format!(
        "output.datum_llh_deg_m:=[{}, {}, {}]",
        spec.start_lat_deg, spec.start_lon_deg, spec.start_height_m
    );
    let node = Command::new(env!("CARGO_BIN_EXE_gnss_ins_node"))
        .args(["--ros-args", "--params-file", params])
        .args(["-p", "init.heading_deg:=0.0", "-p", &datum])
        .args(["-r", "__ns:=/test", "-p", "queue_depth:=500"])
        .args(extra)
        .env("ROS_DOMAIN_ID", domain_id.to_string())
        .env("RUST_LOG", "info,rustdds=error,ros2_client=warn")
        .stdin(Stdio::null())
        .spawn()
        .unwrap();
    KillOnDrop(node)
}

/// The DDS type name of `M`.
pub fn type_name<M: RosMessage>() -> MessageTypeName {
    let parts: Vec<&str> = M::TYPE_NAME.split('/').collect();
    MessageTypeName::new(parts[0], parts[2])
}

/// The test's participant: publishers of the node's inputs, subscriptions of its outputs.
pub struct Peer {
    pub node: ros2_client::Node,
    pub imu: Publisher<Imu>,
    pub gnss: Publisher<GnssMeasurements>,
    /// On /tf, for a peer that stands in for a base controller.
    pub tf_out: Option<Publisher<TFMessage>>,
    pub odometry: Subscription<Odometry>,
    pub diagnostics: Subscription<DiagnosticArray>,
    pub tf: Subscription<TFMessage>,
}

impl Peer {
    /// A peer called `name` in /test on `domain_id`, publishing the IMU on `imu_topic`
    /// (and on /tf when `publishes_tf`), spinning, and matched with the node within 20 s
    /// (panics otherwise).
    pub fn matched(domain_id: u16, name: &str, imu_topic: &str, publishes_tf: bool) -> Peer {
        let context = Context::with_options(ContextOptions::new().domain_id(domain_id)).unwrap();
        let mut node = context
            .new_node(
                NodeName::new("/test", name).unwrap(),
                NodeOptions::new()
                    .enable_rosout(false)
                    .start_parameter_services(false),
            )
            .unwrap();
        let reliable = QosProfile::publisher_default()
            .history(ros2_client::qos::History::KeepLast { depth: 20_000 });
        let topic = |node: &mut ros2_client::Node, name: &str, t: MessageTypeName| {
            node.create_topic(&Name::parse(name).unwrap(), t, &reliable)
                .unwrap()
        };
        let imu_topic = topic(&mut node, imu_topic, type_name::<Imu>());
        let gnss_topic = topic(
            &mut node,
            "/test/gnss/measurements",
            type_name::<GnssMeasurements>(),
        );
        let odom_topic = topic(&mut node, "/test/odometry", type_name::<Odometry>());
        let diag_topic = topic(&mut node, "/diagnostics", type_name::<DiagnosticArray>());
        let tf_topic = topic(&mut node, "/tf", type_name::<TFMessage>());
        let mut peer = Peer {
            imu: node.create_publisher(&imu_topic, None).unwrap(),
            gnss: node.create_publisher(&gnss_topic, None).unwrap(),
            tf_out: publishes_tf.then(|| node.create_publisher(&tf_topic, None).unwrap()),
            odometry: node.create_subscription(&odom_topic, None).unwrap(),
            diagnostics: node.create_subscription(&diag_topic, None).unwrap(),
            tf: node.create_subscription(&tf_topic, None).unwrap(),
            node,
        };
        let spinner = peer.node.spinner().unwrap();
        std::thread::spawn(move || smol::block_on(spinner.spin()));
        let matched = smol::block_on(async {
            let wait = async {
                peer.imu.wait_for_subscription(&peer.node).await;
                peer.gnss.wait_for_subscription(&peer.node).await;
                if let Some(tf_out) = &peer.tf_out {
                    tf_out.wait_for_subscription(&peer.node).await;
                }
                peer.odometry.wait_for_publisher(&peer.node).await;
                peer.tf.wait_for_publisher(&peer.node).await;
                true
            };
            futures::select! {
                ok = futures::FutureExt::fuse(wait) => ok,
                _ = futures::FutureExt::fuse(smol::Timer::after(Duration::from_secs(20))) => false,
            }
        });
        assert!(matched, "the node's topics were not discovered within 20 s");
        peer
    }

    /// A reliable publisher of `M` on `topic` (another input of the node).
    pub fn publisher<M: RosMessage + serde::Serialize>(&mut self, topic: &str) -> Publisher<M> {
        let topic = self
            .node
            .create_topic(
                &Name::parse(topic).unwrap(),
                type_name::<M>(),
                &QosProfile::publisher_default(),
            )
            .unwrap();
        self.node.create_publisher::<M>(&topic, None).unwrap()
    }

    /// Our side having matched does not mean the node's readers have matched our writers
    /// yet (best effort drops what it sends before): sends an IMU sample with a NaN
    /// (dropped as unconvertible) and an empty GNSS epoch (rejected for having no
    /// satellites) until the node's diagnostics count both, which proves both input paths
    /// are up. Returns the two counts then; panics after 20 s.
    pub fn wait_until_inputs_heard(&self) -> (u64, u64) {
        let bad = outbound::imu(
            &adaptive_gnss_ins::ins::ImuSample {
                t_s: 0.0,
                w_ib_b_rad_s: nalgebra::Vector3::new(f64::NAN, 0.0, 0.0),
                f_ib_b_m_s2: nalgebra::Vector3::zeros(),
            },
            seconds_to_time(0.0).unwrap(),
            "imu_link",
        );
        let empty = GnssMeasurements::default();
        let deadline = Instant::now() + Duration::from_secs(20);
        let (mut bad_counted, mut empty_counted) = (0, 0);
        while bad_counted == 0 || empty_counted == 0 {
            assert!(
                Instant::now() < deadline,
                "the node never reported the bad IMU sample and the empty GNSS epoch"
            );
            self.imu.publish(bad.clone()).unwrap();
            self.gnss.publish(empty.clone()).unwrap();
            std::thread::sleep(Duration::from_millis(250));
            while let Ok(Some((d, _))) = self.diagnostics.take() {
                bad_counted = diagnostic_count(&d, "unconvertible_imu").unwrap_or(0);
                empty_counted = diagnostic_count(&d, "rejected_gnss_no_satellites").unwrap_or(0);
            }
        }
        (bad_counted, empty_counted)
    }
}

/// The value of `key` in the node's /diagnostics report `d`.
pub fn diagnostic_value(d: &DiagnosticArray, key: &str) -> Option<String> {
    d.status[0]
        .values
        .iter()
        .find(|kv| kv.key == key)
        .map(|kv| kv.value.clone())
}

/// The counter `key` of the node's /diagnostics report `d`.
pub fn diagnostic_count(d: &DiagnosticArray, key: &str) -> Option<u64> {
    diagnostic_value(d, key).and_then(|v| v.parse().ok())
}

/// Calls `publish_round` every 250 ms until the newest /diagnostics `peer` heard passes
/// `done`, and returns that report; panics after 20 s (our side having matched does not
/// mean the node's reader has matched our writer yet, so a round is repeated).
pub fn publish_until_counted(
    peer: &mut Peer,
    mut publish_round: impl FnMut(),
    done: impl Fn(&DiagnosticArray) -> bool,
) -> DiagnosticArray {
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut last: Option<DiagnosticArray> = None;
    loop {
        if let Some(d) = last.take_if(|d| done(d)) {
            return d;
        }
        assert!(
            Instant::now() < deadline,
            "the node never counted what was published: {last:?}"
        );
        publish_round();
        std::thread::sleep(Duration::from_millis(250));
        while let Ok(Some((d, _))) = peer.diagnostics.take() {
            last = Some(d);
        }
    }
}

/// What the node published in the last few seconds: every Odometry and transform, and
/// the newest /diagnostics.
pub struct Outputs {
    pub odometry: Vec<Odometry>,
    pub transforms: Vec<adaptive_gnss_ins::ros::msg::TransformStamped>,
    pub last_diagnostics: Option<DiagnosticArray>,
}

/// Takes what the subscriptions receive for `for_s` seconds (the node's queues draining
/// after the stream ended).
pub fn collect_outputs(
    odometry: &Subscription<Odometry>,
    tf: &Subscription<TFMessage>,
    diagnostics: &Subscription<DiagnosticArray>,
    for_s: u64,
) -> Outputs {
    let deadline = std::time::Instant::now() + Duration::from_secs(for_s);
    let mut out = Outputs {
        odometry: Vec::new(),
        transforms: Vec::new(),
        last_diagnostics: None,
    };
    while std::time::Instant::now() < deadline {
        while let Ok(Some((o, _))) = odometry.take() {
            out.odometry.push(o);
        }
        while let Ok(Some((t, _))) = tf.take() {
            out.transforms.extend(t.transforms);
        }
        while let Ok(Some((d, _))) = diagnostics.take() {
            out.last_diagnostics = Some(d);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    out
}
