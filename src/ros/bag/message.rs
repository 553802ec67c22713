//! The records the bag readers share: a still-serialized message, the channels of a
//! summary, and the message encoding of ROS 2 channels.

use std::collections::HashMap;

use mcap::Summary;

/// One message of a bag, still serialized: decode it with [`crate::ros::cdr::decode`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagMessage {
    /// Topic name.
    pub topic: String,
    /// ROS type name, e.g. `sensor_msgs/msg/Imu`.
    pub type_name: String,
    /// Log (receive) time, ns since the UNIX epoch.
    pub log_time_ns: u64,
    /// The ROS 2 payload: CDR encapsulation header + body.
    pub data: Vec<u8>,
}

/// Message encoding of ROS 2 channels.
pub(crate) const CDR_ENCODING: &str = "cdr";

/// Topic and type of an MCAP channel.
#[derive(Debug, Clone)]
pub(crate) struct ChannelInfo {
    /// Topic name.
    pub topic: String,
    /// ROS type name (the schema name; empty without schema).
    pub type_name: String,
}

/// Topic and type of every channel of the summary.
pub(crate) fn channel_infos(summary: &Summary) -> HashMap<u16, ChannelInfo> {
    summary
        .channels
        .iter()
        .map(|(id, channel)| {
            let info = ChannelInfo {
                topic: channel.topic.clone(),
                type_name: channel
                    .schema
                    .as_ref()
                    .map(|schema| schema.name.clone())
                    .unwrap_or_default(),
            };
            (*id, info)
        })
        .collect()
}
