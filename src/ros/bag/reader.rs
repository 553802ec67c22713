//! [`BagReader`]: opens a ROS 2 MCAP bag (a `.mcap` file, or a rosbag2 directory holding
//! one) and streams its messages without loading the file into memory.
//!
//! A complete file is read through its summary: chunk by chunk, in log-time order, one
//! chunk (or a few that overlap in time) in memory at a time. A file without a usable
//! summary (a recording cut short, a truncated copy) is read front to back instead, in
//! file order, and every message before the damage is still yielded; the damage itself
//! comes out of the stream as an error item.

use std::collections::HashMap;
use std::fs::File;
use std::io::{Read, Seek};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mcap::sans_io::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};
use mcap::Summary;

use super::error::BagError;
use super::indexed::IndexedStream;
use super::linear::{message_reader, LinearStream};
use super::message::{channel_infos, BagMessage, CDR_ENCODING};

/// A topic of a bag.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicInfo {
    /// Topic name.
    pub topic: String,
    /// ROS type name, e.g. `sensor_msgs/msg/Imu`.
    pub type_name: String,
    /// Number of messages on the topic (those readable, for a file without summary).
    pub message_count: u64,
}

/// The order in which [`BagReader::messages`] yields messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadOrder {
    /// By log time (ties in file order): the file has a usable summary and index.
    LogTime,
    /// As stored: the file has no usable summary. Bags recorded or written in time order
    /// (rosbag2 recordings, this crate's writer fed in time order) are then in log-time
    /// order too.
    File,
}

/// How the file is read.
enum Layout {
    /// Through the summary and its chunk indexes.
    Indexed(Arc<Summary>),
    /// Front to back.
    Linear,
}

/// An open bag; see the module doc.
pub struct BagReader {
    /// The `.mcap` file.
    path: PathBuf,
    /// How the file is read.
    layout: Layout,
    /// Topics in channel order.
    topics: Vec<TopicInfo>,
}

/// The header string at the start of every SQLite 3 database (rosbag2's `.db3`).
const SQLITE_MAGIC: &[u8; 16] = b"SQLite format 3\0";

/// MCAP magic bytes at the start of every MCAP file.
const MCAP_MAGIC: &[u8] = mcap::MAGIC;

impl BagReader {
    /// Opens a bag: a `.mcap` file, or a directory holding exactly one `.mcap` file (the
    /// rosbag2 layout `BAG/BAG_0.mcap` + `metadata.yaml`). Fails on a file that is not
    /// MCAP or whose channels are not CDR; a damaged MCAP file opens, and the damage is
    /// reported while streaming.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, BagError> {
        let path = resolve_bag_file(path.as_ref())?;
        let mut file = open_file(&path)?;
        check_magic(&path, &mut file)?;
        let summary = read_summary(&path, &mut file);
        let (layout, topics) = match summary {
            Some(summary) if summary_is_usable(&summary) => {
                check_encodings(&path, &summary)?;
                let topics = indexed_topics(&summary);
                (Layout::Indexed(Arc::new(summary)), topics)
            }
            _ => (Layout::Linear, linear_topics(&path)?),
        };
        let reader = Self {
            path,
            layout,
            topics,
        };
        Ok(reader)
    }

    /// The `.mcap` file being read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The topics, in the order their channels were added.
    pub fn topics(&self) -> &[TopicInfo] {
        &self.topics
    }

    /// The order [`Self::messages`] yields messages in.
    pub fn read_order(&self) -> ReadOrder {
        match self.layout {
            Layout::Indexed(_) => ReadOrder::LogTime,
            Layout::Linear => ReadOrder::File,
        }
    }

    /// Streams the messages (see [`BagMessages`]); each call starts from the beginning.
    pub fn messages(&self) -> Result<BagMessages, BagError> {
        let file = open_file(&self.path)?;
        let stream = match &self.layout {
            Layout::Indexed(summary) => {
                Stream::Indexed(IndexedStream::new(self.path.clone(), file, summary.clone()))
            }
            Layout::Linear => Stream::Linear(LinearStream::new(self.path.clone(), file)),
        };
        Ok(BagMessages { stream })
    }
}

/// The message stream of a bag. Each `Err` item reports one problem (a corrupt chunk, a
/// truncated record, a non-CDR channel). Iteration may go on after an error: the stream
/// then resumes with the first message it can still read (after a corrupt chunk, the
/// next chunk), or ends (after a truncation). A caller counts the errors and decides
/// whether to stop at the first.
pub struct BagMessages {
    /// The reading strategy.
    stream: Stream,
}

/// The two reading strategies.
enum Stream {
    /// Log-time order through the index.
    Indexed(IndexedStream),
    /// File order, front to back.
    Linear(LinearStream),
}

impl Iterator for BagMessages {
    type Item = Result<BagMessage, BagError>;

    fn next(&mut self) -> Option<Self::Item> {
        match &mut self.stream {
            Stream::Indexed(stream) => stream.next(),
            Stream::Linear(stream) => stream.next(),
        }
    }
}

