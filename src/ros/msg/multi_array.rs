//! `std_msgs` multi-arrays: `UInt8MultiArray` is how KumarRobotics' `ublox_gps` publishes
//! the receiver's raw byte stream (`raw_data_stream`): one message per serial read, one
//! dimension labelled `raw_data_stream` of stride 1, data offset 0, frames cut anywhere.

use serde::{Deserialize, Serialize};

use super::ros_message;

/// `std_msgs/msg/MultiArrayDimension`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct MultiArrayDimension {
    /// Name of the dimension.
    pub label: String,
    /// Number of elements along it.
    pub size: u32,
    /// Elements spanned by one step along the previous dimension.
    pub stride: u32,
}
ros_message!(MultiArrayDimension, "std_msgs", "MultiArrayDimension");

/// `std_msgs/msg/MultiArrayLayout`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct MultiArrayLayout {
    /// The dimensions, outermost first.
    pub dim: Vec<MultiArrayDimension>,
    /// Padding elements at the start of `data`.
    pub data_offset: u32,
}
ros_message!(MultiArrayLayout, "std_msgs", "MultiArrayLayout");

/// `std_msgs/msg/UInt8MultiArray`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct UInt8MultiArray {
    /// How `data` is laid out.
    pub layout: MultiArrayLayout,
    /// The bytes.
    pub data: Vec<u8>,
}
ros_message!(UInt8MultiArray, "std_msgs", "UInt8MultiArray");
