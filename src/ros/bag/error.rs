//! What can go wrong while writing or reading a bag. Every variant names the file.

use std::path::PathBuf;

use crate::ros::cdr::CdrError;

/// Why a bag could not be written or read, or one problem met while streaming it.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// The operating system refused an operation on the file.
    #[error("{path}: {action}: {source}")]
    Io {
        /// The bag file (or directory).
        path: PathBuf,
        /// What was being done, e.g. "creating the file".
        action: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file does not start with the MCAP magic bytes (not an MCAP file, or empty).
    #[error("{path}: not an MCAP file (no MCAP magic at the start, {len} bytes long)")]
    NotMcap {
        /// The file.
        path: PathBuf,
        /// Length of the file (bytes).
        len: u64,
    },
    /// A rosbag2 bag in the sqlite3 storage (`.db3`), which this crate does not read.
    #[error(
        "{path}: a rosbag2 sqlite3 (.db3) bag; this tool reads MCAP bags: convert it with \
         `ros2 bag convert -i BAG -o out.yaml` (out.yaml: `output_bags: [{{uri: BAG_mcap, \
         storage_id: mcap}}]`) or with the `rosbags-convert` tool of the PyPI package rosbags"
    )]
    Sqlite3 {
        /// The `.db3` file or the directory holding it.
        path: PathBuf,
    },
    /// A directory given as a bag does not hold exactly one `.mcap` file.
    #[error("{path}: a bag directory must hold exactly one .mcap file, found {found}")]
    BagDirectory {
        /// The directory.
        path: PathBuf,
        /// Number of `.mcap` files found in it.
        found: usize,
    },
    /// The MCAP library reported a malformed, truncated or unsupported part of the file.
    #[error("{path}: {action}: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// What was being done, e.g. "reading chunk at byte 1234".
        action: String,
        /// What the MCAP library found.
        source: mcap::McapError,
    },
    /// A chunk's content does not match the CRC stored with it.
    #[error(
        "{path}: chunk at byte {chunk_offset} is corrupt: CRC {calculated:08x}, stored {stored:08x}"
    )]
    ChunkCrc {
        /// The file.
        path: PathBuf,
        /// File offset of the chunk record.
        chunk_offset: u64,
        /// CRC stored in the chunk record.
        stored: u32,
        /// CRC of the chunk's content as read.
        calculated: u32,
    },
    /// A chunk index points at bytes that are not a chunk record.
    #[error("{path}: the index points at byte {chunk_offset}, which holds no chunk record")]
    BadChunkIndex {
        /// The file.
        path: PathBuf,
        /// File offset the index gave for the chunk.
        chunk_offset: u64,
    },
    /// The message definition of a type (or of a type it nests) is unknown to this crate.
    #[error("{path}: no message definition for {type_name} (needed by {root})")]
    NoDefinition {
        /// The file being written.
        path: PathBuf,
        /// The type whose `.msg` text is missing.
        type_name: String,
        /// The topic type that needs it.
        root: String,
    },
    /// A topic was given two different message types.
    #[error("{path}: topic {topic} holds {registered}, cannot write {requested} to it")]
    TopicTypeMismatch {
        /// The file being written.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Type the topic was added with.
        registered: String,
        /// Type of the rejected message.
        requested: String,
    },
    /// Raw CDR was written to a topic that was never added (its type is unknown).
    #[error("{path}: topic {topic} was not added before writing serialized data to it")]
    UnknownTopic {
        /// The file being written.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// A message could not be serialized to CDR.
    #[error("{path}: topic {topic}: {source}")]
    Cdr {
        /// The file being written.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// What the CDR encoder reported.
        source: CdrError,
    },
    /// A channel's messages are not CDR (the only encoding ROS 2 bags use).
    #[error("{path}: topic {topic} has message encoding {encoding:?}, expected \"cdr\"")]
    UnsupportedEncoding {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The channel's message encoding.
        encoding: String,
    },
}

impl BagError {
    /// An [`BagError::Io`] for `path`.
    pub(crate) fn io(
        path: &std::path::Path,
        action: impl Into<String>,
        source: std::io::Error,
    ) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            action: action.into(),
            source,
        }
    }

    /// A [`BagError::Mcap`] for `path`.
    pub(crate) fn mcap(
        path: &std::path::Path,
        action: impl Into<String>,
        source: mcap::McapError,
    ) -> Self {
        Self::Mcap {
            path: path.to_path_buf(),
            action: action.into(),
            source,
        }
    }
}
