//! Front-to-back streaming of a bag without usable summary (file order). The MCAP
//! library decodes one record or chunk at a time and checks chunk CRCs; the first
//! truncated or malformed record ends the stream, after every message before it.

use std::fs::File;
use std::io::BufReader;
use std::path::PathBuf;

use mcap::io::MessageReader;
use mcap::sans_io::LinearReaderOptions;

use super::error::BagError;
use super::message::{BagMessage, CDR_ENCODING};

/// The MCAP library's front-to-back reader over `file`, checking chunk CRCs.
pub(crate) fn message_reader(file: File) -> MessageReader<BufReader<File>> {
    // Choice: no record can be longer than the file. The limit turns a garbage record
    // length into an error instead of a huge allocation (which aborts the process).
    let file_len = file.metadata().map(|metadata| metadata.len()).unwrap_or(0);
    let record_length_limit = usize::try_from(file_len).unwrap_or(usize::MAX);
    let options = LinearReaderOptions::default()
        .with_validate_chunk_crcs(true)
        .with_record_length_limit(record_length_limit);
    MessageReader::new_with_options(BufReader::new(file), options)
}

/// Streams the messages of a file in file order.
pub(crate) struct LinearStream {
    /// The file.
    path: PathBuf,
    /// The MCAP library's streaming reader.
    reader: MessageReader<BufReader<File>>,
    /// Messages yielded so far (for error context).
    yielded: u64,
}

impl LinearStream {
    /// A stream over `file`.
    pub(crate) fn new(path: PathBuf, file: File) -> Self {
        Self {
            path,
            reader: message_reader(file),
            yielded: 0,
        }
    }

    /// The next message or problem; None at the end (also after a fatal problem).
    pub(crate) fn next(&mut self) -> Option<Result<BagMessage, BagError>> {
        let message = match self.reader.next()? {
            Ok(message) => message,
            Err(source) => {
                return Some(Err(BagError::mcap(
                    &self.path,
                    format!(
                        "reading front to back (no usable summary), after {} messages",
                        self.yielded
                    ),
                    source,
                )))
            }
        };
        if message.channel.message_encoding != CDR_ENCODING {
            return Some(Err(BagError::UnsupportedEncoding {
                path: self.path.clone(),
                topic: message.channel.topic.clone(),
                encoding: message.channel.message_encoding.clone(),
            }));
        }
        self.yielded += 1;
        Some(Ok(BagMessage {
            topic: message.channel.topic.clone(),
            type_name: message
                .channel
                .schema
                .as_ref()
                .map(|schema| schema.name.clone())
                .unwrap_or_default(),
            log_time_ns: message.log_time,
            data: message.data.into_owned(),
        }))
    }
}
