//! [`BagWriter`]: writes a ROS 2 bag as one MCAP file laid out as rosbag2's MCAP storage
//! plugin writes it: profile `ros2`, one `ros2msg` schema per message type holding the full
//! message definition, one `cdr` channel per topic with its `offered_qos_profiles`,
//! chunks (uncompressed, or zstd-compressed as rosbag2's `zstd_fast` preset writes them)
//! with message indexes, and a summary with chunk indexes and statistics, so readers can
//! seek.
//!
//! The output is a pure function of the calls made: no clock is read and nothing
//! time-dependent is written, so the same messages give the same bytes.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;

use super::definition::full_definition;
use super::error::BagError;
use super::qos::OfferedQos;
use crate::ros::cdr;
use crate::ros::msg::RosMessage;

/// Options of a [`BagWriter`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BagWriteOptions {
    /// Uncompressed size (bytes) at which a chunk is closed and a new one started.
    pub chunk_size_bytes: u64,
    /// Compression of the chunks.
    pub compression: ChunkCompression,
}

/// Choice: 768 KiB chunks, the default of the MCAP library rosbag2 records with; small
/// enough that a reader holds little in memory, large enough to keep the index short.
/// Uncompressed, as rosbag2's default.
impl Default for BagWriteOptions {
    fn default() -> Self {
        Self {
            chunk_size_bytes: 768 * 1024,
            compression: ChunkCompression::None,
        }
    }
}

/// How the chunks of a bag are compressed. Every rosbag2 MCAP reader (and the `rosbags`
/// package) reads both.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ChunkCompression {
    /// Stored as written.
    #[default]
    None,
    /// zstd at its fastest regular level, in the writing thread.
    ///
    /// Choice: level 1, single-threaded (no worker threads of zstd's own: the caller
    /// decides what runs beside what): a replay's output halves (the hour of
    /// `benches/data/replay_1h.yaml`: 680 MB to 340 MB) for about 2 ns of CPU per byte.
    Zstd,
}

/// A topic added to the bag.
#[derive(Debug)]
struct WriterTopic {
    /// MCAP channel id.
    channel_id: u16,
    /// ROS type name, e.g. `sensor_msgs/msg/Imu`.
    type_name: &'static str,
    /// Messages written so far (the MCAP sequence number of the next one is this + 1).
    count: u32,
}

/// Writes a rosbag2-compatible MCAP bag; see the module doc. Call [`BagWriter::finish`] to
/// learn about errors while closing the file.
pub struct BagWriter {
    /// The file being written.
    path: PathBuf,
    /// The MCAP writer.
    mcap: mcap::Writer<BufWriter<File>>,
    /// Schema id per ROS type name.
    schema_ids: BTreeMap<&'static str, u16>,
    /// Topics by name.
    topics: BTreeMap<String, WriterTopic>,
    /// The serialized message, reused from one message to the next.
    payload: Vec<u8>,
}

