//! u-blox UBX input, pure (bytes in, values out): framing with checksum verification
//! (of a whole log, or of a stream arriving in chunks),
//! decoders for UBX-RXM-RAWX, UBX-RXM-SFRBX and UBX-NAV-PVT, navigation-message decoding
//! (GPS/QZSS LNAV, Galileo I/NAV, BeiDou D1/D2) into ephemerides, and the construction of a
//! [`crate::gnss::GnssEpoch`] from RAWX and the ephemerides.
//!
//! Choice: written against the UBX interface description and the ICDs rather than on the
//! `ublox` crate 0.10 (MIT), which decodes the UBX messages but the navigation subframes
//! of GPS only, so the Galileo and BeiDou work would remain anyway.

mod beidou_d1;
mod beidou_d2;
mod beidou_subframe;
mod bits;
mod broadcast_nav;
mod epoch;
mod error;
mod frame;
mod galileo_inav;
mod gps_lnav;
mod ids;
mod message;
mod nav_decoder;
mod nav_error;
mod nav_pvt;
mod rawx;
mod reader;
mod scanner;
mod sfrbx;
mod stream;

pub use crate::gnss::epoch_build::{preferred_signals, BuiltEpoch, EpochStats};
pub use beidou_d1::decode_d1_ephemeris;
pub use beidou_d2::{d2_page, decode_d2_ephemeris, D2_EPHEMERIS_PAGES};
pub use beidou_subframe::{bds_subframe, BdsSubframe};
pub use bits::Bits;
pub use broadcast_nav::{BroadcastNav, BroadcastNavStats};
pub use epoch::{build_epoch, build_epoch_with};
pub use error::UbxError;
pub use frame::{encode_frame, FrameReader, UbxFrame};
pub use galileo_inav::{crc24q, decode_inav_ephemeris, inav_word, InavWord};
pub use gps_lnav::{
    decode_lnav_ephemeris, decode_lnav_klobuchar, lnav_subframe, nearest_gps_time, LnavSubframe,
};
pub use ids::{sat_id, signal};
pub use message::{decode_message, UbxMessage};
pub use nav_decoder::{NavDecoder, NavDecoderStats, NavUpdate};
pub use nav_error::NavDataError;
pub use nav_pvt::{decode_nav_pvt, CarrierSolution, NavPvt};
pub use rawx::{decode_rawx, RawMeasurement, RawX, RawxBlock, TrackingStatus};
pub use reader::{read_ubx_log, read_ubx_log_with, UbxLog, UbxLogStats};
pub use scanner::{checksum, FrameStats, MAX_FRAME_LEN, MAX_PAYLOAD_LEN};
pub use sfrbx::{decode_sfrbx, Sfrbx};
pub use stream::UbxFramer;
