//! The parameters of `gnss_ins_ubx_node`, declared once in [`UBX_NODE_PARAMETERS`] (the
//! parameter services, `docs/parameters.md` and the launch file's list come from it), and
//! read from the values the command line's files and rules give the node.

use serde_yaml::Value;

use crate::config::manual::{table, Row};
use crate::config::{Assignment, ConfigError, Kind};
use crate::gnss::ionosphere::IonosphereMode;
use crate::ros::args::{is_valid_topic_name, NodeArgs};
use crate::ros::node::params::{
    boolean, depth, frame, refused, resolved, NodeParameter, ParamsError, QUEUE_DEPTH,
    QUEUE_DEPTH_PARAMETER, USE_SIM_TIME, USE_SIM_TIME_PARAMETER,
};
use crate::ros::ubx_adapter::{TimeBase, UbxAdapterParamError, UbxAdapterParams};

pub const TIME_BASE: &str = "time_base";
pub const LEAP_SECONDS: &str = "leap_seconds";
pub const HOST_LATENCY_S: &str = "host_latency_s";
pub const MAX_IMU_GNSS_SKEW_S: &str = "max_imu_gnss_skew_s";
pub const IONOSPHERE: &str = "ionosphere";
pub const FRAME_ID: &str = "frame_id";
pub const OFFSET_WINDOW_EPOCHS: &str = "offset_window_epochs";
pub const RAWX_TOPIC: &str = "rawx_topic";
pub const SFRBX_TOPIC: &str = "sfrbx_topic";
pub const STREAM_TOPIC: &str = "stream_topic";
pub const IMU_TOPIC: &str = "imu_topic";
pub const MEASUREMENTS_TOPIC: &str = "measurements_topic";

const TOPIC_RANGE: &str = "a topic name (relative, absolute or ~/private)";

/// Every parameter of `gnss_ins_ubx_node`. The adapter's come with the ranges
/// [`UbxAdapterParams::validate`] checks; see its fields for the choices behind the
/// defaults.
///
/// Choice: only `use_sim_time` changes while the node runs. The clock check's windows and
/// the ephemeris store are built for one time base and ionosphere choice, and a topic
/// changed at run time would leave the DDS entities of the old one; a restart is clearer.
pub const UBX_NODE_PARAMETERS: [NodeParameter; 14] = [
    USE_SIM_TIME_PARAMETER,
    QUEUE_DEPTH_PARAMETER,
    NodeParameter {
        name: TIME_BASE,
        kind: Kind::Text,
        default: "gnss",
        range: "gnss or host",
        runtime: false,
        doc: "Clock of the published stamps: gnss = the receiver's epoch, GPST - leap \
              seconds (UTC, for IMU stamps on a PTP/NTP-synced host); host = the driver's \
              receive stamp minus host_latency_s.",
    },
    NodeParameter {
        name: LEAP_SECONDS,
        kind: Kind::Integer,
        default: "18",
        range: "an integer in [0, 60] (s)",
        runtime: false,
        doc: "GPS - UTC (s), used while the receiver does not report valid leap seconds.",
    },
    NodeParameter {
        name: HOST_LATENCY_S,
        kind: Kind::Double,
        default: "0.035",
        range: "in [0, 1] s",
        runtime: false,
        doc: "Receiver epoch to host receive stamp (s): subtracted in time_base host, and the \
              offset the clock check expects (35 ms: a u-blox F9 at 4 Hz on walk_0827).",
    },
    NodeParameter {
        name: MAX_IMU_GNSS_SKEW_S,
        kind: Kind::Double,
        default: "0.01",
        range: "in (0, 10] s",
        runtime: false,
        doc: "Warn on /diagnostics when IMU and GNSS stamps disagree by more than this on \
              average (10 ms at 20 m/s is 0.2 m).",
    },
    NodeParameter {
        name: IONOSPHERE,
        kind: Kind::Text,
        default: "iono_free",
        range: "iono_free, broadcast or none",
        runtime: false,
        doc: "One ionosphere-free pair per satellite, or one signal with (broadcast) or \
              without (none) the Klobuchar model, as gnss_ins convert --ionosphere.",
    },
    NodeParameter {
        name: FRAME_ID,
        kind: Kind::Text,
        default: "gnss_antenna",
        range: "a frame id (non-empty, no spaces)",
        runtime: false,
        doc: "header.frame_id of the published measurements: the antenna frame.",
    },
    NodeParameter {
        name: OFFSET_WINDOW_EPOCHS,
        kind: Kind::Integer,
        default: "100",
        range: "an integer in [2, 10000]",
        runtime: false,
        doc: "Epochs over which the receiver-to-host offset, its jitter and the IMU/GNSS \
              skew are averaged.",
    },
    NodeParameter {
        name: RAWX_TOPIC,
        kind: Kind::Text,
        default: "ubx_rxm_rawx",
        range: TOPIC_RANGE,
        runtime: false,
        doc: "ublox_ubx_msgs/UBXRxmRawx input (ublox_dgnss); remappings apply to it.",
    },
    NodeParameter {
        name: SFRBX_TOPIC,
        kind: Kind::Text,
        default: "ubx_rxm_sfrbx",
        range: TOPIC_RANGE,
        runtime: false,
        doc: "ublox_ubx_msgs/UBXRxmSfrbx input (ublox_dgnss).",
    },
    NodeParameter {
        name: STREAM_TOPIC,
        kind: Kind::Text,
        default: "ubx_raw",
        range: TOPIC_RANGE,
        runtime: false,
        doc: "std_msgs/UInt8MultiArray input: the receiver's byte stream (ublox_gps \
              raw_data_stream).",
    },
    NodeParameter {
        name: IMU_TOPIC,
        kind: Kind::Text,
        default: "imu",
        range: TOPIC_RANGE,
        runtime: false,
        doc: "sensor_msgs/Imu input, for the IMU/GNSS clock check only.",
    },
    NodeParameter {
        name: MEASUREMENTS_TOPIC,
        kind: Kind::Text,
        default: "gnss/measurements",
        range: TOPIC_RANGE,
        runtime: false,
        doc: "GnssMeasurements output (gnss_ins_node's input).",
    },
];

