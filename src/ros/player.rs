//! `gnss_ins play`: publishes a recorded bag onto DDS with its original topic names and
//! types, paced by the recorded log times, like `ros2 bag play`.
//!
//! The payloads are not decoded: each message's CDR body is re-published byte for byte,
//! so any message type in the bag plays (not only the ones this package knows), and a
//! subscriber receives exactly what was recorded.
//!
//! Choice: the topic writers are RustDDS data writers created on the node's participant,
//! not ros2-client publishers, because only the RustDDS writer tells when a subscriber
//! matched and when every reliable subscriber acknowledged the last message. The player
//! waits for those acknowledgements before it exits (like `ros2 bag play
//! --wait-for-all-acked`): a message lost on the wire near the end is repaired instead of
//! dying with the process.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{Duration, Instant};

use ros2_client::dds::rustdds::{
    self, no_key::DataWriterCdr, DataWriterStatus, QosPolicies, StatusEvented,
};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile,
};
use serde::ser::SerializeTuple;
use serde::{Serialize, Serializer};

use crate::ros::bag::{BagMessage, BagReader};
use crate::ros::cdr::{CDR_LE, ENCAPSULATION_HEADER_LEN};
use crate::ros::msg::{Clock, RosMessage, Time};

/// Queue depth of the player's reliable publishers.
///
/// Choice: 1000 messages hold several seconds of a 150–200 Hz IMU, so a subscriber that
/// stalls briefly still receives everything over reliable QoS.
pub const PLAYER_QUEUE_DEPTH: usize = 1000;

/// How long `--wait-for` waits for a subscriber before giving up.
pub const WAIT_FOR_SUBSCRIBER_TIMEOUT: Duration = Duration::from_secs(30);

/// How long the player waits, after the last message of a pass, for every reliable
/// subscriber to acknowledge what it was sent. Choice: RustDDS repeats its heartbeat
/// every 100 ms while data is unacknowledged, so 5 s is many repair rounds; a subscriber
/// that is gone or stalled longer only delays the exit, with a warning.
pub const ACKNOWLEDGEMENT_TIMEOUT: Duration = Duration::from_secs(5);

/// Poll period while waiting for a subscriber to match.
const MATCH_POLL_PERIOD: Duration = Duration::from_millis(20);

/// A data writer that publishes recorded CDR bodies unchanged.
type RawWriter = DataWriterCdr<RawCdrBody>;

/// How the bag is played.
#[derive(Debug, Clone)]
pub struct PlayOptions {
    /// Speed factor: 2.0 plays twice as fast as recorded.
    pub rate: f64,
    /// Publish `/clock` (rosgraph_msgs/Clock) with the bag's time, for `use_sim_time`.
    pub clock: bool,
    /// Rate of `/clock` in bag time (Hz) when `clock` is set.
    pub clock_hz: f64,
    /// Play again from the start when the bag ends, until the process is stopped.
    pub repeat: bool,
    /// Wall time to wait after the publishers are created, before the first message.
    pub delay: Duration,
    /// Bag time skipped at the start of each pass (`ros2 bag play --start-offset`): a
    /// recording joined in its middle, as after a crash or a re-launch.
    pub start_offset: Duration,
    /// Topics that must have a matched subscriber before playing starts.
    pub wait_for_topics: Vec<String>,
    /// DDS domain (`ROS_DOMAIN_ID`).
    pub domain_id: u16,
}

/// What one pass over the bag did.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct PlayReport {
    /// Messages published, per topic.
    pub published: BTreeMap<String, u64>,
    /// Messages not published, with the reason.
    pub skipped: BTreeMap<String, u64>,
    /// Passes over the bag completed.
    pub passes: u64,
}

/// Why playing failed.
#[derive(Debug, thiserror::Error)]
pub enum PlayError {
    #[error("{0}")]
    Bag(#[from] crate::ros::bag::BagError),
    #[error("cannot create the DDS participant, node or publisher: {0}")]
    Dds(String),
    #[error("topic `{topic}` has type `{type_name}`, not a ROS 2 `package/msg/Name`")]
    TypeName { topic: String, type_name: String },
    #[error("invalid topic name `{0}`")]
    TopicName(String),
    #[error("--rate must lie in [{MIN_RATE}, {MAX_RATE}], got {0}")]
    Rate(f64),
    #[error("--clock-hz must lie in [{MIN_CLOCK_HZ}, {MAX_CLOCK_HZ}], got {0}")]
    ClockRate(f64),
    #[error("--wait-for {0}: the bag has no such topic")]
    UnknownWaitTopic(String),
    #[error("--wait-for {0}: no subscriber matched within {1:?}")]
    NoSubscriber(String, Duration),
}

/// A CDR body re-published as it is: serializing writes the bytes with no length and
/// no alignment, so the subscriber sees the recorded body unchanged.
#[derive(Debug)]
struct RawCdrBody(Vec<u8>);

impl Serialize for RawCdrBody {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut tuple = serializer.serialize_tuple(self.0.len())?;
        for byte in &self.0 {
            tuple.serialize_element(byte)?;
        }
        tuple.end()
    }
}

