//! Front-to-back streaming of a bag without usable summary (file order). The MCAP
//! library decodes one record or chunk at a time and checks chunk CRCs; the first
//! truncated or malformed record ends the stream, after every message before it.

use std::fs::File;
use std::io::BufReader;
use std::path::PathBuf;

use mcap::io::MessageReader;
use mcap::sans_io::LinearReaderOptions;

use super::error::BagError;
use super::reader::{BagMessage, CDR_ENCODING};

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
        let options = LinearReaderOptions::default().with_validate_chunk_crcs(true);
        Self {
            path,
            reader: MessageReader::new_with_options(BufReader::new(file), options),
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
