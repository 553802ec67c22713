//! Serde structs for the ROS 2 messages the node reads and writes, and those of the u-blox
//! drivers it reads (`ublox_ubx_msgs`, `std_msgs/UInt8MultiArray`).
//!
//! Each struct matches its ROS 2 Jazzy definition field for field, in the same order:
//! CDR is positional, so the order *is* the wire format. Fixed-size arrays (`float64[9]`,
//! `float64[36]`) are Rust arrays (no length on the wire), unbounded arrays are `Vec`
//! (`u32` length first), `string` is `String`, `byte` and `uint8` are `u8`.
//! `tests/cdr_fixtures.rs` checks the bytes against an independent serializer.

mod builtin;
mod diagnostic;
mod fixed_array;
mod geometry;
mod gnss;
mod multi_array;
mod nav;
mod rcl;
mod rosgraph;
mod sensor;
mod tf2;
mod ublox;

pub use builtin::{Header, Time};
pub use diagnostic::{DiagnosticArray, DiagnosticStatus, KeyValue};
pub use geometry::{
    Point, Pose, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist,
    TwistWithCovariance, TwistWithCovarianceStamped, Vector3,
};
pub use gnss::{
    GnssMeasurements, NoiseEstimates, SatelliteMeasurement, SatelliteNoise, GNSS_MEASUREMENTS_MSG,
    NOISE_ESTIMATES_MSG, SATELLITE_MEASUREMENT_MSG, SATELLITE_NOISE_MSG,
};
pub use multi_array::{MultiArrayDimension, MultiArrayLayout, UInt8MultiArray};
pub use nav::Odometry;
pub use rcl::{Log, ParameterEvent};
pub use rosgraph::Clock;
pub use sensor::{Imu, NavSatFix, NavSatStatus};
pub use tf2::TFMessage;
pub use ublox::{CarrSoln, RawxData, RecStat, TrkStat, UbxNavRelPosNed, UbxRxmRawx, UbxRxmSfrbx};

/// A ROS 2 message type and the names it is known by.
pub trait RosMessage: serde::Serialize + serde::de::DeserializeOwned {
    /// ROS 2 interface name, e.g. `sensor_msgs/msg/Imu` (rosbag2, MCAP, `ros2 topic`).
    const TYPE_NAME: &'static str;
    /// DDS type name, e.g. `sensor_msgs::msg::dds_::Imu_` (what RTPS discovery announces).
    const DDS_TYPE_NAME: &'static str;
}

/// Implements [`RosMessage`] for `$ty`, the message `$name` of ROS package `$package`.
macro_rules! ros_message {
    ($ty:ty, $package:literal, $name:literal) => {
        impl $crate::ros::msg::RosMessage for $ty {
            const TYPE_NAME: &'static str = concat!($package, "/msg/", $name);
            const DDS_TYPE_NAME: &'static str = concat!($package, "::msg::dds_::", $name, "_");
        }
    };
}
use ros_message;