/// The section of `docs/parameters.md` on `gnss_ins_ubx_node`.
pub fn reference_section() -> String {
    let mut text = String::from(
        "\n## `gnss_ins_ubx_node`\n\nThe parameters of the u-blox adapter node (declared in \
         `src/ros/ubx_node/params.rs`); it has no others and refuses the filter's. Topic \
         names resolve as any (namespace, then remappings).\n\n",
    );
    let rows: Vec<Row> = UBX_NODE_PARAMETERS.iter().map(NodeParameter::row).collect();
    table(&mut text, &rows);
    text
}

/// The node's topics, relative to its namespace unless absolute.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UbxTopics {
    pub rawx: String,
    pub sfrbx: String,
    pub stream: String,
    pub imu: String,
    pub measurements: String,
}

/// What the command line configures.
#[derive(Debug, Clone, PartialEq)]
pub struct UbxNodeParams {
    pub adapter: UbxAdapterParams,
    pub topics: UbxTopics,
    pub use_sim_time: bool,
    pub queue_depth: usize,
}

/// Why the parameters are refused.
#[derive(Debug, thiserror::Error)]
pub enum UbxParamsError {
    #[error(transparent)]
    Params(#[from] ParamsError),
    #[error("{origin}: `{name}` is no parameter of gnss_ins_ubx_node (see --help)")]
    Unknown { origin: String, name: String },
    #[error("{origin}: parameter {source}")]
    Adapter {
        origin: String,
        source: UbxAdapterParamError,
    },
}

/// The parameter called `name`.
pub fn parameter(name: &str) -> Option<&'static NodeParameter> {
    NodeParameter::named_in(&UBX_NODE_PARAMETERS, name)
}

