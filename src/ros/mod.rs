//! The ROS 2 side of the crate: wire messages, their CDR encoding and their conversion
//! into the core types. Nothing in here holds filter math.
//!
//! - [`msg`]: serde structs byte-identical (in CDR) to the ROS 2 Jazzy messages the node
//!   uses, plus the package's own messages of `msg/`.
//! - [`cdr`]: `encode` / `decode` of a whole serialized ROS 2 payload (encapsulation
//!   header + CDR body).
//! - [`convert`]: wire messages -> core types (`GnssEpoch`, `ImuSample`) and ROS time.
//! - [`fix_velocity`], [`fix_pairing`]: `gnss/fix` joined with its `gnss/velocity`.
//! - [`rel_pos_ned`]: a moving-base u-blox pair's UBXNavRelPosNED -> the engine's
//!   baseline heading.
//! - [`outbound`]: engine outputs -> Odometry, NavSatFix, NoiseEstimates, TF.
//! - [`adapter`]: the engine behind decoded messages in and messages to publish out, with
//!   the node's conversion, frame locks, time-jump rule, non-finite guard and counters;
//!   the live node and `gnss_ins replay` both drive it.
//! - [`bag`]: rosbag2-compatible MCAP bag writing and streaming reading.
//! - [`args`]: the node's `--ros-args` command line; [`log_level`]: its `--log-level`
//!   rules; [`param_overrides`]: its parameter files and `-p` rules resolved as rclcpp
//!   does; [`names`]: topic-name resolution.
//! - [`node`]: the `gnss_ins_node` ROS 2 node (ros2-client): DDS around the adapter.
//! - [`log_limit`]: repeated warnings limited (the adapters' and the node's).
//! - [`player`]: `gnss_ins play`, a recorded bag published onto DDS.
//! - [`ubx_adapter`]: the u-blox drivers' raw GNSS messages -> GnssMeasurements
//!   (`gnss_ins convert --bag`, and the live adapter node).
//! - [`ubx_node`]: the `gnss_ins_ubx_node` ROS 2 node around the adapter.

pub mod adapter;
pub mod args;
pub mod bag;
pub mod cdr;
pub mod convert;
pub mod fix_pairing;
pub mod fix_velocity;
pub mod log_level;
pub mod log_limit;
pub mod msg;
pub mod names;
pub mod node;
pub mod outbound;
pub mod param_overrides;
pub mod player;
pub mod rel_pos_ned;
pub mod ubx_adapter;
pub mod ubx_node;
