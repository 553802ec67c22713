//! Log-time streaming of a bag with a usable summary, through the chunk indexes.
//!
//! Choice: the chunks are split into groups whose time ranges overlap (sorted by start
//! time, a group grows while the next chunk starts before the group ends). Groups are
//! disjoint in time, so reading them one after another in log-time order gives the whole
//! file in log-time order with only the chunks of one group in memory at a time (one
//! chunk, mostly, in a bag written in time order).
//!
//! A chunk that cannot be read (I/O error, CRC mismatch, bad record) is reported, and the
//! group is read on without it. Math note: the MCAP library loads chunks in order of
//! start time and loads chunk F before yielding any message later than F's start time,
//! so when F fails every message yielded so far is at or before `start(F)` and none of
//! the other chunks' messages after `start(F)` has been yielded. The group is resumed
//! from `start(F)` without F, skipping the messages at exactly `start(F)` already yielded
//! (the resumed reader yields those first, in the same order, since the chunks holding
//! them are loaded before any chunk starting at `start(F)`).

use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mcap::records::{op, ChunkIndex, Record};
use mcap::sans_io::indexed_reader::ReadOrder;
use mcap::sans_io::{IndexedReadEvent, IndexedReader, IndexedReaderOptions};
use mcap::Summary;

use super::error::BagError;
use super::message::{channel_infos, BagMessage, ChannelInfo};

/// Choice: a chunk is trusted to decompress to at most 64 times the file length (zstd on
/// ROS messages reaches about 10); a corrupt index claiming more gives an error instead
/// of a huge allocation.
const MAX_COMPRESSION_RATIO: u64 = 64;

/// Length of a record's opcode and length prefix.
const RECORD_PREFIX_LEN: usize = 9;

/// The reader of the current group of chunks.
struct GroupReader {
    /// The MCAP library's indexed reader over the group.
    reader: IndexedReader,
    /// The group's chunk indexes (without those that failed).
    chunks: Vec<ChunkIndex>,
    /// After resuming at a failed chunk: messages at this log time still to skip.
    skip: Option<(u64, usize)>,
}

impl GroupReader {
    /// A log-time reader over `chunks` from `start_ns` on, skipping the first `skip`
    /// messages at exactly `start_ns`.
    fn new(
        chunks: Vec<ChunkIndex>,
        start_ns: Option<u64>,
        skip: usize,
        record_length_limit: usize,
    ) -> Result<Self, mcap::McapError> {
        let summary = Summary {
            chunk_indexes: chunks.clone(),
            ..Summary::default()
        };
        let mut options = IndexedReaderOptions::new().with_order(ReadOrder::LogTime);
        if let Some(start_ns) = start_ns {
            options = options.starting_at(start_ns);
        }
        options.record_length_limit = Some(record_length_limit);
        let reader = IndexedReader::new_with_options(&summary, options)?;
        Ok(Self {
            reader,
            chunks,
            skip: start_ns.map(|start_ns| (start_ns, skip)),
        })
    }

    /// True when the message at `log_time_ns` was already yielded before a resume.
    fn skips(&mut self, log_time_ns: u64) -> bool {
        match &mut self.skip {
            Some((time, count)) if *time == log_time_ns && *count > 0 => {
                *count -= 1;
                true
            }
            _ => {
                self.skip = None;
                false
            }
        }
    }
}

/// What one step of the group reader asks for.
enum Step {
    /// The group is exhausted.
    GroupDone,
    /// The group cannot be read further.
    Failed(BagError),
    /// The chunk whose compressed data starts at `offset` (`length` bytes) must be loaded.
    Load { offset: u64, length: usize },
    /// A message: channel, log time, payload.
    Message(u16, u64, Vec<u8>),
}

/// Streams the messages of an indexed file in log-time order.
pub(crate) struct IndexedStream {
    /// The file.
    path: PathBuf,
    /// Its handle.
    file: File,
    /// Its length (bytes): chunk indexes pointing past it are rejected.
    file_len: u64,
    /// Topic and type per channel id.
    channels: HashMap<u16, ChannelInfo>,
    /// Groups not read yet.
    groups: VecDeque<Vec<ChunkIndex>>,
    /// The group being read.
    current: Option<GroupReader>,
    /// Buffer of the chunk record being loaded.
    record: Vec<u8>,
    /// Largest chunk (compressed or not) accepted, in bytes.
    record_length_limit: usize,
    /// Log time of the last message yielded, and how many were yielded at that time.
    last_yielded: Option<(u64, usize)>,
}

