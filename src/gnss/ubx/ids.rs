//! u-blox GNSS and signal identifiers (UBX interface description, "GNSS identifiers" and
//! "Signal identifiers", F9/X20 generation) mapped to this crate's types.

use crate::gnss::ephemeris::Signal;
use crate::gnss::{Constellation, SatId};

/// u-blox gnssId of GPS.
pub const GNSS_GPS: u8 = 0;
/// u-blox gnssId of SBAS.
pub const GNSS_SBAS: u8 = 1;
/// u-blox gnssId of Galileo.
pub const GNSS_GALILEO: u8 = 2;
/// u-blox gnssId of BeiDou.
pub const GNSS_BEIDOU: u8 = 3;
/// u-blox gnssId of QZSS.
pub const GNSS_QZSS: u8 = 5;
/// u-blox gnssId of GLONASS.
pub const GNSS_GLONASS: u8 = 6;

/// The satellite of a u-blox (gnssId, svId); None for unknown systems (e.g. NavIC) or
/// svId 0.
pub fn sat_id(gnss_id: u8, sv_id: u8) -> Option<SatId> {
    let constellation = match gnss_id {
        GNSS_GPS => Constellation::Gps,
        GNSS_SBAS => Constellation::Sbas,
        GNSS_GALILEO => Constellation::Galileo,
        GNSS_BEIDOU => Constellation::Beidou,
        GNSS_QZSS => Constellation::Qzss,
        GNSS_GLONASS => Constellation::Glonass,
        _ => return None,
    };
    (sv_id != 0).then_some(SatId {
        constellation,
        prn: u16::from(sv_id),
    })
}

/// The signal of a u-blox (gnssId, sigId); None for signals this crate does not model
/// (GLONASS, QZSS other than L1 C/A, unknown ids).
///
/// Choice: BeiDou sigId 4 is B3I D1; the id of B3I D2 differs between receiver
/// generations, so D2 B3I is not mapped.
pub fn signal(gnss_id: u8, sig_id: u8) -> Option<Signal> {
    Some(match (gnss_id, sig_id) {
        (GNSS_GPS, 0) => Signal::GpsL1Ca,
        (GNSS_GPS, 3 | 4) => Signal::GpsL2C,
        (GNSS_GPS, 6 | 7) => Signal::GpsL5,
        (GNSS_SBAS, 0) => Signal::SbasL1,
        (GNSS_GALILEO, 0 | 1) => Signal::GalileoE1,
        (GNSS_GALILEO, 3 | 4) => Signal::GalileoE5a,
        (GNSS_GALILEO, 5 | 6) => Signal::GalileoE5b,
        (GNSS_GALILEO, 8..=10) => Signal::GalileoE6,
        (GNSS_BEIDOU, 0 | 1) => Signal::BeidouB1I,
        (GNSS_BEIDOU, 2 | 3) => Signal::BeidouB2I,
        (GNSS_BEIDOU, 4) => Signal::BeidouB3I,
        (GNSS_BEIDOU, 5 | 6) => Signal::BeidouB1C,
        (GNSS_BEIDOU, 7 | 8) => Signal::BeidouB2a,
        (GNSS_QZSS, 0) => Signal::QzssL1Ca,
        _ => return None,
    })
}