/// The little-endian CDR body of a recorded payload, or why it cannot be re-published
/// as it is (DDS writers here emit little-endian CDR).
fn little_endian_body(data: &[u8]) -> Result<&[u8], &'static str> {
    match data.split_at_checked(ENCAPSULATION_HEADER_LEN) {
        Some((header, body)) if header[..2] == CDR_LE => Ok(body),
        Some(_) => Err("not little-endian CDR"),
        None => Err("shorter than the CDR header"),
    }
}

/// `package/msg/Name` → the DDS type name parts.
fn message_type_name(type_name: &str) -> Option<MessageTypeName> {
    let mut parts = type_name.split('/');
    match (parts.next(), parts.next(), parts.next(), parts.next()) {
        (Some(package), Some("msg"), Some(name), None)
            if !package.is_empty() && !name.is_empty() =>
        {
            Some(MessageTypeName::new(package, name))
        }
        _ => None,
    }
}

/// Slowest and fastest speed factors. Choice: a thousandth of real time already turns a
/// second of recording into a quarter of an hour, and a thousand times real time is
/// beyond what DDS delivers for a 200 Hz IMU without loss; outside, the release times
/// overflow a `Duration` (a rate of 1e-300) or collapse to zero.
pub const MIN_RATE: f64 = 1e-3;
pub const MAX_RATE: f64 = 1e3;
/// Slowest and fastest `/clock` rates (Hz of bag time): 1e4 Hz is 0.1 ms of bag time per
/// tick, finer than any consumer's timer; below 0.01 Hz the clock would barely move.
pub const MIN_CLOCK_HZ: f64 = 1e-2;
pub const MAX_CLOCK_HZ: f64 = 1e4;

/// Wall-clock offset from the start of a pass at which a message recorded `since_start`
/// after the bag's first message is released, at speed `rate`.
pub fn release_offset(since_start: Duration, rate: f64) -> Duration {
    since_start.div_f64(rate)
}

fn ros_time(log_time_ns: u64) -> Time {
    Time {
        sec: i32::try_from(log_time_ns / 1_000_000_000).unwrap_or(i32::MAX),
        nanosec: (log_time_ns % 1_000_000_000) as u32,
    }
}

fn dds_error(e: impl std::fmt::Debug) -> PlayError {
    PlayError::Dds(format!("{e:?}"))
}

fn reliable_qos() -> QosProfile {
    QosProfile::publisher_default().history(ros2_client::qos::History::KeepLast {
        depth: PLAYER_QUEUE_DEPTH,
    })
}

fn create_topic(
    node: &Node,
    topic: &str,
    type_name: MessageTypeName,
) -> Result<rustdds::Topic, PlayError> {
    let name = Name::parse(topic).map_err(|_| PlayError::TopicName(topic.to_owned()))?;
    node.create_topic(&name, type_name, &reliable_qos())
        .map_err(dds_error)
}

fn create_writer<M: Serialize>(
    publisher: &rustdds::Publisher,
    topic: &rustdds::Topic,
) -> Result<DataWriterCdr<M>, PlayError> {
    publisher
        .create_datawriter_no_key::<M, _>(topic, Some(QosPolicies::from(&reliable_qos())))
        .map_err(dds_error)
}

