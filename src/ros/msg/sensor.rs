//! `sensor_msgs` messages: IMU samples and GNSS fixes.

use serde::{Deserialize, Serialize};

use super::{ros_message, Header, Quaternion, Vector3};

/// `sensor_msgs/msg/Imu` (REP-145: `linear_acceleration` is specific force, gravity
/// included, in the IMU's frame `header.frame_id`).
///
/// Covariances are row-major 3×3 about the x, y, z axes; an all-zero matrix means
/// "unknown", and element 0 set to -1 means "this quantity is not provided".
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct Imu {
    /// Sample time and IMU frame.
    pub header: Header,
    /// Orientation estimate of the IMU frame.
    pub orientation: Quaternion,
    /// Covariance of `orientation` (rad²), as rotations about x, y, z.
    pub orientation_covariance: [f64; 9],
    /// Angular velocity (rad/s).
    pub angular_velocity: Vector3,
    /// Covariance of `angular_velocity` (rad²/s²).
    pub angular_velocity_covariance: [f64; 9],
    /// Specific force (m/s²).
    pub linear_acceleration: Vector3,
    /// Covariance of `linear_acceleration` (m²/s⁴).
    pub linear_acceleration_covariance: [f64; 9],
}
ros_message!(Imu, "sensor_msgs", "Imu");

/// `sensor_msgs/msg/NavSatStatus`: fix quality and the constellations used.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NavSatStatus {
    /// One of the `STATUS_*` constants.
    pub status: i8,
    /// Bit mask of the `SERVICE_*` constants.
    pub service: u16,
}
ros_message!(NavSatStatus, "sensor_msgs", "NavSatStatus");

impl NavSatStatus {
    /// Status not set yet.
    pub const STATUS_UNKNOWN: i8 = -2;
    /// Unable to fix position.
    pub const STATUS_NO_FIX: i8 = -1;
    /// Unaugmented fix.
    pub const STATUS_FIX: i8 = 0;
    /// Fix with satellite-based augmentation.
    pub const STATUS_SBAS_FIX: i8 = 1;
    /// Fix with ground-based augmentation.
    pub const STATUS_GBAS_FIX: i8 = 2;
    /// No service information.
    pub const SERVICE_UNKNOWN: u16 = 0;
    /// GPS used.
    pub const SERVICE_GPS: u16 = 1;
    /// GLONASS used.
    pub const SERVICE_GLONASS: u16 = 2;
    /// BeiDou (COMPASS) used.
    pub const SERVICE_COMPASS: u16 = 4;
    /// Galileo used.
    pub const SERVICE_GALILEO: u16 = 8;
}

/// `sensor_msgs/msg/NavSatFix`: a geodetic WGS84 position fix.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct NavSatFix {
    /// Time of the fix and the antenna's frame.
    pub header: Header,
    /// Fix quality.
    pub status: NavSatStatus,
    /// Latitude (degrees), positive north.
    pub latitude: f64,
    /// Longitude (degrees), positive east.
    pub longitude: f64,
    /// Altitude above the WGS84 ellipsoid (m).
    pub altitude: f64,
    /// Row-major 3×3 position covariance in ENU (m²).
    pub position_covariance: [f64; 9],
    /// One of the `COVARIANCE_TYPE_*` constants.
    pub position_covariance_type: u8,
}
ros_message!(NavSatFix, "sensor_msgs", "NavSatFix");

impl NavSatFix {
    /// Covariance unknown.
    pub const COVARIANCE_TYPE_UNKNOWN: u8 = 0;
    /// Covariance approximated (e.g. from DOP).
    pub const COVARIANCE_TYPE_APPROXIMATED: u8 = 1;
    /// Only the diagonal is known.
    pub const COVARIANCE_TYPE_DIAGONAL_KNOWN: u8 = 2;
    /// Full covariance known.
    pub const COVARIANCE_TYPE_KNOWN: u8 = 3;
}
