//! Errors of the UBX decoders.

use thiserror::Error;

/// Why a UBX payload could not be decoded.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum UbxError {
    /// The payload length does not match what the message layout requires.
    #[error("{message}: payload of {actual} bytes, layout needs {expected}")]
    BadLength {
        message: &'static str,
        expected: usize,
        actual: usize,
    },
    /// A field holds a value outside its documented range.
    #[error("{message}: invalid {field} = {value}")]
    InvalidField {
        message: &'static str,
        field: &'static str,
        value: i64,
    },
}

/// Little-endian field readers over a payload; None past the end.
pub(crate) mod le {
    pub fn u8_at(p: &[u8], off: usize) -> Option<u8> {
        p.get(off).copied()
    }
    pub fn i8_at(p: &[u8], off: usize) -> Option<i8> {
        p.get(off).map(|&b| b as i8)
    }
    fn array<const N: usize>(p: &[u8], off: usize) -> Option<[u8; N]> {
        p.get(off..off.checked_add(N)?)?.try_into().ok()
    }
    pub fn u16_at(p: &[u8], off: usize) -> Option<u16> {
        array(p, off).map(u16::from_le_bytes)
    }
    pub fn u32_at(p: &[u8], off: usize) -> Option<u32> {
        array(p, off).map(u32::from_le_bytes)
    }
    pub fn i32_at(p: &[u8], off: usize) -> Option<i32> {
        array(p, off).map(i32::from_le_bytes)
    }
    pub fn f32_at(p: &[u8], off: usize) -> Option<f32> {
        array(p, off).map(f32::from_le_bytes)
    }
    pub fn f64_at(p: &[u8], off: usize) -> Option<f64> {
        array(p, off).map(f64::from_le_bytes)
    }
}