impl IndexedStream {
    /// A stream over `file`, described by `summary`.
    pub(crate) fn new(path: PathBuf, file: File, summary: Arc<Summary>) -> Self {
        let file_len = file.metadata().map(|metadata| metadata.len()).unwrap_or(0);
        Self {
            path,
            file,
            file_len,
            channels: channel_infos(&summary),
            groups: overlap_groups(&summary.chunk_indexes),
            current: None,
            record: Vec::new(),
            record_length_limit: usize::try_from(file_len.saturating_mul(MAX_COMPRESSION_RATIO))
                .unwrap_or(usize::MAX),
            last_yielded: None,
        }
    }

    /// The next message or problem; None at the end.
    pub(crate) fn next(&mut self) -> Option<Result<BagMessage, BagError>> {
        loop {
            if self.current.is_none() {
                let chunks = self.groups.pop_front()?;
                match GroupReader::new(chunks, None, 0, self.record_length_limit) {
                    Ok(group) => self.current = Some(group),
                    Err(source) => {
                        return Some(Err(BagError::mcap(&self.path, "indexing chunks", source)))
                    }
                }
            }
            let current = self.current.as_mut()?;
            let step = match current.reader.next_event() {
                None => Step::GroupDone,
                Some(Err(source)) => Step::Failed(BagError::mcap(
                    &self.path,
                    "reading indexed messages",
                    source,
                )),
                Some(Ok(IndexedReadEvent::ReadChunkRequest { offset, length })) => {
                    Step::Load { offset, length }
                }
                Some(Ok(IndexedReadEvent::Message { header, data })) => {
                    Step::Message(header.channel_id, header.log_time, data.to_vec())
                }
            };
            match step {
                Step::GroupDone => self.current = None,
                Step::Failed(error) => {
                    self.current = None;
                    return Some(Err(error));
                }
                Step::Load { offset, length } => {
                    if let Err(error) = self.load(offset, length) {
                        self.resume_without(offset);
                        return Some(Err(error));
                    }
                }
                Step::Message(channel_id, log_time_ns, data) => {
                    if current.skips(log_time_ns) {
                        continue;
                    }
                    self.last_yielded = match self.last_yielded {
                        Some((time, count)) if time == log_time_ns => Some((time, count + 1)),
                        _ => Some((log_time_ns, 1)),
                    };
                    return Some(self.message(channel_id, log_time_ns, data));
                }
            }
        }
    }

    /// Loads the chunk whose compressed data starts at `offset` into the group reader.
    fn load(&mut self, offset: u64, length: usize) -> Result<(), BagError> {
        let Some(current) = self.current.as_mut() else {
            return Ok(());
        };
        let range = load_chunk(
            &self.path,
            &mut self.file,
            self.file_len,
            &mut self.record,
            &current.chunks,
            offset,
            length,
        )?;
        let data = self.record.get(range).unwrap_or_default();
        current
            .reader
            .insert_chunk_record_data(offset, data)
            .map_err(|source| {
                BagError::mcap(
                    &self.path,
                    format!("reading the chunk with data at byte {offset}"),
                    source,
                )
            })
    }

    /// Restarts the current group without the chunk whose data starts at `offset`, from
    /// that chunk's start time (see the module doc).
    fn resume_without(&mut self, offset: u64) {
        let Some(current) = self.current.take() else {
            return;
        };
        let (failed, remaining): (Vec<ChunkIndex>, Vec<ChunkIndex>) = current
            .chunks
            .into_iter()
            .partition(|chunk| chunk.compressed_data_offset().ok() == Some(offset));
        let Some(failed) = failed.first() else {
            return;
        };
        if remaining.is_empty() {
            return;
        }
        let start_ns = failed.message_start_time;
        let already_yielded = match self.last_yielded {
            Some((time, count)) if time == start_ns => count,
            _ => 0,
        };
        // A reader over chunks that were valid a moment ago cannot fail to build; if it
        // did, the group is dropped (its first chunk's error was already reported).
        self.current = GroupReader::new(
            remaining,
            Some(start_ns),
            already_yielded,
            self.record_length_limit,
        )
        .ok();
    }

