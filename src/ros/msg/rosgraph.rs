//! `rosgraph_msgs/msg/Clock`.

use serde::{Deserialize, Serialize};

use super::{ros_message, Time};

/// `rosgraph_msgs/msg/Clock`: the simulated time published on `/clock`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Clock {
    /// Current time.
    pub clock: Time,
}
ros_message!(Clock, "rosgraph_msgs", "Clock");
