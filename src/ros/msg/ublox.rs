//! `ublox_ubx_msgs` messages of the ROS 2 u-blox driver `ublox_dgnss`
//! (github.com/aussierobots/ublox_dgnss): raw measurements (UBX-RXM-RAWX) and navigation
//! subframes (UBX-RXM-SFRBX), one message per UBX frame, the fields copied from the
//! payload as they are (no scaling). The driver stamps `header.stamp` with the host time
//! at which it read the frame from the receiver and sets `header.frame_id` to its
//! `frame_id` parameter.

use serde::{Deserialize, Serialize};

use super::{ros_message, Header};

/// `ublox_ubx_msgs/msg/RecStat`: receiver status bits of a RAWX message (recStat).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecStat {
    /// The leap seconds are known (bit 0).
    pub leap_sec: bool,
    /// The receiver clock was reset (bit 1).
    pub clk_reset: bool,
}
ros_message!(RecStat, "ublox_ubx_msgs", "RecStat");

/// `ublox_ubx_msgs/msg/TrkStat`: tracking status bits of one measurement (trkStat).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TrkStat {
    /// Pseudo-range valid (bit 0).
    pub pr_valid: bool,
    /// Carrier phase valid (bit 1).
    pub cp_valid: bool,
    /// Half-cycle valid (bit 2).
    pub half_cyc: bool,
    /// Half-cycle subtracted from the phase (bit 3).
    pub sub_half_cyc: bool,
}
ros_message!(TrkStat, "ublox_ubx_msgs", "TrkStat");

/// `ublox_ubx_msgs/msg/RawxData`: one measurement block of a RAWX message.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct RawxData {
    /// Pseudo-range (m).
    pub pr_mes: f64,
    /// Carrier phase (cycles).
    pub cp_mes: f64,
    /// Doppler (Hz), positive for an approaching satellite.
    pub do_mes: f32,
    /// u-blox GNSS id.
    pub gnss_id: u8,
    /// Satellite number within the GNSS.
    pub sv_id: u8,
    /// u-blox signal id.
    pub sig_id: u8,
    /// GLONASS frequency slot + 7.
    pub freq_id: u8,
    /// Carrier-phase lock time (ms).
    pub locktime: u16,
    /// Carrier-to-noise density (dB-Hz).
    pub c_no: u8,
    /// Pseudo-range σ code, the payload byte (bits 0–3: n of 0.01 · 2^n m).
    pub pr_stdev: u8,
    /// Carrier-phase σ code, the payload byte (bits 0–3: n of 0.004 · n cycles).
    pub cp_stdev: u8,
    /// Doppler σ code, the payload byte (bits 0–3: n of 0.002 · 2^n Hz).
    pub do_stdev: u8,
    /// Tracking status.
    pub trk_stat: TrkStat,
}
ros_message!(RawxData, "ublox_ubx_msgs", "RawxData");

/// `ublox_ubx_msgs/msg/UBXRxmRawx` (topic `ubx_rxm_rawx`): the raw measurements of one
/// receiver epoch.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct UbxRxmRawx {
    /// Host receive time and the driver's frame.
    pub header: Header,
    /// Receiver time of week of the measurements (s).
    pub rcv_tow: f64,
    /// GPS week of the receiver time.
    pub week: u16,
    /// GPS − UTC leap seconds (s).
    pub leap_s: i8,
    /// Number of measurement blocks (the length of `rawx_data` when well formed).
    pub num_meas: u8,
    /// Receiver status.
    pub rec_stat: RecStat,
    /// Message version.
    pub version: u8,
    /// The measurements.
    pub rawx_data: Vec<RawxData>,
}
ros_message!(UbxRxmRawx, "ublox_ubx_msgs", "UBXRxmRawx");

