//! Message definition texts (`.msg` format) of every type a bag may hold, keyed by
//! `pkg/Type`. The standard ROS 2 Jazzy texts, and those of the u-blox driver's
//! `ublox_ubx_msgs`, are written here field for field (comments left out); the package's
//! own texts are the files of `msg/`.

use crate::ros::msg::{
    GNSS_MEASUREMENTS_MSG, NOISE_ESTIMATES_MSG, SATELLITE_MEASUREMENT_MSG, SATELLITE_NOISE_MSG,
};

/// `builtin_interfaces/Time`.
pub const TIME_MSG: &str = "int32 sec\nuint32 nanosec\n";

/// `std_msgs/Header`.
pub const HEADER_MSG: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";

/// `geometry_msgs/Point`.
pub const POINT_MSG: &str = "float64 x\nfloat64 y\nfloat64 z\n";

/// `geometry_msgs/Vector3`.
pub const VECTOR3_MSG: &str = "float64 x\nfloat64 y\nfloat64 z\n";

/// `geometry_msgs/Quaternion` (identity by default).
pub const QUATERNION_MSG: &str = "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";

/// `geometry_msgs/Pose`.
pub const POSE_MSG: &str = "Point position\nQuaternion orientation\n";

/// `geometry_msgs/PoseWithCovariance`.
pub const POSE_WITH_COVARIANCE_MSG: &str = "Pose pose\nfloat64[36] covariance\n";

/// `geometry_msgs/Twist`.
pub const TWIST_MSG: &str = "Vector3 linear\nVector3 angular\n";

/// `geometry_msgs/TwistWithCovariance`.
pub const TWIST_WITH_COVARIANCE_MSG: &str = "Twist twist\nfloat64[36] covariance\n";

/// `geometry_msgs/TwistWithCovarianceStamped`.
pub const TWIST_WITH_COVARIANCE_STAMPED_MSG: &str =
    "std_msgs/Header header\nTwistWithCovariance twist\n";

/// `geometry_msgs/Transform`.
pub const TRANSFORM_MSG: &str = "Vector3 translation\nQuaternion rotation\n";

/// `geometry_msgs/TransformStamped`.
pub const TRANSFORM_STAMPED_MSG: &str =
    "std_msgs/Header header\nstring child_frame_id\nTransform transform\n";

/// `sensor_msgs/Imu`.
pub const IMU_MSG: &str = "\
std_msgs/Header header
geometry_msgs/Quaternion orientation
float64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance
geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance
";

/// `sensor_msgs/NavSatStatus`.
pub const NAV_SAT_STATUS_MSG: &str = "\
int8 STATUS_UNKNOWN = -2
int8 STATUS_NO_FIX = -1
int8 STATUS_FIX = 0
int8 STATUS_SBAS_FIX = 1
int8 STATUS_GBAS_FIX = 2
int8 status
uint16 SERVICE_UNKNOWN = 0
uint16 SERVICE_GPS = 1
uint16 SERVICE_GLONASS = 2
uint16 SERVICE_COMPASS = 4
uint16 SERVICE_GALILEO = 8
uint16 service
";

/// `sensor_msgs/NavSatFix`.
pub const NAV_SAT_FIX_MSG: &str = "\
std_msgs/Header header
NavSatStatus status
float64 latitude
float64 longitude
float64 altitude
float64[9] position_covariance
uint8 COVARIANCE_TYPE_UNKNOWN = 0
uint8 COVARIANCE_TYPE_APPROXIMATED = 1
uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2
uint8 COVARIANCE_TYPE_KNOWN = 3
uint8 position_covariance_type
";

/// `nav_msgs/Odometry`.
pub const ODOMETRY_MSG: &str = "\
std_msgs/Header header
string child_frame_id
geometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist
";

/// `diagnostic_msgs/KeyValue`.
pub const KEY_VALUE_MSG: &str = "string key\nstring value\n";

