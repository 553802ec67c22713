//! Dispatch of a checksum-verified frame to its decoder.

use super::error::UbxError;
use super::frame::UbxFrame;
use super::nav_pvt::{decode_nav_pvt, NavPvt, CLASS_NAV, ID_PVT};
use super::rawx::{decode_rawx, RawX, CLASS_RXM, ID_RAWX};
use super::sfrbx::{decode_sfrbx, Sfrbx, ID_SFRBX};

/// A decoded UBX message of the kinds this crate uses.
#[derive(Debug, Clone, PartialEq)]
pub enum UbxMessage {
    /// UBX-RXM-RAWX.
    RawX(RawX),
    /// UBX-RXM-SFRBX.
    Sfrbx(Sfrbx),
    /// UBX-NAV-PVT.
    NavPvt(NavPvt),
    /// Any other (class, id): not decoded.
    Unknown { class: u8, id: u8 },
}

/// Decodes a frame's payload by its class and id.
pub fn decode_message(frame: &UbxFrame<'_>) -> Result<UbxMessage, UbxError> {
    Ok(match (frame.class, frame.id) {
        (CLASS_RXM, ID_RAWX) => UbxMessage::RawX(decode_rawx(frame.payload)?),
        (CLASS_RXM, ID_SFRBX) => UbxMessage::Sfrbx(decode_sfrbx(frame.payload)?),
        (CLASS_NAV, ID_PVT) => UbxMessage::NavPvt(decode_nav_pvt(frame.payload)?),
        (class, id) => UbxMessage::Unknown { class, id },
    })
}