/// Plays `bag` onto DDS; returns when the bag has played (never with `repeat`, unless
/// the bag cannot be read).
///
/// `progress` is called before each message with the pass (0 the first) and the
/// fraction of the bag's messages that pass has played.
pub fn play(
    bag: &Path,
    options: &PlayOptions,
    mut progress: impl FnMut(u64, f64),
) -> Result<PlayReport, PlayError> {
    if !(MIN_RATE..=MAX_RATE).contains(&options.rate) {
        return Err(PlayError::Rate(options.rate));
    }
    if options.clock && !(MIN_CLOCK_HZ..=MAX_CLOCK_HZ).contains(&options.clock_hz) {
        return Err(PlayError::ClockRate(options.clock_hz));
    }
    let reader = BagReader::open(bag)?;
    let context = Context::with_options(ContextOptions::new().domain_id(options.domain_id))
        .map_err(dds_error)?;
    let node = context
        .new_node(
            NodeName::new("/", "gnss_ins_player").map_err(dds_error)?,
            NodeOptions::new()
                .enable_rosout(false)
                .start_parameter_services(false),
        )
        .map_err(dds_error)?;

    let dds_publisher = context
        .domain_participant()
        .create_publisher(&QosPolicies::from(&reliable_qos()))
        .map_err(dds_error)?;
    let mut writers = BTreeMap::new();
    for info in reader.topics() {
        let type_name = message_type_name(&info.type_name).ok_or_else(|| PlayError::TypeName {
            topic: info.topic.clone(),
            type_name: info.type_name.clone(),
        })?;
        let topic = create_topic(&node, &info.topic, type_name)?;
        let writer = create_writer::<RawCdrBody>(&dds_publisher, &topic)?;
        log::info!("playing {} ({})", info.topic, info.type_name);
        writers.insert(info.topic.clone(), writer);
    }
    let clock = if options.clock {
        let type_name = message_type_name(Clock::TYPE_NAME)
            .ok_or_else(|| PlayError::Dds("bad Clock type name".to_owned()))?;
        let topic = create_topic(&node, "/clock", type_name)?;
        Some(create_writer::<Clock>(&dds_publisher, &topic)?)
    } else {
        None
    };

    wait_for_subscribers(&writers, options)?;
    std::thread::sleep(options.delay);

    let mut report = PlayReport::default();
    loop {
        let pass = report.passes;
        let mut progress = |f| progress(pass, f);
        play_once(
            &reader,
            &writers,
            clock.as_ref(),
            options,
            &mut report,
            &mut progress,
        )?;
        wait_for_acknowledgements(&writers);
        report.passes += 1;
        if !options.repeat {
            return Ok(report);
        }
    }
}

/// Waits until every reliable subscriber of every topic acknowledged all it was sent,
/// at most [`ACKNOWLEDGEMENT_TIMEOUT`] in all; warns about the topics still unacknowledged.
fn wait_for_acknowledgements(writers: &BTreeMap<String, RawWriter>) {
    let deadline = Instant::now() + ACKNOWLEDGEMENT_TIMEOUT;
    for (topic, writer) in writers {
        let left = deadline.saturating_duration_since(Instant::now());
        match writer.wait_for_acknowledgments(left) {
            Ok(true) => {}
            Ok(false) => log::warn!(
                "{topic}: not every subscriber acknowledged the last messages within {ACKNOWLEDGEMENT_TIMEOUT:?}"
            ),
            Err(e) => log::warn!("{topic}: cannot wait for acknowledgements: {e:?}"),
        }
    }
}

/// Waits until every `--wait-for` topic's writer has matched a subscriber, as its
/// RustDDS status reports it.
fn wait_for_subscribers(
    writers: &BTreeMap<String, RawWriter>,
    options: &PlayOptions,
) -> Result<(), PlayError> {
    let deadline = Instant::now() + WAIT_FOR_SUBSCRIBER_TIMEOUT;
    for topic in &options.wait_for_topics {
        let writer = writers
            .get(topic)
            .ok_or_else(|| PlayError::UnknownWaitTopic(topic.clone()))?;
        while !subscriber_matched(writer) {
            if Instant::now() >= deadline {
                return Err(PlayError::NoSubscriber(
                    topic.clone(),
                    WAIT_FOR_SUBSCRIBER_TIMEOUT,
                ));
            }
            std::thread::sleep(MATCH_POLL_PERIOD);
        }
        log::info!("{topic}: subscriber matched");
    }
    Ok(())
}

/// Whether the writer's pending status events include a match with a subscriber.
fn subscriber_matched(writer: &RawWriter) -> bool {
    let mut matched = false;
    while let Some(status) = writer.try_recv_status() {
        if let DataWriterStatus::PublicationMatched { current, .. } = status {
            matched |= current.count() > 0;
        }
    }
    matched
}

fn count(map: &mut BTreeMap<String, u64>, key: &str) {
    *map.entry(key.to_owned()).or_default() += 1;
}