impl UbxNodeParams {
    /// Every parameter's value, in table order.
    pub fn values(&self) -> Vec<(&'static str, Value)> {
        let a = &self.adapter;
        let t = &self.topics;
        vec![
            (USE_SIM_TIME, self.use_sim_time.into()),
            (QUEUE_DEPTH, self.queue_depth.into()),
            (TIME_BASE, name_of(&TIME_BASES, &a.time_base).into()),
            (LEAP_SECONDS, a.leap_seconds.into()),
            (HOST_LATENCY_S, a.host_latency_s.into()),
            (MAX_IMU_GNSS_SKEW_S, a.max_imu_gnss_skew_s.into()),
            (IONOSPHERE, name_of(&IONOSPHERES, &a.ionosphere).into()),
            (FRAME_ID, a.frame_id.clone().into()),
            (OFFSET_WINDOW_EPOCHS, a.offset_window_epochs.into()),
            (RAWX_TOPIC, t.rawx.clone().into()),
            (SFRBX_TOPIC, t.sfrbx.clone().into()),
            (STREAM_TOPIC, t.stream.clone().into()),
            (IMU_TOPIC, t.imu.clone().into()),
            (MEASUREMENTS_TOPIC, t.measurements.clone().into()),
        ]
    }
}

/// The values of `time_base` by name.
const TIME_BASES: [(&str, TimeBase); 2] = [("gnss", TimeBase::Gnss), ("host", TimeBase::Host)];
/// The values of `ionosphere` by name.
const IONOSPHERES: [(&str, IonosphereMode); 3] = [
    ("iono_free", IonosphereMode::IonoFree),
    ("broadcast", IonosphereMode::Broadcast),
    ("none", IonosphereMode::None),
];

