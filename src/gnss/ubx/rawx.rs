//! UBX-RXM-RAWX (0x02 0x15): multi-GNSS raw measurements of one receiver epoch.

use super::error::{le, UbxError};

/// Message class of UBX-RXM.
pub const CLASS_RXM: u8 = 0x02;
/// Message id of UBX-RXM-RAWX.
pub const ID_RAWX: u8 = 0x15;
const NAME: &str = "UBX-RXM-RAWX";
const HEADER_LEN: usize = 16;
const BLOCK_LEN: usize = 32;

/// Tracking status bits (trkStat) of one measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackingStatus {
    /// Pseudo-range valid.
    pub pr_valid: bool,
    /// Carrier phase valid.
    pub cp_valid: bool,
    /// Half-cycle valid.
    pub half_cycle_valid: bool,
    /// Half-cycle subtracted from the phase.
    pub half_cycle_subtracted: bool,
}

/// One measurement (satellite, signal) of a RAWX message, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawMeasurement {
    /// Pseudo-range (m).
    pub pseudorange_m: f64,
    /// Carrier phase (cycles).
    pub carrier_phase_cycles: f64,
    /// Doppler (Hz), positive for an approaching satellite.
    pub doppler_hz: f64,
    /// u-blox GNSS id (0 GPS, 1 SBAS, 2 Galileo, 3 BeiDou, 5 QZSS, 6 GLONASS, 7 NavIC).
    pub gnss_id: u8,
    /// Satellite number within the GNSS.
    pub sv_id: u8,
    /// u-blox signal id within the GNSS.
    pub sig_id: u8,
    /// GLONASS frequency slot + 7 (other systems: unused).
    pub freq_id: u8,
    /// Carrier-phase lock time (s), saturating at 64.5 s.
    pub lock_time_s: f64,
    /// Carrier-to-noise density (dB-Hz).
    pub cn0_dbhz: f64,
    /// Pseudo-range 1σ (m): 0.01 · 2^n.
    pub pseudorange_sigma_m: f64,
    /// Carrier-phase 1σ (cycles): 0.004 · n.
    pub carrier_phase_sigma_cycles: f64,
    /// Doppler 1σ (Hz): 0.002 · 2^n.
    pub doppler_sigma_hz: f64,
    /// Tracking status.
    pub tracking: TrackingStatus,
}

/// A decoded UBX-RXM-RAWX message.
#[derive(Debug, Clone, PartialEq)]
pub struct RawX {
    /// Receiver time of week of the measurements (s), receiver clock, ≈ GPST.
    pub rcv_tow_s: f64,
    /// GPS week of the receiver time.
    pub week: u16,
    /// GPS − UTC leap seconds (s).
    pub leap_s: i8,
    /// Whether the leap seconds are known (recStat bit 0).
    pub leap_s_valid: bool,
    /// Whether the receiver clock was reset (recStat bit 1): phases discontinuous.
    pub clock_reset: bool,
    /// Message version.
    pub version: u8,
    /// The measurements.
    pub measurements: Vec<RawMeasurement>,
}

/// One measurement block as transmitted: the RAWX payload's fields, unscaled (what a
/// driver's message such as `ublox_ubx_msgs/RawxData` copies).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawxBlock {
    /// prMes (m).
    pub pr_mes: f64,
    /// cpMes (cycles).
    pub cp_mes: f64,
    /// doMes (Hz).
    pub do_mes: f32,
    pub gnss_id: u8,
    pub sv_id: u8,
    pub sig_id: u8,
    pub freq_id: u8,
    /// locktime (ms).
    pub locktime_ms: u16,
    /// cno (dB-Hz).
    pub cno: u8,
    /// prStdev, cpStdev, doStdev bytes (bits 0–3 hold the code).
    pub pr_stdev: u8,
    pub cp_stdev: u8,
    pub do_stdev: u8,
    /// trkStat byte.
    pub trk_stat: u8,
}

