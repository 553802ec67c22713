//! `diagnostic_msgs` messages.

use serde::{Deserialize, Serialize};

use super::{ros_message, Header};

/// `diagnostic_msgs/msg/KeyValue`: one named value of a diagnostic status.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct KeyValue {
    /// Name of the value.
    pub key: String,
    /// The value, as text.
    pub value: String,
}
ros_message!(KeyValue, "diagnostic_msgs", "KeyValue");

/// `diagnostic_msgs/msg/DiagnosticStatus`: the state of one component.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct DiagnosticStatus {
    /// One of the level constants (`OK`, `WARN`, `ERROR`, `STALE`).
    pub level: u8,
    /// Name of the component.
    pub name: String,
    /// Human-readable summary.
    pub message: String,
    /// Hardware identifier, if any.
    pub hardware_id: String,
    /// Named values.
    pub values: Vec<KeyValue>,
}
ros_message!(DiagnosticStatus, "diagnostic_msgs", "DiagnosticStatus");

impl DiagnosticStatus {
    /// Working as expected.
    pub const OK: u8 = 0;
    /// Degraded.
    pub const WARN: u8 = 1;
    /// Failed.
    pub const ERROR: u8 = 2;
    /// No recent data.
    pub const STALE: u8 = 3;
}

/// `diagnostic_msgs/msg/DiagnosticArray`: statuses of several components.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct DiagnosticArray {
    /// Time of the report.
    pub header: Header,
    /// One status per component.
    pub status: Vec<DiagnosticStatus>,
}
ros_message!(DiagnosticArray, "diagnostic_msgs", "DiagnosticArray");
