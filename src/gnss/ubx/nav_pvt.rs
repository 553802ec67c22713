//! UBX-NAV-PVT (0x01 0x07): the receiver's navigation solution, used as a reference
//! trajectory.

use super::error::{le, UbxError};

/// Message class of UBX-NAV.
pub const CLASS_NAV: u8 = 0x01;
/// Message id of UBX-NAV-PVT.
pub const ID_PVT: u8 = 0x07;
const NAME: &str = "UBX-NAV-PVT";
/// Payload length of NAV-PVT (protocol ≥ 14).
pub const PVT_LEN: usize = 92;

/// Carrier-phase solution status (flags bits 6–7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CarrierSolution {
    /// No carrier-phase solution.
    None,
    /// RTK float.
    Float,
    /// RTK fixed.
    Fixed,
}

/// A decoded NAV-PVT message, in SI units (angles in radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavPvt {
    /// GPS time of week of the navigation epoch (ms).
    pub itow_ms: u32,
    /// UTC date and time: year, month, day, hour, minute, second.
    pub utc: (u16, u8, u8, u8, u8, u8),
    /// Fix type: 0 none, 1 dead reckoning, 2 2D, 3 3D, 4 GNSS + DR, 5 time only.
    pub fix_type: u8,
    /// Valid fix within the accuracy masks (flags bit 0).
    pub gnss_fix_ok: bool,
    /// Differential corrections applied (flags bit 1).
    pub diff_solution: bool,
    /// Carrier-phase solution status.
    pub carrier_solution: CarrierSolution,
    /// Satellites used.
    pub num_sv: u8,
    /// Longitude (rad).
    pub lon_rad: f64,
    /// Latitude (rad).
    pub lat_rad: f64,
    /// Height above the ellipsoid (m).
    pub height_m: f64,
    /// Height above mean sea level (m).
    pub height_msl_m: f64,
    /// Horizontal accuracy estimate (m).
    pub h_acc_m: f64,
    /// Vertical accuracy estimate (m).
    pub v_acc_m: f64,
    /// Velocity north, east, down (m/s).
    pub vel_ned_mps: [f64; 3],
    /// Speed accuracy estimate (m/s).
    pub speed_acc_mps: f64,
    /// Position DOP.
    pub pdop: f64,
}

/// Decodes a NAV-PVT payload (exactly 92 bytes).
pub fn decode_nav_pvt(p: &[u8]) -> Result<NavPvt, UbxError> {
    if p.len() != PVT_LEN {
        return Err(UbxError::BadLength {
            message: NAME,
            expected: PVT_LEN,
            actual: p.len(),
        });
    }
    parse(p).ok_or(UbxError::BadLength {
        message: NAME,
        expected: PVT_LEN,
        actual: p.len(),
    })
}

fn parse(p: &[u8]) -> Option<NavPvt> {
    let flags = le::u8_at(p, 21)?;
    let carrier_solution = match (flags >> 6) & 0x03 {
        1 => CarrierSolution::Float,
        2 => CarrierSolution::Fixed,
        _ => CarrierSolution::None,
    };
    let deg = |v: i32| (f64::from(v) * 1e-7).to_radians();
    let mm = |v: i32| f64::from(v) * 1e-3;
    let umm = |v: u32| f64::from(v) * 1e-3;
    Some(NavPvt {
        itow_ms: le::u32_at(p, 0)?,
        utc: (
            le::u16_at(p, 4)?,
            le::u8_at(p, 6)?,
            le::u8_at(p, 7)?,
            le::u8_at(p, 8)?,
            le::u8_at(p, 9)?,
            le::u8_at(p, 10)?,
        ),
        fix_type: le::u8_at(p, 20)?,
        gnss_fix_ok: flags & 0x01 != 0,
        diff_solution: flags & 0x02 != 0,
        carrier_solution,
        num_sv: le::u8_at(p, 23)?,
        lon_rad: deg(le::i32_at(p, 24)?),
        lat_rad: deg(le::i32_at(p, 28)?),
        height_m: mm(le::i32_at(p, 32)?),
        height_msl_m: mm(le::i32_at(p, 36)?),
        h_acc_m: umm(le::u32_at(p, 40)?),
        v_acc_m: umm(le::u32_at(p, 44)?),
        vel_ned_mps: [
            mm(le::i32_at(p, 48)?),
            mm(le::i32_at(p, 52)?),
            mm(le::i32_at(p, 56)?),
        ],
        speed_acc_mps: umm(le::u32_at(p, 68)?),
        pdop: f64::from(le::u16_at(p, 76)?) * 0.01,
    })
}