/// One pass over the bag in log-time order (file order for a bag without an index).
fn play_once(
    reader: &BagReader,
    writers: &BTreeMap<String, RawWriter>,
    clock: Option<&DataWriterCdr<Clock>>,
    options: &PlayOptions,
    report: &mut PlayReport,
    progress: &mut dyn FnMut(f64),
) -> Result<(), PlayError> {
    let started = Instant::now();
    let total: u64 = reader.topics().iter().map(|t| t.message_count).sum();
    let mut bag_start_ns = None;
    let mut first_ns = None;
    let offset_ns = u64::try_from(options.start_offset.as_nanos()).unwrap_or(u64::MAX);
    let mut last_clock_ns: Option<u64> = None;
    let clock_period_ns = if options.clock {
        (1e9 / options.clock_hz) as u64
    } else {
        u64::MAX
    };
    for (k, message) in reader.messages()?.enumerate() {
        progress(k as f64 / total.max(1) as f64);
        let BagMessage {
            topic,
            log_time_ns,
            data,
            ..
        } = match message {
            Ok(m) => m,
            Err(e) => {
                log::warn!(
                    "{}: {e}; the rest of the bag is skipped",
                    reader.path().display()
                );
                count(&mut report.skipped, "unreadable bag record");
                break;
            }
        };
        let bag_start = *bag_start_ns.get_or_insert(log_time_ns);
        if log_time_ns < bag_start.saturating_add(offset_ns) {
            continue;
        }
        let first = *first_ns.get_or_insert(log_time_ns);
        let since_start = Duration::from_nanos(log_time_ns.saturating_sub(first));
        let due = started + release_offset(since_start, options.rate);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        if let Some(clock) = clock {
            let clock_due = last_clock_ns
                .is_none_or(|last| log_time_ns.saturating_sub(last) >= clock_period_ns);
            if clock_due {
                last_clock_ns = Some(log_time_ns);
                let time = ros_time(log_time_ns);
                if let Err(e) = clock.write(Clock { clock: time }, None) {
                    log::warn!("/clock: publish failed: {e:?}");
                }
            }
        }
        let Some(writer) = writers.get(&topic) else {
            count(&mut report.skipped, "topic not in the bag's summary");
            continue;
        };
        match little_endian_body(&data) {
            Ok(body) => match writer.write(RawCdrBody(body.to_vec()), None) {
                Ok(()) => count(&mut report.published, &topic),
                Err(e) => {
                    log::warn!("{topic}: publish failed: {e:?}");
                    count(&mut report.skipped, "publish failed");
                }
            },
            Err(reason) => {
                log::warn!("{topic}: a payload is {reason}; skipped");
                count(&mut report.skipped, reason);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_body_serializes_unchanged() {
        let body = vec![1u8, 0, 0, 0, 0xAB, 0, 0, 0, 0, 0, 0xF0, 0x3F];
        let encoded = crate::ros::cdr::encode(&RawCdrBody(body.clone())).unwrap();
        assert_eq!(&encoded[ENCAPSULATION_HEADER_LEN..], &body[..]);
    }

    #[test]
    fn payload_header_checks() {
        assert_eq!(little_endian_body(&[0, 1, 0, 0, 7]), Ok(&[7u8][..]));
        assert!(little_endian_body(&[0, 0, 0, 0, 7]).is_err());
        assert!(little_endian_body(&[0, 1]).is_err());
    }

    #[test]
    fn type_names() {
        assert_eq!(
            message_type_name("sensor_msgs/msg/Imu")
                .unwrap()
                .dds_msg_type(),
            "sensor_msgs::msg::dds_::Imu_"
        );
        assert!(message_type_name("sensor_msgs/Imu").is_none());
        assert!(message_type_name("a/srv/B").is_none());
    }

    #[test]
    fn rates_outside_their_range_are_refused_before_the_bag_is_opened() {
        let options = |rate: f64, clock_hz: f64| PlayOptions {
            rate,
            clock: true,
            clock_hz,
            repeat: false,
            delay: Duration::ZERO,
            start_offset: Duration::ZERO,
            wait_for_topics: Vec::new(),
            domain_id: 0,
        };
        let missing = Path::new("/nonexistent/bag.mcap");
        for rate in [1e-300, 0.0, -1.0, f64::NAN, f64::INFINITY, 1e300] {
            let err = play(missing, &options(rate, 100.0), |_, _| {}).unwrap_err();
            assert!(matches!(err, PlayError::Rate(_)), "rate {rate}: {err}");
        }
        for clock_hz in [1e-300, 0.0, f64::NAN, 1e300] {
            let err = play(missing, &options(1.0, clock_hz), |_, _| {}).unwrap_err();
            assert!(
                matches!(err, PlayError::ClockRate(_)),
                "clock {clock_hz}: {err}"
            );
        }
        // At the limits the release offsets stay finite.
        let hour = Duration::from_secs(3600);
        assert_eq!(
            release_offset(hour, MIN_RATE),
            Duration::from_secs(3_600_000)
        );
        assert_eq!(release_offset(hour, MAX_RATE), Duration::from_millis(3600));
    }

    #[test]
    fn pacing_scales_with_rate() {
        let t = Duration::from_secs(10);
        assert_eq!(release_offset(t, 2.0), Duration::from_secs(5));
        assert_eq!(release_offset(t, 0.5), Duration::from_secs(20));
    }
}
