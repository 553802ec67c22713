//! The walk_0827 UBX log as the u-blox ROS 2 drivers would have published it, for the
//! robot-bag and adapter tests and the adapter benchmark.
//!
//! - ublox_dgnss: one UBXRxmRawx / UBXRxmSfrbx per frame, the fields read from the
//!   payload at the offsets the driver reads them (ubx_rxm_rawx.hpp, ubx_rxm_sfrbx.hpp:
//!   the σ bytes and status bits as they are), stamped with the host receive time;
//! - ublox_gps: the byte stream in UInt8MultiArray chunks laid out as its
//!   `raw_data_stream` (one dimension `raw_data_stream`, stride 1, data offset 0).
//!
//! The host receive time of a byte is that of the logger's read that brought it: the
//! RTKLIB time tag beside the log records, after each read, the logger's tick and the
//! file position (GPST), here turned into UTC (GPST − 18 s).
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::gnss::ubx::FrameReader;
use adaptive_gnss_ins::ros::msg::{
    Header, MultiArrayDimension, MultiArrayLayout, RawxData, RecStat, Time, TrkStat,
    UInt8MultiArray, UbxRxmRawx, UbxRxmSfrbx,
};
use adaptive_gnss_ins::tools::convert::{ImuInput, ImuTime};
use adaptive_gnss_ins::tools::imu_csv::{AccelUnit, GyroUnit, ImuCsvFormat};
use adaptive_gnss_ins::tools::time_tag::{parse_time_tag, TimeTag};

/// GPS − UTC during the recording (s).
pub const LEAP_S: f64 = 18.0;

/// The path of the recording's file `name` (../shared/data/walk_0827).
pub fn walk_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/walk_0827")
        .join(name)
}

/// The recording's file `name`.
pub fn walk_file(name: &str) -> Vec<u8> {
    let path = walk_path(name);
    std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "test data {} is missing ({e}): expected ../shared/data/walk_0827 beside the crate",
            path.display()
        )
    })
}

/// The walk's IMU CSV as `gnss_ins convert` reads it, its axes turned by `rpy_deg` (roll,
/// pitch, yaw) into the body frame.
pub fn walk_imu_input(rpy_deg: [f64; 3]) -> ImuInput {
    ImuInput {
        csv: walk_path("imu_1730.csv"),
        format: ImuCsvFormat::new(
            "ax,ay,az,gx,gy,gz,tick_ms",
            AccelUnit::G,
            GyroUnit::DegPerS,
            rpy_deg,
        )
        .unwrap(),
        time: ImuTime::Tag(walk_path("imu_1730.csv.tag")),
    }
}

/// The log and its time tag.
pub fn walk_log() -> (Vec<u8>, TimeTag) {
    let tag = parse_time_tag(&walk_file("gnss_1730.ubx.tag")).expect("time tag");
    (walk_file("gnss_1730.ubx"), tag)
}

/// Host receive time (UTC ns since 1970) of the byte before `end` (exclusive offset):
/// the first read whose file position reached it.
pub fn host_ns(tag: &TimeTag, end: usize) -> u64 {
    let index = tag
        .records
        .partition_point(|r| (r.byte_offset as usize) < end)
        .min(tag.records.len() - 1);
    let gpst_s = tag.start_gpst_s + f64::from(tag.records[index].tick_ms) * 1e-3;
    ((gpst_s - LEAP_S) * 1e9).round() as u64
}

/// The ROS stamp of `ns` since 1970.
pub fn stamp(ns: u64) -> Time {
    Time {
        sec: (ns / 1_000_000_000) as i32,
        nanosec: (ns % 1_000_000_000) as u32,
    }
}

/// A message of the ublox_dgnss driver.
#[derive(Debug, Clone, PartialEq)]
pub enum DriverMessage {
    Rawx(UbxRxmRawx),
    Sfrbx(UbxRxmSfrbx),
}

fn f64_at(p: &[u8], o: usize) -> f64 {
    f64::from_le_bytes(p[o..o + 8].try_into().unwrap())
}

fn header(ns: u64) -> Header {
    Header {
        stamp: stamp(ns),
        frame_id: "ubx".to_owned(),
    }
}

/// UBXRxmRawx as ublox_dgnss fills it from a RAWX payload.
pub fn rawx_message(p: &[u8], ns: u64) -> UbxRxmRawx {
    let num_meas = p[11];
    let rawx_data = (0..usize::from(num_meas))
        .map(|k| {
            let b = &p[16 + 32 * k..16 + 32 * (k + 1)];
            let trk = b[30];
            RawxData {
                pr_mes: f64_at(b, 0),
                cp_mes: f64_at(b, 8),
                do_mes: f32::from_le_bytes(b[16..20].try_into().unwrap()),
                gnss_id: b[20],
                sv_id: b[21],
                sig_id: b[22],
                freq_id: b[23],
                locktime: u16::from_le_bytes([b[24], b[25]]),
                c_no: b[26],
                pr_stdev: b[27],
                cp_stdev: b[28],
                do_stdev: b[29],
                trk_stat: TrkStat {
                    pr_valid: trk & 1 != 0,
                    cp_valid: trk & 2 != 0,
                    half_cyc: trk & 4 != 0,
                    sub_half_cyc: trk & 8 != 0,
                },
            }
        })
        .collect();
    UbxRxmRawx {
        header: header(ns),
        rcv_tow: f64_at(p, 0),
        week: u16::from_le_bytes([p[8], p[9]]),
        leap_s: p[10] as i8,
        num_meas,
        rec_stat: RecStat {
            leap_sec: p[12] & 1 != 0,
            clk_reset: p[12] & 2 != 0,
        },
        version: p[13],
        rawx_data,
    }
}

/// UBXRxmSfrbx as ublox_dgnss fills it from an SFRBX payload.
pub fn sfrbx_message(p: &[u8], ns: u64) -> UbxRxmSfrbx {
    let num_words = p[4];
    UbxRxmSfrbx {
        header: header(ns),
        gnss_id: p[0],
        sv_id: p[1],
        sig_id: p[2],
        freq_id: p[3],
        num_words,
        chn: p[5],
        version: p[6],
        dwrd: (0..usize::from(num_words))
            .map(|k| u32::from_le_bytes(p[8 + 4 * k..12 + 4 * k].try_into().unwrap()))
            .collect(),
    }
}

/// Every RAWX and SFRBX frame of the log as the driver publishes it, with its host
/// receive time (ns), in stream order.
pub fn driver_messages(log: &[u8], tag: &TimeTag) -> Vec<(u64, DriverMessage)> {
    FrameReader::new(log)
        .filter_map(|f| {
            let end = f.offset + f.payload.len() + 8;
            let ns = host_ns(tag, end);
            match (f.class, f.id) {
                (0x02, 0x15) => Some((ns, DriverMessage::Rawx(rawx_message(f.payload, ns)))),
                (0x02, 0x13) => Some((ns, DriverMessage::Sfrbx(sfrbx_message(f.payload, ns)))),
                _ => None,
            }
        })
        .collect()
}

/// A chunk of the byte stream as ublox_gps publishes it.
pub fn stream_chunk(bytes: &[u8]) -> UInt8MultiArray {
    UInt8MultiArray {
        layout: MultiArrayLayout {
            dim: vec![MultiArrayDimension {
                label: "raw_data_stream".to_owned(),
                size: bytes.len() as u32,
                stride: 1,
            }],
            data_offset: 0,
        },
        data: bytes.to_vec(),
    }
}