impl BagWriter {
    /// Creates (or truncates) the bag file `path` with the default options.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, BagError> {
        Self::create_with_options(path, BagWriteOptions::default())
    }

    /// Creates (or truncates) the bag file `path`.
    pub fn create_with_options(
        path: impl AsRef<Path>,
        options: BagWriteOptions,
    ) -> Result<Self, BagError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path)
            .map_err(|source| BagError::io(&path, "creating the file", source))?;
        // Choice: chunk CRCs are kept (rosbag2 turns them off) so corruption is detected.
        let mcap_options = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("adaptive_gnss_ins ", env!("CARGO_PKG_VERSION")))
            .chunk_size(Some(options.chunk_size_bytes));
        let mcap_options = match options.compression {
            ChunkCompression::None => mcap_options.compression(None),
            ChunkCompression::Zstd => mcap_options
                .compression(Some(mcap::Compression::Zstd))
                .compression_level(1)
                .compression_threads(0),
        };
        let mcap = mcap_options
            .create(BufWriter::new(file))
            .map_err(|source| BagError::mcap(&path, "writing the header", source))?;
        Ok(Self {
            path,
            mcap,
            schema_ids: BTreeMap::new(),
            topics: BTreeMap::new(),
            payload: Vec::new(),
        })
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Adds `topic` carrying `T` with the default offered QoS. Adding a topic again with
    /// the same type does nothing; with another type it is an error.
    pub fn add_topic<T: RosMessage>(&mut self, topic: &str) -> Result<(), BagError> {
        self.add_topic_with_qos::<T>(topic, &OfferedQos::default())
    }

    /// Adds `topic` carrying `T`, offered with `qos` (e.g. transient-local for `/tf_static`).
    pub fn add_topic_with_qos<T: RosMessage>(
        &mut self,
        topic: &str,
        qos: &OfferedQos,
    ) -> Result<(), BagError> {
        self.ensure_topic(topic, T::TYPE_NAME, qos).map(|_| ())
    }

    /// Serializes `message` to CDR and writes it on `topic` at `log_time_ns` (ns since the
    /// UNIX epoch; also used as publish time). An unknown topic is added with the default QoS.
    pub fn write<T: RosMessage>(
        &mut self,
        topic: &str,
        message: &T,
        log_time_ns: u64,
    ) -> Result<(), BagError> {
        self.ensure_topic(topic, T::TYPE_NAME, &OfferedQos::default())?;
        let mut payload = std::mem::take(&mut self.payload);
        let written = match cdr::encode_into(&mut payload, message) {
            Ok(()) => self.write_cdr(topic, &payload, log_time_ns),
            Err(source) => Err(BagError::Cdr {
                path: self.path.clone(),
                topic: topic.to_string(),
                source,
            }),
        };
        self.payload = payload;
        written
    }

    /// Writes an already serialized ROS 2 payload (encapsulation header + CDR body) on
    /// `topic`, which must have been added, at `log_time_ns`.
    pub fn write_cdr(
        &mut self,
        topic: &str,
        payload: &[u8],
        log_time_ns: u64,
    ) -> Result<(), BagError> {
        let Some(entry) = self.topics.get_mut(topic) else {
            return Err(BagError::UnknownTopic {
                path: self.path.clone(),
                topic: topic.to_string(),
            });
        };
        entry.count = entry.count.wrapping_add(1);
        let header = MessageHeader {
            channel_id: entry.channel_id,
            sequence: entry.count,
            log_time: log_time_ns,
            publish_time: log_time_ns,
        };
        self.mcap
            .write_to_known_channel(&header, payload)
            .map_err(|source| {
                BagError::mcap(&self.path, format!("writing a message on {topic}"), source)
            })
    }

    /// Writes the last chunk, the summary (schemas, channels, statistics, indexes) and the
    /// footer, and flushes the file.
    pub fn finish(mut self) -> Result<(), BagError> {
        self.mcap
            .finish()
            .map_err(|source| BagError::mcap(&self.path, "writing the summary", source))?;
        let path = self.path;
        self.mcap
            .into_inner()
            .into_inner()
            .map_err(|error| BagError::io(&path, "flushing the file", error.into_error()))?;
        Ok(())
    }

    /// Adds `topic` (and its schema) if new; checks its type otherwise.
    fn ensure_topic(
        &mut self,
        topic: &str,
        type_name: &'static str,
        qos: &OfferedQos,
    ) -> Result<u16, BagError> {
        if let Some(existing) = self.topics.get(topic) {
            if existing.type_name != type_name {
                return Err(BagError::TopicTypeMismatch {
                    path: self.path.clone(),
                    topic: topic.to_string(),
                    registered: existing.type_name.to_string(),
                    requested: type_name.to_string(),
                });
            }
            return Ok(existing.channel_id);
        }
        let schema_id = self.ensure_schema(type_name)?;
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), qos.to_yaml())]);
        let channel_id = self
            .mcap
            .add_channel(schema_id, topic, "cdr", &metadata)
            .map_err(|source| {
                BagError::mcap(&self.path, format!("adding topic {topic}"), source)
            })?;
        self.topics.insert(
            topic.to_string(),
            WriterTopic {
                channel_id,
                type_name,
                count: 0,
            },
        );
        Ok(channel_id)
    }

    /// Adds the schema of `type_name` if new.
    fn ensure_schema(&mut self, type_name: &'static str) -> Result<u16, BagError> {
        if let Some(id) = self.schema_ids.get(type_name) {
            return Ok(*id);
        }
        let definition = full_definition(type_name).map_err(|missing| BagError::NoDefinition {
            path: self.path.clone(),
            type_name: missing.type_name,
            root: type_name.to_string(),
        })?;
        let id = self
            .mcap
            .add_schema(type_name, "ros2msg", definition.as_bytes())
            .map_err(|source| {
                BagError::mcap(
                    &self.path,
                    format!("adding the schema of {type_name}"),
                    source,
                )
            })?;
        self.schema_ids.insert(type_name, id);
        Ok(id)
    }
}
