//! The u-blox drivers' messages -> the UBX core types, checking what the wire format
//! cannot: that the stated counts match the arrays.

use crate::gnss::ubx::{RawMeasurement, RawX, RawxBlock, Sfrbx};
use crate::ros::msg::{RawxData, TrkStat, UbxRxmRawx, UbxRxmSfrbx};

/// A driver message whose stated count disagrees with its array.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{message}: {stated} entries stated, {actual} present")]
pub struct CountMismatch {
    pub message: &'static str,
    pub stated: usize,
    pub actual: usize,
}

fn check_count(message: &'static str, stated: u8, actual: usize) -> Result<(), CountMismatch> {
    if usize::from(stated) == actual {
        Ok(())
    } else {
        Err(CountMismatch {
            message,
            stated: usize::from(stated),
            actual,
        })
    }
}

fn trk_stat_byte(t: &TrkStat) -> u8 {
    u8::from(t.pr_valid)
        | u8::from(t.cp_valid) << 1
        | u8::from(t.half_cyc) << 2
        | u8::from(t.sub_half_cyc) << 3
}

fn block(d: &RawxData) -> RawxBlock {
    RawxBlock {
        pr_mes: d.pr_mes,
        cp_mes: d.cp_mes,
        do_mes: d.do_mes,
        gnss_id: d.gnss_id,
        sv_id: d.sv_id,
        sig_id: d.sig_id,
        freq_id: d.freq_id,
        locktime_ms: d.locktime,
        cno: d.c_no,
        pr_stdev: d.pr_stdev,
        cp_stdev: d.cp_stdev,
        do_stdev: d.do_stdev,
        trk_stat: trk_stat_byte(&d.trk_stat),
    }
}

/// The RAWX of a `ublox_ubx_msgs/UBXRxmRawx`, exactly as [`crate::gnss::ubx::decode_rawx`]
/// gives it from the frame the driver read.
pub fn rawx_of(msg: &UbxRxmRawx) -> Result<RawX, CountMismatch> {
    check_count("UBXRxmRawx", msg.num_meas, msg.rawx_data.len())?;
    let rec_stat = u8::from(msg.rec_stat.leap_sec) | u8::from(msg.rec_stat.clk_reset) << 1;
    let measurements = msg
        .rawx_data
        .iter()
        .map(|d| RawMeasurement::from_block(&block(d)))
        .collect();
    Ok(RawX::new(
        msg.rcv_tow,
        msg.week,
        msg.leap_s,
        rec_stat,
        msg.version,
        measurements,
    ))
}

/// The SFRBX of a `ublox_ubx_msgs/UBXRxmSfrbx`.
pub fn sfrbx_of(msg: &UbxRxmSfrbx) -> Result<Sfrbx, CountMismatch> {
    check_count("UBXRxmSfrbx", msg.num_words, msg.dwrd.len())?;
    Ok(Sfrbx {
        gnss_id: msg.gnss_id,
        sv_id: msg.sv_id,
        sig_id: msg.sig_id,
        freq_id: msg.freq_id,
        channel: msg.chn,
        version: msg.version,
        words: msg.dwrd.clone(),
    })
}
