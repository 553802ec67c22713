//! Errors of the navigation-message (subframe/page) decoders.

use thiserror::Error;

use crate::gnss::SatId;

/// Why a navigation subframe or page was refused.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum NavDataError {
    /// Wrong number of data words for the message type.
    #[error("{sat}: {words} data words, {expected} expected")]
    WordCount {
        sat: SatId,
        words: usize,
        expected: usize,
    },
    /// GPS LNAV parity failure in a word (0-based).
    #[error("{sat}: LNAV parity error in word {word}")]
    Parity { sat: SatId, word: usize },
    /// GPS preamble or BeiDou preamble missing.
    #[error("{sat}: preamble missing")]
    Preamble { sat: SatId },
    /// BeiDou BCH(15,11) check failed in a word (0-based).
    #[error("{sat}: BCH error in word {word}")]
    Bch { sat: SatId, word: usize },
    /// Galileo page CRC-24Q failed.
    #[error("{sat}: I/NAV CRC mismatch")]
    Crc { sat: SatId },
    /// Galileo even/odd page parts out of order, or an alert page.
    #[error("{sat}: I/NAV page parts invalid (even/odd or page type)")]
    PageLayout { sat: SatId },
    /// Subframes of one frame whose clock and orbit parts contradict each other (GPS:
    /// IODC LSBs ≠ IODE; BeiDou: toc ≠ toe): corrupt or forged data, since a new upload
    /// only ever starts at a frame boundary.
    #[error("{sat}: clock and orbit subframes of one frame have different issues of data")]
    IssueMismatch { sat: SatId },
    /// A field beyond the data bits (never for subframes that passed their checks).
    #[error("{sat}: field beyond the navigation data bits")]
    MissingField { sat: SatId },
}
