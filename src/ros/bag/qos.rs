//! The `offered_qos_profiles` metadata of a bag channel: the QoS a player should publish
//! the topic with, as rosbag2 (Jazzy, metadata version 9) serializes it: a YAML list of
//! profiles with lower-case policy names.

/// Delivery guarantee of a topic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reliability {
    /// Every sample is delivered (retransmitted if lost).
    #[default]
    Reliable,
    /// Samples may be lost.
    BestEffort,
}

/// Whether late subscribers get samples published before they joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Durability {
    /// Only samples published after a subscriber joined.
    #[default]
    Volatile,
    /// The last `depth` samples are kept for late subscribers (e.g. `/tf_static`).
    TransientLocal,
}

/// One offered QoS profile (history is always keep-last).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OfferedQos {
    /// Reliability policy.
    pub reliability: Reliability,
    /// Durability policy.
    pub durability: Durability,
    /// History depth (samples kept).
    pub depth: u32,
}

/// Reliable, volatile, depth 10: the `rclcpp` default a plain publisher offers.
impl Default for OfferedQos {
    fn default() -> Self {
        Self {
            reliability: Reliability::Reliable,
            durability: Durability::Volatile,
            depth: 10,
        }
    }
}

/// Seconds part of `RMW_DURATION_INFINITE` (i64::MAX ns), as rosbag2 writes "no deadline".
const INFINITE_SEC: i64 = i64::MAX / 1_000_000_000;
/// Nanoseconds part of `RMW_DURATION_INFINITE`.
const INFINITE_NSEC: i64 = i64::MAX % 1_000_000_000;

impl OfferedQos {
    /// The `offered_qos_profiles` YAML of this single profile: deadline, lifespan and
    /// liveliness lease infinite, automatic liveliness, ROS namespace conventions kept.
    pub fn to_yaml(&self) -> String {
        let reliability = match self.reliability {
            Reliability::Reliable => "reliable",
            Reliability::BestEffort => "best_effort",
        };
        let durability = match self.durability {
            Durability::Volatile => "volatile",
            Durability::TransientLocal => "transient_local",
        };
        let infinite = format!("\n    sec: {INFINITE_SEC}\n    nsec: {INFINITE_NSEC}");
        format!(
            "- history: keep_last\n  depth: {depth}\n  reliability: {reliability}\n  \
             durability: {durability}\n  deadline:{infinite}\n  lifespan:{infinite}\n  \
             liveliness: automatic\n  liveliness_lease_duration:{infinite}\n  \
             avoid_ros_namespace_conventions: false",
            depth = self.depth,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_profile_yaml_parses_to_the_expected_values() {
        let yaml = OfferedQos::default().to_yaml();
        let parsed: serde_yaml::Value = serde_yaml::from_str(&yaml).unwrap();
        let profile = &parsed[0];
        assert_eq!(profile["history"], "keep_last");
        assert_eq!(profile["depth"], 10);
        assert_eq!(profile["reliability"], "reliable");
        assert_eq!(profile["durability"], "volatile");
        assert_eq!(profile["deadline"]["sec"], 9_223_372_036_i64);
        assert_eq!(profile["deadline"]["nsec"], 854_775_807);
        assert_eq!(profile["avoid_ros_namespace_conventions"], false);
    }

    #[test]
    fn transient_local_best_effort_is_spelled_as_rosbag2_does() {
        let qos = OfferedQos {
            reliability: Reliability::BestEffort,
            durability: Durability::TransientLocal,
            depth: 1,
        };
        let parsed: serde_yaml::Value = serde_yaml::from_str(&qos.to_yaml()).unwrap();
        assert_eq!(parsed[0]["reliability"], "best_effort");
        assert_eq!(parsed[0]["durability"], "transient_local");
        assert_eq!(parsed[0]["depth"], 1);
    }
}