/// The `.mcap` file of `path`: `path` itself, or the only `.mcap` file in directory `path`.
fn resolve_bag_file(path: &Path) -> Result<PathBuf, BagError> {
    if !path.is_dir() {
        return Ok(path.to_path_buf());
    }
    let entries = std::fs::read_dir(path)
        .map_err(|source| BagError::io(path, "listing the bag directory", source))?;
    let mut files = Vec::new();
    let mut has_db3 = false;
    for entry in entries {
        let entry =
            entry.map_err(|source| BagError::io(path, "listing the bag directory", source))?;
        let file = entry.path();
        if file
            .extension()
            .is_some_and(|extension| extension == "mcap")
        {
            files.push(file);
        } else if file.extension().is_some_and(|extension| extension == "db3") {
            has_db3 = true;
        }
    }
    match files.as_slice() {
        [single] => Ok(single.clone()),
        [] if has_db3 => Err(BagError::Sqlite3 {
            path: path.to_path_buf(),
        }),
        _ => Err(BagError::BagDirectory {
            path: path.to_path_buf(),
            found: files.len(),
        }),
    }
}

/// Opens `path` for reading.
fn open_file(path: &Path) -> Result<File, BagError> {
    File::open(path).map_err(|source| BagError::io(path, "opening the file", source))
}

/// Fails unless `file` starts with the MCAP magic.
fn check_magic(path: &Path, file: &mut File) -> Result<(), BagError> {
    let len = file
        .metadata()
        .map_err(|source| BagError::io(path, "reading the file size", source))?
        .len();
    let mut magic = [0_u8; 8];
    let starts_with_magic = file.read_exact(&mut magic).is_ok() && magic == MCAP_MAGIC;
    if !starts_with_magic {
        let mut sqlite = [0_u8; 16];
        sqlite[..8].copy_from_slice(&magic);
        let is_sqlite = file.read_exact(&mut sqlite[8..]).is_ok() && &sqlite == SQLITE_MAGIC;
        if is_sqlite {
            return Err(BagError::Sqlite3 {
                path: path.to_path_buf(),
            });
        }
        return Err(BagError::NotMcap {
            path: path.to_path_buf(),
            len,
        });
    }
    Ok(())
}

/// The summary section of `file`, or None when it has none or it cannot be read (a
/// truncated or damaged file, which is then read front to back).
fn read_summary(path: &Path, file: &mut File) -> Option<Summary> {
    let len = file.metadata().ok()?.len();
    // No record can be longer than the file: a garbage length is an error, not an allocation.
    let options = SummaryReaderOptions::default()
        .with_file_size(len)
        .with_record_length_limit(usize::try_from(len).unwrap_or(usize::MAX));
    let mut reader = SummaryReader::new_with_options(options);
    while let Some(event) = reader.next_event() {
        match event {
            Ok(SummaryReadEvent::ReadRequest(need)) => {
                let read = file.read(reader.insert(need)).ok()?;
                reader.notify_read(read);
            }
            Ok(SummaryReadEvent::SeekRequest(to)) => {
                let position = file.seek(to).ok()?;
                reader.notify_seeked(position);
            }
            Err(error) => {
                log::debug!(
                    "{}: no usable summary ({error}), reading front to back",
                    path.display()
                );
                return None;
            }
        }
    }
    reader.finish()
}

/// True when the summary indexes every message: statistics present, and chunk indexes
/// for all chunks (a file written without chunks has messages no index points to).
fn summary_is_usable(summary: &Summary) -> bool {
    let Some(stats) = &summary.stats else {
        return false;
    };
    stats.message_count == 0
        || (stats.chunk_count > 0 && stats.chunk_count as usize == summary.chunk_indexes.len())
}

/// Fails when a channel of the summary does not carry CDR.
fn check_encodings(path: &Path, summary: &Summary) -> Result<(), BagError> {
    match summary
        .channels
        .values()
        .find(|channel| channel.message_encoding != CDR_ENCODING)
    {
        Some(channel) => Err(BagError::UnsupportedEncoding {
            path: path.to_path_buf(),
            topic: channel.topic.clone(),
            encoding: channel.message_encoding.clone(),
        }),
        None => Ok(()),
    }
}

/// Topics of an indexed file, in channel id order, with the counts of the statistics.
fn indexed_topics(summary: &Summary) -> Vec<TopicInfo> {
    let mut ids: Vec<u16> = summary.channels.keys().copied().collect();
    ids.sort_unstable();
    let infos = channel_infos(summary);
    ids.iter()
        .filter_map(|id| {
            let info = infos.get(id)?;
            let message_count = summary
                .stats
                .as_ref()
                .and_then(|stats| stats.channel_message_counts.get(id).copied())
                .unwrap_or(0);
            Some(TopicInfo {
                topic: info.topic.clone(),
                type_name: info.type_name.clone(),
                message_count,
            })
        })
        .collect()
}

/// Topics of a file without summary, found by reading it through once, in the order
/// their channels appear; counts are of the messages readable.
fn linear_topics(path: &Path) -> Result<Vec<TopicInfo>, BagError> {
    let file = open_file(path)?;
    let mut reader = message_reader(file);
    let mut topics: Vec<TopicInfo> = Vec::new();
    let mut index_by_channel: HashMap<u16, usize> = HashMap::new();
    for message in reader.by_ref() {
        let Ok(message) = message else { break };
        let index = *index_by_channel
            .entry(message.channel.id)
            .or_insert_with(|| {
                topics.push(TopicInfo {
                    topic: message.channel.topic.clone(),
                    type_name: message
                        .channel
                        .schema
                        .as_ref()
                        .map(|schema| schema.name.clone())
                        .unwrap_or_default(),
                    message_count: 0,
                });
                topics.len() - 1
            });
        if let Some(topic) = topics.get_mut(index) {
            topic.message_count += 1;
        }
    }
    Ok(topics)
}