/// `ublox_ubx_msgs/msg/UBXRxmSfrbx` (topic `ubx_rxm_sfrbx`): one broadcast navigation
/// subframe or page.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct UbxRxmSfrbx {
    /// Host receive time and the driver's frame.
    pub header: Header,
    /// u-blox GNSS id.
    pub gnss_id: u8,
    /// Satellite number.
    pub sv_id: u8,
    /// u-blox signal id.
    pub sig_id: u8,
    /// GLONASS frequency slot + 7.
    pub freq_id: u8,
    /// Number of data words (the length of `dwrd` when well formed).
    pub num_words: u8,
    /// Tracking channel.
    pub chn: u8,
    /// Message version.
    pub version: u8,
    /// The data words.
    pub dwrd: Vec<u32>,
}
ros_message!(UbxRxmSfrbx, "ublox_ubx_msgs", "UBXRxmSfrbx");

/// `ublox_ubx_msgs/msg/CarrSoln`: the carrier-phase range solution of a NAV-RELPOSNED
/// message (flags.carrSoln).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CarrSoln {
    /// One of the `CARRIER_SOLUTION_*` values.
    pub status: u8,
}
ros_message!(CarrSoln, "ublox_ubx_msgs", "CarrSoln");

impl CarrSoln {
    /// No carrier-phase range solution.
    pub const NO_CARRIER_RANGE_SOLUTION: u8 = 0;
    /// Carrier phase with floating ambiguities.
    pub const PHASE_WITH_FLOATING_AMBIGUITIES: u8 = 1;
    /// Carrier phase with fixed ambiguities.
    pub const PHASE_WITH_FIXED_AMBIGUITIES: u8 = 2;
}

/// `ublox_ubx_msgs/msg/UBXNavRelPosNED` (topic `ubx_nav_rel_pos_ned`): the relative
/// position of the rover's antenna from the reference (UBX-NAV-RELPOSNED), in the payload's
/// integer units. In moving-base mode the reference is the moving base's antenna, and the
/// relative position is the baseline between the two antennas.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub struct UbxNavRelPosNed {
    /// Host receive time and the driver's frame.
    pub header: Header,
    /// Message version.
    pub version: u8,
    /// Reference station id (0..4095).
    pub ref_station_id: u16,
    /// GPS time of week of the navigation epoch (ms).
    pub itow: u32,
    /// North, east and down components of the relative position (cm).
    pub rel_pos_n: i32,
    pub rel_pos_e: i32,
    pub rel_pos_d: i32,
    /// Length of the relative position (cm).
    pub rel_pos_length: i32,
    /// Heading of the relative position, clockwise from north (1e-5 deg).
    pub rel_pos_heading: i32,
    /// High-precision parts of the components and the length (0.1 mm): the full value is
    /// the cm field + this × 1e-2 cm.
    pub rel_pos_hp_n: i8,
    pub rel_pos_hp_e: i8,
    pub rel_pos_hp_d: i8,
    pub rel_pos_hp_length: i8,
    /// Accuracies of the components and the length (0.1 mm).
    pub acc_n: u32,
    pub acc_e: u32,
    pub acc_d: u32,
    pub acc_length: u32,
    /// Accuracy of the heading (1e-5 deg).
    pub acc_heading: u32,
    /// A valid fix (within the DOP and accuracy masks).
    pub gnss_fix_ok: bool,
    /// Differential corrections were applied.
    pub diff_soln: bool,
    /// The components and accuracies are valid (moving base: the baseline too).
    pub rel_pos_valid: bool,
    pub carr_soln: CarrSoln,
    /// The receiver is in moving-base mode.
    pub is_moving: bool,
    /// An extrapolated reference position was used this epoch.
    pub ref_pos_miss: bool,
    /// Extrapolated reference observations were used this epoch.
    pub ref_obs_miss: bool,
    /// `rel_pos_heading` is valid.
    pub rel_pos_heading_valid: bool,
    /// The components (high-precision parts included) are normalized.
    pub rel_pos_normalized: bool,
}
ros_message!(UbxNavRelPosNed, "ublox_ubx_msgs", "UBXNavRelPosNED");