    /// A [`BagMessage`] on channel `channel_id`.
    fn message(
        &self,
        channel_id: u16,
        log_time_ns: u64,
        data: Vec<u8>,
    ) -> Result<BagMessage, BagError> {
        match self.channels.get(&channel_id) {
            Some(channel) => Ok(BagMessage {
                topic: channel.topic.clone(),
                type_name: channel.type_name.clone(),
                log_time_ns,
                data,
            }),
            None => Err(BagError::mcap(
                &self.path,
                format!("reading a message at {log_time_ns} ns"),
                mcap::McapError::UnknownChannel(0, channel_id),
            )),
        }
    }
}

/// Chunk indexes grouped by overlapping time ranges, groups in time order.
fn overlap_groups(chunk_indexes: &[ChunkIndex]) -> VecDeque<Vec<ChunkIndex>> {
    let mut sorted: Vec<&ChunkIndex> = chunk_indexes.iter().collect();
    sorted.sort_by_key(|chunk| (chunk.message_start_time, chunk.chunk_start_offset));
    let mut groups: VecDeque<Vec<ChunkIndex>> = VecDeque::new();
    let mut group_end = 0_u64;
    for chunk in sorted {
        match groups.back_mut() {
            Some(group) if chunk.message_start_time <= group_end => {
                group.push(chunk.clone());
                group_end = group_end.max(chunk.message_end_time);
            }
            _ => {
                groups.push_back(vec![chunk.clone()]);
                group_end = chunk.message_end_time;
            }
        }
    }
    groups
}

/// Reads the chunk record whose compressed data starts at `data_offset` into `record`,
/// checks it (record type, length, CRC of uncompressed content) and returns the range of
/// its compressed data in `record`.
fn load_chunk(
    path: &Path,
    file: &mut File,
    file_len: u64,
    record: &mut Vec<u8>,
    chunks: &[ChunkIndex],
    data_offset: u64,
    data_len: usize,
) -> Result<Range<usize>, BagError> {
    let chunk = chunks
        .iter()
        .find(|chunk| chunk.compressed_data_offset().ok() == Some(data_offset))
        .ok_or(BagError::BadChunkIndex {
            path: path.to_path_buf(),
            chunk_offset: data_offset,
        })?;
    let chunk_offset = chunk.chunk_start_offset;
    let bad_index = || BagError::BadChunkIndex {
        path: path.to_path_buf(),
        chunk_offset,
    };
    let in_file = chunk_offset
        .checked_add(chunk.chunk_length)
        .is_some_and(|end| end <= file_len);
    let record_len = usize::try_from(chunk.chunk_length)
        .ok()
        .filter(|_| in_file)
        .ok_or_else(bad_index)?;
    let action = format!("reading the chunk at byte {chunk_offset}");
    file.seek(SeekFrom::Start(chunk_offset))
        .map_err(|source| BagError::io(path, action.clone(), source))?;
    record.resize(record_len, 0);
    file.read_exact(record)
        .map_err(|source| BagError::io(path, action.clone(), source))?;

    let (prefix, rest) = record
        .split_first_chunk::<RECORD_PREFIX_LEN>()
        .ok_or_else(bad_index)?;
    let [opcode, length_bytes @ ..] = *prefix;
    let body_len = usize::try_from(u64::from_le_bytes(length_bytes)).map_err(|_| bad_index())?;
    let body = rest.get(..body_len).ok_or_else(bad_index)?;
    if opcode != op::CHUNK {
        return Err(bad_index());
    }
    let (stored_crc, compression_empty, content) = match mcap::parse_record(op::CHUNK, body) {
        Ok(Record::Chunk { header, data }) => {
            (header.uncompressed_crc, header.compression.is_empty(), data)
        }
        Ok(_) => return Err(bad_index()),
        Err(source) => return Err(BagError::mcap(path, action, source)),
    };
    // Choice: the CRC is checked for uncompressed chunks (what this crate and rosbag2
    // write); a compressed chunk is checked by its decompressor. A stored CRC of 0 means
    // "not computed" (rosbag2's default).
    if compression_empty && stored_crc != 0 {
        let calculated = crc32fast::hash(&content);
        if calculated != stored_crc {
            return Err(BagError::ChunkCrc {
                path: path.to_path_buf(),
                chunk_offset,
                stored: stored_crc,
                calculated,
            });
        }
    }
    if content.len() != data_len {
        return Err(bad_index());
    }
    // The chunk's content is the last field of its body.
    let end = RECORD_PREFIX_LEN + body_len;
    Ok(end - data_len..end)
}