/// `diagnostic_msgs/DiagnosticStatus`.
pub const DIAGNOSTIC_STATUS_MSG: &str = "\
byte OK=0
byte WARN=1
byte ERROR=2
byte STALE=3
byte level
string name
string message
string hardware_id
KeyValue[] values
";

/// `diagnostic_msgs/DiagnosticArray`.
pub const DIAGNOSTIC_ARRAY_MSG: &str = "std_msgs/Header header\nDiagnosticStatus[] status\n";

/// `tf2_msgs/TFMessage`.
pub const TF_MESSAGE_MSG: &str = "geometry_msgs/TransformStamped[] transforms\n";

/// `rosgraph_msgs/Clock`.
pub const CLOCK_MSG: &str = "builtin_interfaces/Time clock\n";

/// `rcl_interfaces/Log` (what /rosout carries).
pub const LOG_MSG: &str =
    "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\n\
builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n\
string function\nuint32 line\n";

/// `std_msgs/MultiArrayDimension`.
pub const MULTI_ARRAY_DIMENSION_MSG: &str = "string label\nuint32 size\nuint32 stride\n";

/// `std_msgs/MultiArrayLayout`.
pub const MULTI_ARRAY_LAYOUT_MSG: &str = "MultiArrayDimension[] dim\nuint32 data_offset\n";

/// `std_msgs/UInt8MultiArray`.
pub const UINT8_MULTI_ARRAY_MSG: &str = "MultiArrayLayout layout\nuint8[] data\n";

/// `ublox_ubx_msgs/RecStat`.
pub const REC_STAT_MSG: &str = "bool leap_sec\nbool clk_reset\n";

/// `ublox_ubx_msgs/TrkStat`.
pub const TRK_STAT_MSG: &str = "bool pr_valid\nbool cp_valid\nbool half_cyc\nbool sub_half_cyc\n";

/// `ublox_ubx_msgs/RawxData`.
pub const RAWX_DATA_MSG: &str = "\
float64 pr_mes
float64 cp_mes
float32 do_mes
uint8 gnss_id
uint8 sv_id
uint8 sig_id
uint8 freq_id
uint16 locktime
uint8 c_no
uint8 pr_stdev
uint8 cp_stdev
uint8 do_stdev
TrkStat trk_stat
";

/// `ublox_ubx_msgs/UBXRxmRawx`.
pub const UBX_RXM_RAWX_MSG: &str = "\
std_msgs/Header header
float64 rcv_tow
uint16 week
int8 leap_s
uint8 num_meas
RecStat rec_stat
uint8 version
RawxData[] rawx_data
";

/// `ublox_ubx_msgs/UBXRxmSfrbx`.
pub const UBX_RXM_SFRBX_MSG: &str = "\
std_msgs/Header header
uint8 gnss_id
uint8 sv_id
uint8 sig_id
uint8 freq_id
uint8 num_words
uint8 chn
uint8 version
uint32[] dwrd
";

/// `ublox_ubx_msgs/CarrSoln`.
pub const CARR_SOLN_MSG: &str = "\
uint8 CARRIER_SOLUTION_NO_CARRIER_RANGE_SOLUTION = 0
uint8 CARRIER_SOLUTION_PHASE_WITH_FLOATING_AMBIGUITIES = 1
uint8 CARRIER_SOLUTION_PHASE_WITH_FIXED_AMBIGUITIES = 2
uint8 status
";

/// `ublox_ubx_msgs/UBXNavRelPosNED`.
pub const UBX_NAV_REL_POS_NED_MSG: &str = "\
std_msgs/Header header
uint8 version
uint16 ref_station_id
uint32 itow
int32 rel_pos_n
int32 rel_pos_e
int32 rel_pos_d
int32 rel_pos_length
int32 rel_pos_heading
int8 rel_pos_hp_n
int8 rel_pos_hp_e
int8 rel_pos_hp_d
int8 rel_pos_hp_length
uint32 acc_n
uint32 acc_e
uint32 acc_d
uint32 acc_length
uint32 acc_heading
bool gnss_fix_ok
bool diff_soln
bool rel_pos_valid
CarrSoln carr_soln
bool is_moving
bool ref_pos_miss
bool ref_obs_miss
bool rel_pos_heading_valid
bool rel_pos_normalized
";

