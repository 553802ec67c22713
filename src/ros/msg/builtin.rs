//! `builtin_interfaces/msg/Time` and `std_msgs/msg/Header`.

use serde::{Deserialize, Serialize};

use super::ros_message;

/// `builtin_interfaces/msg/Time`: a ROS time stamp (UTC-based for wall/system time).
/// Conversions to and from `f64` seconds are in [`crate::ros::convert`].
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Time {
    /// Whole seconds (since the UNIX epoch for system time).
    pub sec: i32,
    /// Nanoseconds past `sec`, valid in [0, 1e9).
    pub nanosec: u32,
}
ros_message!(Time, "builtin_interfaces", "Time");

/// `std_msgs/msg/Header`: time stamp and coordinate frame of the data.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct Header {
    /// Time of validity of the data.
    pub stamp: Time,
    /// Frame the data is expressed in.
    pub frame_id: String,
}
ros_message!(Header, "std_msgs", "Header");
