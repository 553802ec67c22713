//! `nav_msgs/msg/Odometry`.

use serde::{Deserialize, Serialize};

use super::{ros_message, Header, PoseWithCovariance, TwistWithCovariance};

/// `nav_msgs/msg/Odometry`: pose in `header.frame_id`, twist in `child_frame_id`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct Odometry {
    /// Stamp and the frame of the pose (e.g. `map`, `odom`).
    pub header: Header,
    /// Frame of the twist (e.g. `base_link`).
    pub child_frame_id: String,
    /// Pose of `child_frame_id` in `header.frame_id`, with covariance.
    pub pose: PoseWithCovariance,
    /// Velocity in `child_frame_id`, with covariance.
    pub twist: TwistWithCovariance,
}
ros_message!(Odometry, "nav_msgs", "Odometry");
