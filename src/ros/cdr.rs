//! Whole ROS 2 serialized payloads: the 4-byte encapsulation header followed by a plain
//! (XCDR1) CDR body, as rmw implementations put them on the wire and rosbag2 stores them.
//!
//! Math note (alignment): CDR aligns every primitive to its own size, counted from the
//! first byte of the body, i.e. the byte after the encapsulation header. `cdr-encoding`
//! counts alignment from the first byte its serializer writes (and its deserializer
//! reads), so the body is written after the header by a fresh serializer and read from
//! `payload[4..]`: both count from the body's first byte, as ROS 2 does.

use byteorder::{BigEndian, LittleEndian};
use serde::{de::DeserializeOwned, Serialize};

/// Encapsulation identifier of plain CDR, big-endian (`CDR_BE`).
pub const CDR_BE: [u8; 2] = [0x00, 0x00];
/// Encapsulation identifier of plain CDR, little-endian (`CDR_LE`).
pub const CDR_LE: [u8; 2] = [0x00, 0x01];
/// Length of the encapsulation header: 2 bytes identifier + 2 bytes options.
pub const ENCAPSULATION_HEADER_LEN: usize = 4;
/// Bytes that may follow the body: writers may pad the payload to a multiple of 4.
pub const MAX_TRAILING_PADDING: usize = 3;

/// Why a payload could not be encoded or decoded.
#[derive(Debug, thiserror::Error)]
pub enum CdrError {
    /// The payload is too short to hold the encapsulation header.
    #[error("{type_name}: payload of {len} bytes has no 4-byte CDR encapsulation header")]
    MissingHeader {
        /// Rust type that was being decoded.
        type_name: &'static str,
        /// Length of the payload (bytes).
        len: usize,
    },
    /// The encapsulation identifier is not plain CDR (e.g. XCDR2 or a parameter list).
    #[error(
        "{type_name}: unsupported encapsulation {identifier:02x?}, expected CDR_BE 00 00 or CDR_LE 00 01"
    )]
    UnsupportedEncapsulation {
        /// Rust type that was being decoded.
        type_name: &'static str,
        /// The first two bytes of the payload.
        identifier: [u8; 2],
    },
    /// The body is truncated or does not match the type (bad bool, bad UTF-8, ...).
    #[error("{type_name}: malformed CDR body: {source}")]
    MalformedBody {
        /// Rust type that was being decoded.
        type_name: &'static str,
        /// What the CDR deserializer found.
        source: cdr_encoding::Error,
    },
    /// More bytes follow the message than alignment padding can explain.
    #[error(
        "{type_name}: {trailing} bytes left after the message, at most {MAX_TRAILING_PADDING} bytes of padding are allowed"
    )]
    TrailingBytes {
        /// Rust type that was being decoded.
        type_name: &'static str,
        /// Number of unread bytes after the body.
        trailing: usize,
    },
    /// The value could not be serialized (e.g. a sequence longer than `u32::MAX`).
    #[error("{type_name}: cannot serialize: {source}")]
    Serialize {
        /// Rust type that was being encoded.
        type_name: &'static str,
        /// What the CDR serializer reported.
        source: cdr_encoding::Error,
    },
}

/// Serializes `value` into a ROS 2 payload: the `CDR_LE` encapsulation header
/// `00 01 00 00` followed by the little-endian CDR body, without trailing padding.
pub fn encode<T: Serialize>(value: &T) -> Result<Vec<u8>, CdrError> {
    let mut payload = Vec::with_capacity(64);
    encode_into(&mut payload, value)?;
    Ok(payload)
}

/// [`encode`] into `payload`, replacing its content; a buffer reused from one message to
/// the next is allocated only when a message is larger than any before.
pub fn encode_into<T: Serialize>(payload: &mut Vec<u8>, value: &T) -> Result<(), CdrError> {
    payload.clear();
    payload.extend_from_slice(&CDR_LE);
    payload.extend_from_slice(&[0x00, 0x00]);
    // A fresh serializer counts alignment from the body's first byte (see module doc).
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut *payload, value).map_err(|source| {
        CdrError::Serialize {
            type_name: std::any::type_name::<T>(),
            source,
        }
    })
}

/// Deserializes a ROS 2 payload in `CDR_LE` or `CDR_BE` encapsulation. The two options
/// bytes of the header are ignored; up to [`MAX_TRAILING_PADDING`] bytes after the body
/// are accepted as padding. Never panics on malformed input.
pub fn decode<T: DeserializeOwned>(payload: &[u8]) -> Result<T, CdrError> {
    let type_name = std::any::type_name::<T>();
    let (header, body) = match payload.split_at_checked(ENCAPSULATION_HEADER_LEN) {
        Some(parts) => parts,
        None => {
            return Err(CdrError::MissingHeader {
                type_name,
                len: payload.len(),
            })
        }
    };
    let identifier = [header[0], header[1]];
    let decoded = match identifier {
        CDR_LE => cdr_encoding::from_bytes::<T, LittleEndian>(body),
        CDR_BE => cdr_encoding::from_bytes::<T, BigEndian>(body),
        _ => {
            return Err(CdrError::UnsupportedEncapsulation {
                type_name,
                identifier,
            })
        }
    };
    let (value, consumed) =
        decoded.map_err(|source| CdrError::MalformedBody { type_name, source })?;
    let trailing = body.len().saturating_sub(consumed);
    if trailing > MAX_TRAILING_PADDING {
        return Err(CdrError::TrailingBytes {
            type_name,
            trailing,
        });
    }
    Ok(value)
}
