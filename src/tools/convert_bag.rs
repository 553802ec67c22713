//! `gnss_ins convert --bag`: a robot's rosbag2 MCAP bag -> the GNSS measurements and IMU
//! samples of our bag. The raw GNSS comes as the u-blox drivers publish it
//! (`ublox_ubx_msgs/UBXRxmRawx` + `UBXRxmSfrbx` of ublox_dgnss, or the byte stream of
//! ublox_gps as `std_msgs/UInt8MultiArray`) and goes through the live
//! [`UbxAdapter`], the bag's log time standing for the node's arrival time; the
//! `sensor_msgs/Imu` messages are copied as recorded (their stamps and frame).

use std::path::PathBuf;

use crate::ros::bag::{BagError, BagReader, TopicInfo};
use crate::ros::cdr;
use crate::ros::msg::{
    GnssMeasurements, Imu, RosMessage, Time, UInt8MultiArray, UbxRxmRawx, UbxRxmSfrbx,
};
use crate::ros::ubx_adapter::{
    ClockReport, LeapSource, UbxAdapter, UbxAdapterCounts, UbxAdapterParamError, UbxAdapterParams,
};

/// ublox_dgnss's RAWX topic (its node at the root namespace).
pub const DEFAULT_RAWX_TOPIC: &str = "/ubx_rxm_rawx";
/// ublox_dgnss's SFRBX topic.
pub const DEFAULT_SFRBX_TOPIC: &str = "/ubx_rxm_sfrbx";
/// ublox_gps's byte-stream topic (`raw_data_stream.publish: true`).
pub const DEFAULT_STREAM_TOPIC: &str = "/raw_data_stream";
/// Choice: the IMU topic most robot IMU drivers publish (REP-145 `imu/data`).
pub const DEFAULT_IMU_TOPIC: &str = "/imu/data";

/// The topics read. Defaults: the drivers' own topic names at the root namespace.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RobotBagTopics {
    /// ublox_dgnss `ubx_rxm_rawx`.
    pub rawx: String,
    /// ublox_dgnss `ubx_rxm_sfrbx`.
    pub sfrbx: String,
    /// ublox_gps `raw_data_stream` (read only when the bag has no RAWX messages).
    pub stream: String,
    /// sensor_msgs/Imu.
    pub imu: String,
}

impl Default for RobotBagTopics {
    fn default() -> Self {
        Self {
            rawx: DEFAULT_RAWX_TOPIC.to_owned(),
            sfrbx: DEFAULT_SFRBX_TOPIC.to_owned(),
            stream: DEFAULT_STREAM_TOPIC.to_owned(),
            imu: DEFAULT_IMU_TOPIC.to_owned(),
        }
    }
}

/// A robot bag to convert.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotBag {
    pub path: PathBuf,
    pub topics: RobotBagTopics,
}

/// Which form of the raw GNSS the bag held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UbxInput {
    /// ublox_dgnss UBXRxmRawx / UBXRxmSfrbx messages.
    DriverMessages,
    /// The receiver's byte stream in UInt8MultiArray chunks.
    ByteStream,
}

/// Why a robot bag could not be converted.
#[derive(Debug, thiserror::Error)]
pub enum RobotBagError {
    #[error(transparent)]
    Bag(#[from] BagError),
    #[error(transparent)]
    Params(#[from] UbxAdapterParamError),
    #[error("topic {topic} holds {found}, expected {expected}")]
    TopicType {
        topic: String,
        found: String,
        expected: &'static str,
    },
    #[error("no u-blox raw GNSS in the bag: no messages on {rawx} nor on {stream}")]
    NoUbx { rawx: String, stream: String },
}

/// What was read.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotBagSummary {
    pub input: UbxInput,
    /// The adapter's counts and clock check.
    pub counts: UbxAdapterCounts,
    pub clock: ClockReport,
    /// GPS − UTC the receiver reported in its last epoch, if it did.
    pub receiver_leap_seconds: Option<i32>,
    /// IMU messages copied, and those skipped (undecodable, or a stamp before 1970).
    pub imu_samples: usize,
    pub imu_skipped: usize,
    /// Problems reading the bag (a corrupt chunk, a truncation): messages lost.
    pub read_errors: usize,
}

/// The converted messages, each with its stamp in ns (the log time to write it at).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RobotBagMessages {
    pub gnss: Vec<(u64, GnssMeasurements)>,
    pub imu: Vec<(u64, Imu)>,
}

/// Nanoseconds since 1970 of a stamp; None before 1970.
fn stamp_ns(stamp: &Time) -> Option<u64> {
    let sec = u64::try_from(stamp.sec).ok()?;
    Some(sec * 1_000_000_000 + u64::from(stamp.nanosec))
}

