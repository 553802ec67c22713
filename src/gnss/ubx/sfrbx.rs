//! UBX-RXM-SFRBX (0x02 0x13): one broadcast navigation-data subframe/page as received.

use super::error::{le, UbxError};

/// Message id of UBX-RXM-SFRBX (class UBX-RXM).
pub const ID_SFRBX: u8 = 0x13;
const NAME: &str = "UBX-RXM-SFRBX";
const HEADER_LEN: usize = 8;

/// A decoded SFRBX message: the raw 32-bit data words and their origin.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sfrbx {
    /// u-blox GNSS id.
    pub gnss_id: u8,
    /// Satellite number.
    pub sv_id: u8,
    /// u-blox signal id the data came from.
    pub sig_id: u8,
    /// GLONASS frequency slot + 7.
    pub freq_id: u8,
    /// Tracking channel.
    pub channel: u8,
    /// Message version.
    pub version: u8,
    /// The data words, in the per-system layout of the interface description.
    pub words: Vec<u32>,
}

/// Decodes an SFRBX payload; the length must be 8 + 4 · numWords.
pub fn decode_sfrbx(p: &[u8]) -> Result<Sfrbx, UbxError> {
    let num = usize::from(le::u8_at(p, 4).ok_or(UbxError::BadLength {
        message: NAME,
        expected: HEADER_LEN,
        actual: p.len(),
    })?);
    let expected = HEADER_LEN + 4 * num;
    let bad = UbxError::BadLength {
        message: NAME,
        expected,
        actual: p.len(),
    };
    if p.len() != expected {
        return Err(bad);
    }
    let words = (0..num)
        .map(|k| le::u32_at(p, HEADER_LEN + 4 * k))
        .collect::<Option<Vec<_>>>()
        .ok_or(bad.clone())?;
    let byte = |off| le::u8_at(p, off).ok_or(bad.clone());
    Ok(Sfrbx {
        gnss_id: byte(0)?,
        sv_id: byte(1)?,
        sig_id: byte(2)?,
        freq_id: byte(3)?,
        channel: byte(5)?,
        version: byte(6)?,
        words,
    })
}
