//! `geometry_msgs` messages: points, vectors, rotations, poses, twists, transforms.

use serde::{Deserialize, Serialize};

use super::{fixed_array, ros_message, Header};

/// `geometry_msgs/msg/Point`: a position (m).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Point {
    /// x coordinate.
    pub x: f64,
    /// y coordinate.
    pub y: f64,
    /// z coordinate.
    pub z: f64,
}
ros_message!(Point, "geometry_msgs", "Point");

/// `geometry_msgs/msg/Vector3`: a free vector (unit given by the field using it).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Vector3 {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
}
ros_message!(Vector3, "geometry_msgs", "Vector3");

/// `geometry_msgs/msg/Quaternion`: a rotation, scalar part last.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct Quaternion {
    /// Vector part, x.
    pub x: f64,
    /// Vector part, y.
    pub y: f64,
    /// Vector part, z.
    pub z: f64,
    /// Scalar part.
    pub w: f64,
}
ros_message!(Quaternion, "geometry_msgs", "Quaternion");

/// The identity rotation, as the ROS definition's default (`float64 w 1`).
impl Default for Quaternion {
    fn default() -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

/// `geometry_msgs/msg/Pose`: position and orientation.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// Position (m).
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}
ros_message!(Pose, "geometry_msgs", "Pose");

/// `geometry_msgs/msg/PoseWithCovariance`: a pose with its 6×6 covariance.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Row-major 6×6 covariance of (x, y, z, rotation about X, Y, Z), in m² / rad².
    #[serde(with = "fixed_array")]
    pub covariance: [f64; 36],
}
ros_message!(PoseWithCovariance, "geometry_msgs", "PoseWithCovariance");

/// Identity pose with zero covariance (serde's derive does not cover `[f64; 36]`).
impl Default for PoseWithCovariance {
    fn default() -> Self {
        Self {
            pose: Pose::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/msg/Twist`: linear and angular velocity.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Twist {
    /// Linear velocity (m/s).
    pub linear: Vector3,
    /// Angular velocity (rad/s).
    pub angular: Vector3,
}
ros_message!(Twist, "geometry_msgs", "Twist");

/// `geometry_msgs/msg/TwistWithCovariance`: a twist with its 6×6 covariance.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Row-major 6×6 covariance of (vx, vy, vz, wx, wy, wz), in m²/s² / rad²/s².
    #[serde(with = "fixed_array")]
    pub covariance: [f64; 36],
}
ros_message!(TwistWithCovariance, "geometry_msgs", "TwistWithCovariance");

/// Zero twist with zero covariance (serde's derive does not cover `[f64; 36]`).
impl Default for TwistWithCovariance {
    fn default() -> Self {
        Self {
            twist: Twist::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/msg/TwistWithCovarianceStamped`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct TwistWithCovarianceStamped {
    /// Stamp and frame of the twist.
    pub header: Header,
    /// The twist and its covariance.
    pub twist: TwistWithCovariance,
}
ros_message!(
    TwistWithCovarianceStamped,
    "geometry_msgs",
    "TwistWithCovarianceStamped"
);

/// `geometry_msgs/msg/Transform`: a rigid transform between two frames.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Transform {
    /// Translation (m).
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}
ros_message!(Transform, "geometry_msgs", "Transform");

/// `geometry_msgs/msg/TransformStamped`: the transform from `header.frame_id` to
/// `child_frame_id`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// Child frame.
    pub child_frame_id: String,
    /// Pose of the child frame in the parent frame.
    pub transform: Transform,
}
ros_message!(TransformStamped, "geometry_msgs", "TransformStamped");