/// Appends `gnss` with their stamps in ns; the adapter stamps only ROS times, but those
/// before 1970 cannot be written.
fn push_stamped(out: &mut Vec<(u64, GnssMeasurements)>, gnss: Vec<GnssMeasurements>) {
    out.extend(
        gnss.into_iter()
            .filter_map(|m| stamp_ns(&m.header.stamp).map(|ns| (ns, m))),
    );
}

/// Whether `topic` is in the bag with messages, after checking its type.
fn has_messages<T: RosMessage>(topics: &[TopicInfo], topic: &str) -> Result<bool, RobotBagError> {
    match topics.iter().find(|t| t.topic == topic) {
        None => Ok(false),
        Some(t) if t.type_name == T::TYPE_NAME => Ok(t.message_count > 0),
        Some(t) => Err(RobotBagError::TopicType {
            topic: topic.to_owned(),
            found: t.type_name.clone(),
            expected: T::TYPE_NAME,
        }),
    }
}

/// Reads `bag` through a [`UbxAdapter`] with `params`; `progress` is called with the
/// fraction of the bag's messages read.
pub fn read_robot_bag(
    bag: &RobotBag,
    params: UbxAdapterParams,
    mut progress: impl FnMut(f64),
) -> Result<(RobotBagMessages, RobotBagSummary), RobotBagError> {
    let mut adapter = UbxAdapter::new(params)?;
    let reader = BagReader::open(&bag.path)?;
    let topics = &bag.topics;
    let input = if has_messages::<UbxRxmRawx>(reader.topics(), &topics.rawx)? {
        has_messages::<UbxRxmSfrbx>(reader.topics(), &topics.sfrbx)?;
        UbxInput::DriverMessages
    } else if has_messages::<UInt8MultiArray>(reader.topics(), &topics.stream)? {
        UbxInput::ByteStream
    } else {
        return Err(RobotBagError::NoUbx {
            rawx: topics.rawx.clone(),
            stream: topics.stream.clone(),
        });
    };
    has_messages::<Imu>(reader.topics(), &topics.imu)?;
    let mut out = RobotBagMessages::default();
    let (mut imu_skipped, mut read_errors) = (0, 0);
    let mut last_s = 0.0;
    let total: u64 = reader.topics().iter().map(|t| t.message_count).sum();
    for (k, item) in reader.messages()?.enumerate() {
        progress(k as f64 / total.max(1) as f64);
        let Ok(msg) = item else {
            read_errors += 1;
            continue;
        };
        // Choice: the log time (the recorder's receive time) stands for the node's
        // arrival time; the precision of an f64 of UNIX seconds (0.24 µs) is ample.
        let arrival_s = msg.log_time_ns as f64 * 1e-9;
        last_s = arrival_s;
        let topic = msg.topic.as_str();
        if topic == topics.imu {
            match cdr::decode::<Imu>(&msg.data) {
                Ok(imu) => {
                    adapter.on_imu(&imu, arrival_s);
                    match stamp_ns(&imu.header.stamp) {
                        Some(ns) => out.imu.push((ns, imu)),
                        None => imu_skipped += 1,
                    }
                }
                Err(_) => imu_skipped += 1,
            }
            continue;
        }
        let gnss = match input {
            UbxInput::DriverMessages if topic == topics.rawx => {
                match cdr::decode::<UbxRxmRawx>(&msg.data) {
                    Ok(rawx) => adapter.on_rawx(&rawx, arrival_s).into_iter().collect(),
                    Err(e) => {
                        adapter.on_undecodable(topic, &e.to_string());
                        Vec::new()
                    }
                }
            }
            UbxInput::DriverMessages if topic == topics.sfrbx => {
                match cdr::decode::<UbxRxmSfrbx>(&msg.data) {
                    Ok(sfrbx) => adapter.on_sfrbx(&sfrbx),
                    Err(e) => adapter.on_undecodable(topic, &e.to_string()),
                }
                Vec::new()
            }
            UbxInput::ByteStream if topic == topics.stream => {
                match cdr::decode::<UInt8MultiArray>(&msg.data) {
                    Ok(chunk) => adapter.on_stream_chunk(&chunk, arrival_s),
                    Err(e) => {
                        adapter.on_undecodable(topic, &e.to_string());
                        Vec::new()
                    }
                }
            }
            _ => Vec::new(),
        };
        push_stamped(&mut out.gnss, gnss);
    }
    if input == UbxInput::ByteStream {
        push_stamped(&mut out.gnss, adapter.finish_stream(last_s));
    }
    let summary = RobotBagSummary {
        input,
        counts: *adapter.counts(),
        clock: adapter.clock_report(),
        receiver_leap_seconds: adapter
            .leap_seconds()
            .filter(|(_, source)| *source == LeapSource::Receiver)
            .map(|(s, _)| s),
        imu_samples: out.imu.len(),
        imu_skipped,
        read_errors,
    };
    Ok((out, summary))
}
