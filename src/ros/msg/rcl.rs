//! `rcl_interfaces/msg/Log` and `rcl_interfaces/msg/ParameterEvent`.

use ros2_client::parameters::raw::Parameter;
use serde::{Deserialize, Serialize};

use super::{ros_message, Time};

/// `rcl_interfaces/msg/Log`: one log line of a node, published on `/rosout`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct Log {
    /// When the line was logged.
    pub stamp: Time,
    /// One of the level constants.
    pub level: u8,
    /// Logger name (the node's fully qualified name with `.` for `/`, no leading `.`).
    pub name: String,
    /// The text.
    pub msg: String,
    /// Source file.
    pub file: String,
    /// Function (or module) that logged.
    pub function: String,
    /// Source line.
    pub line: u32,
}
ros_message!(Log, "rcl_interfaces", "Log");

impl Log {
    /// Debug level.
    pub const DEBUG: u8 = 10;
    /// Info level.
    pub const INFO: u8 = 20;
    /// Warning level.
    pub const WARN: u8 = 30;
    /// Error level.
    pub const ERROR: u8 = 40;
    /// Fatal level.
    pub const FATAL: u8 = 50;
}

/// `rcl_interfaces/msg/ParameterEvent`: what a node declared, changed or deleted, on
/// `/parameter_events`. `Parameter` (name and `ParameterValue`) is ros2-client's, the type
/// the parameter services already speak.
#[derive(Serialize, Deserialize, Debug, Clone)]
pub struct ParameterEvent {
    /// When it happened (the node's clock).
    pub stamp: Time,
    /// The node's fully qualified name.
    pub node: String,
    /// Parameters declared.
    pub new_parameters: Vec<Parameter>,
    /// Parameters set, with their new values.
    pub changed_parameters: Vec<Parameter>,
    /// Parameters undeclared.
    pub deleted_parameters: Vec<Parameter>,
}
ros_message!(ParameterEvent, "rcl_interfaces", "ParameterEvent");