/// The name of `value` among `choices`.
fn name_of<T: PartialEq>(choices: &[(&'static str, T)], value: &T) -> &'static str {
    choices
        .iter()
        .find(|(_, v)| v == value)
        .map_or("", |(n, _)| n)
}

/// One of `choices` by its name, or `default`.
fn one_of<T: Copy>(
    a: Option<&Assignment>,
    name: &'static str,
    choices: &[(&str, T)],
    reason: &'static str,
    default: T,
) -> Result<T, ParamsError> {
    let Some(a) = a else {
        return Ok(default);
    };
    let text = a.value.as_str().unwrap_or_default();
    choices
        .iter()
        .find(|(n, _)| *n == text)
        .map(|(_, v)| *v)
        .ok_or_else(|| refused(a, name, reason))
}

/// A number `read` accepts, or `default`.
fn number<T>(
    a: Option<&Assignment>,
    name: &'static str,
    read: fn(&Value) -> Option<T>,
    reason: &'static str,
    default: T,
) -> Result<T, ParamsError> {
    match a {
        None => Ok(default),
        Some(a) => read(&a.value).ok_or_else(|| refused(a, name, reason)),
    }
}

/// A topic name, or the declared default.
fn topic(a: Option<&Assignment>, name: &'static str) -> Result<String, ParamsError> {
    match a {
        None => Ok(parameter(name)
            .map(|p| p.default)
            .unwrap_or_default()
            .to_owned()),
        Some(Assignment {
            value: Value::String(s),
            ..
        }) if is_valid_topic_name(s) => Ok(s.clone()),
        Some(a) => Err(refused(a, name, "must be a topic name")),
    }
}

/// The node's parameters from the values resolved for it; a name the table does not
/// declare is refused (the node has no other parameters).
pub fn ubx_node_params_from(values: &[Assignment]) -> Result<UbxNodeParams, UbxParamsError> {
    if let Some(a) = values.iter().find(|a| parameter(&a.name).is_none()) {
        return Err(UbxParamsError::Unknown {
            origin: a.origin.clone(),
            name: ConfigError::shortened(&a.name),
        });
    }
    let value = |name: &str| values.iter().rev().find(|a| a.name == name);
    let d = UbxAdapterParams::default();
    let adapter = UbxAdapterParams {
        time_base: one_of(
            value(TIME_BASE),
            TIME_BASE,
            &TIME_BASES,
            "must be gnss or host",
            d.time_base,
        )?,
        leap_seconds: number(
            value(LEAP_SECONDS),
            LEAP_SECONDS,
            |v| v.as_i64().and_then(|i| i32::try_from(i).ok()),
            "must be an integer",
            d.leap_seconds,
        )?,
        host_latency_s: number(
            value(HOST_LATENCY_S),
            HOST_LATENCY_S,
            Value::as_f64,
            "must be a number",
            d.host_latency_s,
        )?,
        max_imu_gnss_skew_s: number(
            value(MAX_IMU_GNSS_SKEW_S),
            MAX_IMU_GNSS_SKEW_S,
            Value::as_f64,
            "must be a number",
            d.max_imu_gnss_skew_s,
        )?,
        ionosphere: one_of(
            value(IONOSPHERE),
            IONOSPHERE,
            &IONOSPHERES,
            "must be iono_free, broadcast or none",
            d.ionosphere,
        )?,
        frame_id: frame(value(FRAME_ID), FRAME_ID, &d.frame_id)?,
        offset_window_epochs: number(
            value(OFFSET_WINDOW_EPOCHS),
            OFFSET_WINDOW_EPOCHS,
            |v| v.as_u64().and_then(|u| usize::try_from(u).ok()),
            "must be a non-negative integer",
            d.offset_window_epochs,
        )?,
    };
    if let Err(source) = adapter.validate() {
        return Err(UbxParamsError::Adapter {
            origin: value(source.name).map_or_else(String::new, |a| a.origin.clone()),
            source,
        });
    }
    Ok(UbxNodeParams {
        adapter,
        topics: UbxTopics {
            rawx: topic(value(RAWX_TOPIC), RAWX_TOPIC)?,
            sfrbx: topic(value(SFRBX_TOPIC), SFRBX_TOPIC)?,
            stream: topic(value(STREAM_TOPIC), STREAM_TOPIC)?,
            imu: topic(value(IMU_TOPIC), IMU_TOPIC)?,
            measurements: topic(value(MEASUREMENTS_TOPIC), MEASUREMENTS_TOPIC)?,
        },
        use_sim_time: boolean(value(USE_SIM_TIME), USE_SIM_TIME, false)?,
        queue_depth: depth(value(QUEUE_DEPTH))?,
    })
}

/// Reads the parameter files and rules of `args` and builds the node's parameters.
pub fn load(args: &NodeArgs) -> Result<UbxNodeParams, UbxParamsError> {
    ubx_node_params_from(&resolved(args)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::args::parse_as;

    fn load_with(extra: &[&str]) -> Result<UbxNodeParams, UbxParamsError> {
        let args = ["--ros-args"].iter().chain(extra).copied();
        load(&parse_as("gnss_ins_ubx_node", args).unwrap())
    }

    #[test]
    fn declared_defaults_are_the_loaded_ones() {
        let p = load_with(&[]).unwrap();
        assert_eq!(p.adapter, UbxAdapterParams::default());
        for (name, value) in p.values() {
            let declared = parameter(name).unwrap().default;
            assert_eq!(
                serde_yaml::from_str::<Value>(declared).unwrap(),
                value,
                "{name}"
            );
        }
        let names: Vec<&str> = p.values().iter().map(|(n, _)| *n).collect();
        let declared: Vec<&str> = UBX_NODE_PARAMETERS.iter().map(|p| p.name).collect();
        assert_eq!(names, declared, "values() follows the table");
    }

    #[test]
    fn values_are_read_and_checked() {
        let p = load_with(&[
            "-p",
            "time_base:=host",
            "-p",
            "host_latency_s:=0.02",
            "-p",
            "ionosphere:=broadcast",
            "-p",
            "rawx_topic:=/ubx_rxm_rawx",
            "-p",
            "gnss_ins_ubx_node:leap_seconds:=17",
        ])
        .unwrap();
        assert_eq!(p.adapter.time_base, TimeBase::Host);
        assert_eq!(p.adapter.host_latency_s, 0.02);
        assert_eq!(p.adapter.ionosphere, IonosphereMode::Broadcast);
        assert_eq!(p.adapter.leap_seconds, 17);
        assert_eq!(p.topics.rawx, "/ubx_rxm_rawx");
        let refused = |rule: &str| load_with(&["-p", rule]).unwrap_err().to_string();
        assert!(refused("time_base:=utc").contains("gnss or host"));
        assert!(refused("leap_seconds:=61").contains("[0, 60]"));
        assert!(refused("host_latency_s:=fast").contains("number"));
        assert!(refused("offset_window_epochs:=1").contains("offset_window_epochs"));
        assert!(refused("frame_id:=''").contains("frame id"));
        assert!(refused("imu_topic:='a b'").contains("topic name"));
        assert!(refused("filter.variant:=ekf").contains("no parameter of gnss_ins_ubx_node"));
    }
}
