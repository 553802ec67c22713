//! ROS 2 bags in MCAP, compatible with rosbag2's MCAP storage plugin, `ros2 bag`,
//! Foxglove and the `rosbags` Python package.
//!
//! - [`BagWriter`]: `create`, `add_topic::<T>`, `write::<T>(topic, &msg, log_time_ns)`,
//!   `finish`. Deterministic output: the same calls give the same bytes.
//! - [`BagReader`]: `open` a `.mcap` file (or a rosbag2 directory holding one), list its
//!   [`TopicInfo`]s, stream [`BagMessage`]s (still CDR; decode them with
//!   [`crate::ros::cdr::decode`]) without loading the file into memory. Damage is reported
//!   as error items of the stream, after every message that could still be read.
//!
//! This module does file I/O; nothing outside `src/ros` and `src/bin` uses it.

mod definition;
mod error;
mod indexed;
mod linear;
mod message;
mod qos;
mod reader;
pub mod schemas;
mod writer;

pub use definition::{full_definition, short_type_name, MissingDefinition};
pub use error::BagError;
pub use message::BagMessage;
pub use qos::{Durability, OfferedQos, Reliability};
pub use reader::{BagMessages, BagReader, ReadOrder, TopicInfo};
pub use writer::{BagWriteOptions, BagWriter, ChunkCompression};
