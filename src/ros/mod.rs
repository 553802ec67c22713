//! The ROS 2 side of the crate: wire messages, their CDR encoding and their conversion
//! into the core types. Nothing in here holds filter math.
//!
//! - [`msg`]: serde structs byte-identical (in CDR) to the ROS 2 Jazzy messages the node
//!   uses, plus the package's own messages of `msg/`.
//! - [`cdr`]: `encode` / `decode` of a whole serialized ROS 2 payload (encapsulation
//!   header + CDR body).
//! - [`convert`]: wire messages -> core types (`GnssEpoch`, `ImuSample`) and ROS time.
//! - [`fix_velocity`]: `gnss/fix` joined with its `gnss/velocity` (node and replay).
//! - [`outbound`]: engine outputs -> Odometry, NavSatFix, NoiseEstimates.
//! - [`bag`]: rosbag2-compatible MCAP bag writing and streaming reading.
//! - [`args`]: the node's `--ros-args` command line; [`log_level`]: its `--log-level`
//!   rules; [`param_overrides`]: its parameter files and `-p` rules resolved as rclcpp
//!   does; [`names`]: topic-name resolution.
//! - [`node`]: the `gnss_ins_node` ROS 2 node (ros2-client) around the engine.
//! - [`player`]: `gnss_ins play`, a recorded bag published onto DDS.
//! - [`ubx_adapter`]: the u-blox drivers' raw GNSS messages -> GnssMeasurements
//!   (`gnss_ins convert --bag`, and the live adapter node).
//! - [`ubx_node`]: the `gnss_ins_ubx_node` ROS 2 node around the adapter.

pub mod args;
pub mod bag;
pub mod cdr;
pub mod convert;
pub mod fix_velocity;
pub mod log_level;
pub mod msg;
pub mod names;
pub mod node;
pub mod outbound;
pub mod param_overrides;
pub mod player;
pub mod ubx_adapter;
pub mod ubx_node;
