//! `tf2_msgs/msg/TFMessage`.

use serde::{Deserialize, Serialize};

use super::{ros_message, TransformStamped};

/// `tf2_msgs/msg/TFMessage`: the payload of `/tf` and `/tf_static`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct TFMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}
ros_message!(TFMessage, "tf2_msgs", "TFMessage");