/// Every known definition text, keyed by `pkg/Type` (no `msg/` in the middle).
const DEFINITIONS: &[(&str, &str)] = &[
    ("builtin_interfaces/Time", TIME_MSG),
    ("std_msgs/Header", HEADER_MSG),
    ("geometry_msgs/Point", POINT_MSG),
    ("geometry_msgs/Vector3", VECTOR3_MSG),
    ("geometry_msgs/Quaternion", QUATERNION_MSG),
    ("geometry_msgs/Pose", POSE_MSG),
    ("geometry_msgs/PoseWithCovariance", POSE_WITH_COVARIANCE_MSG),
    ("geometry_msgs/Twist", TWIST_MSG),
    (
        "geometry_msgs/TwistWithCovariance",
        TWIST_WITH_COVARIANCE_MSG,
    ),
    (
        "geometry_msgs/TwistWithCovarianceStamped",
        TWIST_WITH_COVARIANCE_STAMPED_MSG,
    ),
    ("geometry_msgs/Transform", TRANSFORM_MSG),
    ("geometry_msgs/TransformStamped", TRANSFORM_STAMPED_MSG),
    ("sensor_msgs/Imu", IMU_MSG),
    ("sensor_msgs/NavSatStatus", NAV_SAT_STATUS_MSG),
    ("sensor_msgs/NavSatFix", NAV_SAT_FIX_MSG),
    ("nav_msgs/Odometry", ODOMETRY_MSG),
    ("diagnostic_msgs/KeyValue", KEY_VALUE_MSG),
    ("diagnostic_msgs/DiagnosticStatus", DIAGNOSTIC_STATUS_MSG),
    ("diagnostic_msgs/DiagnosticArray", DIAGNOSTIC_ARRAY_MSG),
    ("tf2_msgs/TFMessage", TF_MESSAGE_MSG),
    ("rosgraph_msgs/Clock", CLOCK_MSG),
    ("rcl_interfaces/Log", LOG_MSG),
    ("std_msgs/MultiArrayDimension", MULTI_ARRAY_DIMENSION_MSG),
    ("std_msgs/MultiArrayLayout", MULTI_ARRAY_LAYOUT_MSG),
    ("std_msgs/UInt8MultiArray", UINT8_MULTI_ARRAY_MSG),
    ("ublox_ubx_msgs/RecStat", REC_STAT_MSG),
    ("ublox_ubx_msgs/TrkStat", TRK_STAT_MSG),
    ("ublox_ubx_msgs/RawxData", RAWX_DATA_MSG),
    ("ublox_ubx_msgs/UBXRxmRawx", UBX_RXM_RAWX_MSG),
    ("ublox_ubx_msgs/UBXRxmSfrbx", UBX_RXM_SFRBX_MSG),
    ("ublox_ubx_msgs/CarrSoln", CARR_SOLN_MSG),
    ("ublox_ubx_msgs/UBXNavRelPosNED", UBX_NAV_REL_POS_NED_MSG),
    (
        "adaptive_gnss_ins/SatelliteMeasurement",
        SATELLITE_MEASUREMENT_MSG,
    ),
    ("adaptive_gnss_ins/GnssMeasurements", GNSS_MEASUREMENTS_MSG),
    ("adaptive_gnss_ins/SatelliteNoise", SATELLITE_NOISE_MSG),
    ("adaptive_gnss_ins/NoiseEstimates", NOISE_ESTIMATES_MSG),
];

/// The definition text of `short_name` (`pkg/Type`), or None when this crate has none.
pub fn definition_text(short_name: &str) -> Option<&'static str> {
    DEFINITIONS
        .iter()
        .find(|(name, _)| *name == short_name)
        .map(|(_, text)| *text)
}