impl RawMeasurement {
    /// The measurement of a block, in SI units.
    pub fn from_block(b: &RawxBlock) -> Self {
        let code = |byte: u8| byte & 0x0F;
        Self {
            pseudorange_m: b.pr_mes,
            carrier_phase_cycles: b.cp_mes,
            doppler_hz: f64::from(b.do_mes),
            gnss_id: b.gnss_id,
            sv_id: b.sv_id,
            sig_id: b.sig_id,
            freq_id: b.freq_id,
            lock_time_s: f64::from(b.locktime_ms) * 1e-3,
            cn0_dbhz: f64::from(b.cno),
            pseudorange_sigma_m: 0.01 * 2f64.powi(i32::from(code(b.pr_stdev))),
            carrier_phase_sigma_cycles: 0.004 * f64::from(code(b.cp_stdev)),
            doppler_sigma_hz: 0.002 * 2f64.powi(i32::from(code(b.do_stdev))),
            tracking: TrackingStatus {
                pr_valid: b.trk_stat & 0x01 != 0,
                cp_valid: b.trk_stat & 0x02 != 0,
                half_cycle_valid: b.trk_stat & 0x04 != 0,
                half_cycle_subtracted: b.trk_stat & 0x08 != 0,
            },
        }
    }
}

impl RawX {
    /// A message from its header fields (recStat the status byte) and measurements.
    pub fn new(
        rcv_tow_s: f64,
        week: u16,
        leap_s: i8,
        rec_stat: u8,
        version: u8,
        measurements: Vec<RawMeasurement>,
    ) -> Self {
        Self {
            rcv_tow_s,
            week,
            leap_s,
            leap_s_valid: rec_stat & 0x01 != 0,
            clock_reset: rec_stat & 0x02 != 0,
            version,
            measurements,
        }
    }
}

/// Decodes a RAWX payload. The length must be exactly 16 + 32 · numMeas.
pub fn decode_rawx(p: &[u8]) -> Result<RawX, UbxError> {
    let bad_length = |expected| UbxError::BadLength {
        message: NAME,
        expected,
        actual: p.len(),
    };
    let num = usize::from(le::u8_at(p, 11).ok_or(bad_length(HEADER_LEN))?);
    let expected = HEADER_LEN + BLOCK_LEN * num;
    if p.len() != expected {
        return Err(bad_length(expected));
    }
    let head = (|| {
        Some((
            le::f64_at(p, 0)?,
            le::u16_at(p, 8)?,
            le::i8_at(p, 10)?,
            le::u8_at(p, 12)?,
            le::u8_at(p, 13)?,
        ))
    })();
    let (rcv_tow_s, week, leap_s, rec_stat, version) = head.ok_or(bad_length(expected))?;
    let measurements = (0..num)
        .map(|k| {
            block(p, HEADER_LEN + BLOCK_LEN * k)
                .map(|b| RawMeasurement::from_block(&b))
                .ok_or(bad_length(expected))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(RawX::new(
        rcv_tow_s,
        week,
        leap_s,
        rec_stat,
        version,
        measurements,
    ))
}

fn block(p: &[u8], off: usize) -> Option<RawxBlock> {
    Some(RawxBlock {
        pr_mes: le::f64_at(p, off)?,
        cp_mes: le::f64_at(p, off + 8)?,
        do_mes: le::f32_at(p, off + 16)?,
        gnss_id: le::u8_at(p, off + 20)?,
        sv_id: le::u8_at(p, off + 21)?,
        sig_id: le::u8_at(p, off + 22)?,
        freq_id: le::u8_at(p, off + 23)?,
        locktime_ms: le::u16_at(p, off + 24)?,
        cno: le::u8_at(p, off + 26)?,
        pr_stdev: le::u8_at(p, off + 27)?,
        cp_stdev: le::u8_at(p, off + 28)?,
        do_stdev: le::u8_at(p, off + 29)?,
        trk_stat: le::u8_at(p, off + 30)?,
    })
}
