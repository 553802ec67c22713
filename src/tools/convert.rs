//! `gnss_ins convert`: a u-blox UBX log, an IMU CSV and optionally a reference trajectory
//! written as a rosbag2 MCAP bag of this package's messages; or a robot's bag with the
//! u-blox drivers' raw GNSS and its IMU ([`super::convert_bag`]).
//!
//! Topics (the names `simulate` uses, so `replay` and `compare` read both alike):
//! - `/gnss/measurements`: GnssMeasurements, one per UBX-RXM-RAWX epoch with satellites,
//!   stamped at the receiver's measurement time; satellite states from the broadcast
//!   ephemerides decoded from UBX-RXM-SFRBX; Klobuchar coefficients when the log has them
//!   (NaN otherwise); pseudo-ranges as [`ConvertOptions::ionosphere`] says (by default
//!   the dual-frequency ionosphere-free combination, ionosphere delay 0 per satellite);
//! - `/imu`: sensor_msgs/Imu in the FLU body frame `base_link` (REP-103/145: specific
//!   force in m/s², angular rate in rad/s), so the engine's `mounting.imu_rotation_rpy_deg`
//!   stays [0, 0, 0] for a converted bag;
//! - with a reference: `/ground_truth` nav_msgs/Odometry of the reference position in the
//!   ENU frame `map` at the datum `/ground_truth/datum` (NavSatFix, once, the first
//!   reference position). No attitude reference: the orientation is the all-zero
//!   quaternion and `child_frame_id` is `map`, so the twist is the ENU velocity; the pose
//!   covariance holds the reference's σ east/north/up (rotations −1: not provided);
//! - `/ground_truth/environment`: the reference's solution quality (`rtk_fixed`,
//!   `rtk_float`, `q<N>`) whenever it changes, as the simulator labels its segments, so
//!   errors can be summarized by it.
//!
//! Stamps are UTC (ROS time): GPST − `leap_seconds`.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::earth::{self, Llh};
use crate::gnss::ephemeris::EphemerisStore;
use crate::gnss::ionosphere::IonosphereMode;
use crate::gnss::rinex_nav::parse_rinex_nav;
use crate::gnss::rinex_obs::{build_rinex_epoch, parse_rinex_obs};
use crate::gnss::ubx::{build_epoch_with, read_ubx_log_with, CarrierSolution, NavPvt, UbxLog};
use crate::ins::ImuSample;
use crate::ros::bag::{BagError, BagWriter};
use crate::ros::convert::seconds_to_time;
use crate::ros::msg::{
    DiagnosticArray, DiagnosticStatus, GnssMeasurements, Header, Imu, NavSatFix, NavSatStatus,
    Odometry, Point, Pose, PoseWithCovariance, Quaternion, Time, Twist, TwistWithCovariance,
    Vector3 as RosVector3,
};
use crate::ros::outbound;
use crate::ros::ubx_adapter::{TimeBase, UbxAdapterParams, MAX_LEAP_SECONDS};

use super::convert_bag::{read_robot_bag, RobotBag, RobotBagError, RobotBagSummary};
use super::imu_csv::{gpst_from_column, gpst_from_tag, parse_imu_csv, ImuCsvError, ImuCsvFormat};
use super::rtklib_pos::{parse_pos, PosQuality};
use super::simulate::{
    GNSS_TOPIC, IMU_TOPIC, TRUTH_DATUM_TOPIC, TRUTH_ENVIRONMENT_TOPIC, TRUTH_TOPIC,
};
use super::time_tag::{parse_time_tag, TimeTagError};
use crate::gnss::time_scale::{gpst_of_week_tow, utc_of_gpst, SECONDS_PER_WEEK};

/// Frame of the converted IMU samples (the body frame, FLU).
pub const IMU_FRAME: &str = "base_link";
/// Frame of the GNSS measurements.
pub const GNSS_FRAME: &str = "gnss_antenna";

/// Which ephemerides build an epoch's satellite states.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EphemerisMode {
    /// Every ephemeris decoded anywhere in the log, the one valid at the epoch chosen (as
    /// a RINEX navigation file is used in post-processing): satellites count from the
    /// first epoch.
    WholeLog,
    /// Only those decoded before the epoch, as a receiver in real time.
    AsReceived,
}

/// Where the IMU samples' times come from.
#[derive(Debug, Clone, PartialEq)]
pub enum ImuTime {
    /// A `tick_ms` column stamped with this RTKLIB time-tag file.
    Tag(PathBuf),
    /// A `gpst_s` column.
    Column,
}

/// The IMU input.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuInput {
    pub csv: PathBuf,
    pub format: ImuCsvFormat,
    pub time: ImuTime,
}

/// The reference trajectory, if any.
#[derive(Debug, Clone, PartialEq)]
pub enum TruthInput {
    None,
    /// The UBX-NAV-PVT solutions of the log itself (heights ellipsoidal).
    UbxNavPvt,
    /// An RTKLIB `.pos` file in GPST; `geoid_separation_m` is added to its heights
    /// (0 for ellipsoidal heights).
    Pos {
        path: PathBuf,
        geoid_separation_m: f64,
    },
}

/// Where the GNSS measurements come from.
#[derive(Debug, Clone, PartialEq)]
pub enum GnssSource {
    /// A u-blox UBX log: RXM-RAWX measurements with the ephemerides of its RXM-SFRBX
    /// subframes (and NAV-PVT for a reference).
    Ubx(PathBuf),
    /// RINEX 3 observation and navigation files. Choice: single frequency only (the
    /// first preferred code of each satellite, as the RINEX single-point mode), with the
    /// navigation header's Klobuchar coefficients when it has them; the
    /// ionosphere-free mode is refused rather than silently changed.
    Rinex { obs: PathBuf, nav: PathBuf },
    /// A robot's bag with the u-blox drivers' raw GNSS and its IMU, converted through the
    /// live adapter ([`super::convert_bag`]): always as received, stamped on
    /// `time_base` (`host_latency_s` before the host receive stamps for
    /// [`TimeBase::Host`]).
    Bag {
        bag: RobotBag,
        time_base: TimeBase,
        host_latency_s: f64,
    },
}

/// What to convert.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvertOptions {
    pub gnss: GnssSource,
    pub imu: Option<ImuInput>,
    pub truth: TruthInput,
    /// GPS − UTC (s).
    pub leap_seconds: f64,
    pub ephemeris: EphemerisMode,
    /// Which pseudo-ranges to form (dual-frequency ionosphere-free or single-frequency).
    pub ionosphere: IonosphereMode,
}

/// Why a conversion failed.
#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: {source}")]
    ImuCsv { path: String, source: ImuCsvError },
    #[error("{path}: {source}")]
    TimeTag { path: String, source: TimeTagError },
    #[error("{path}: no epoch with a usable satellite")]
    NoGnss { path: String },
    #[error("{path}: {message}")]
    Rinex { path: String, message: String },
    #[error("RINEX input is single-frequency: use --ionosphere broadcast or none")]
    RinexIonoFree,
    #[error("--truth-ubx needs a UBX log as the GNSS input")]
    TruthNeedsUbx,
    #[error("{path}: no reference solution")]
    NoTruth { path: String },
    #[error("GPST {gpst_s} s is no ROS time")]
    Time { gpst_s: f64 },
    #[error("{path}: {source}")]
    RobotBag {
        path: String,
        source: Box<RobotBagError>,
    },
    #[error("--leap-seconds {0} must be a whole number of seconds for --bag")]
    FractionalLeapSeconds(f64),
    #[error(transparent)]
    Bag(#[from] BagError),
}

/// Counts of a conversion.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConvertSummary {
    /// GNSS epochs written, and their satellites.
    pub gnss_epochs: usize,
    pub satellites: usize,
    /// RAWX epochs without a usable satellite (not written).
    pub empty_epochs: usize,
    /// Satellite-epochs without a dual-frequency pair (ionosphere-free): no range used.
    pub single_frequency: usize,
    /// Of those, the satellite-epochs kept for their carrier phase and rate alone.
    pub phase_only: usize,
    /// Whether the log had Klobuchar coefficients.
    pub klobuchar: bool,
    /// GPS − UTC the receiver reported (valid RAWX leap seconds), if it did.
    pub receiver_leap_seconds: Option<i8>,
    pub imu_samples: usize,
    /// IMU lines skipped, by reason.
    pub imu_skipped: Vec<(String, usize)>,
    /// Reference samples written, by label.
    pub truth: Vec<(String, usize)>,
    /// Reference lines skipped, by reason.
    pub truth_skipped: Vec<(String, usize)>,
    /// First and last stamps written (UTC s).
    pub span_utc_s: (f64, f64),
    /// For a robot bag: what the adapter read, used and dropped.
    pub robot_bag: Option<RobotBagSummary>,
}

/// One reference sample, GPST.
#[derive(Debug, Clone, PartialEq)]
struct TruthRecord {
    gpst_s: f64,
    p: Llh,
    velocity_enu_mps: Option<Vector3<f64>>,
    sigma_enu_m: Option<Vector3<f64>>,
    label: String,
}

/// A message waiting to be written in time order.
enum Item {
    Imu(Box<Imu>),
    Gnss(Box<GnssMeasurements>),
    Datum(Box<NavSatFix>),
    Truth(Box<Odometry>),
    Environment(Box<DiagnosticArray>),
}

fn read(path: &Path) -> Result<Vec<u8>, ConvertError> {
    std::fs::read(path).map_err(|source| ConvertError::Io {
        path: path.display().to_string(),
        source,
    })
}

fn stamp_of(gpst_s: f64, leap_s: f64) -> Result<(Time, u64), ConvertError> {
    let utc = utc_of_gpst(gpst_s, leap_s);
    let stamp = seconds_to_time(utc).map_err(|_| ConvertError::Time { gpst_s })?;
    let sec = u64::try_from(stamp.sec).map_err(|_| ConvertError::Time { gpst_s })?;
    Ok((stamp, sec * 1_000_000_000 + u64::from(stamp.nanosec)))
}

/// Called with the phase of a conversion and the fraction of it done.
pub type ConvertProgress<'a> = &'a mut dyn FnMut(&'static str, f64);

/// Converts the inputs of `options` into the bag `out`.
pub fn convert(options: &ConvertOptions, out: &Path) -> Result<ConvertSummary, ConvertError> {
    convert_with_progress(options, out, &mut |_, _| {})
}

/// [`convert`], telling `progress` how far its longer phases are: building the GNSS
/// epochs (or reading a robot bag) and writing the bag.
pub fn convert_with_progress(
    options: &ConvertOptions,
    out: &Path,
    progress: ConvertProgress,
) -> Result<ConvertSummary, ConvertError> {
    let mut summary = ConvertSummary::default();
    let mut items: Vec<(u64, Item)> = Vec::new();
    let (gnss_path, log) = match &options.gnss {
        GnssSource::Ubx(path) => {
            let log = read_ubx_log_with(&read(path)?, options.ionosphere);
            summary.klobuchar = log.klobuchar.is_some();
            summary.receiver_leap_seconds = log
                .rawx
                .iter()
                .rev()
                .find(|r| r.leap_s_valid)
                .map(|r| r.leap_s);
            gnss_items(&log, options, &mut items, &mut summary, progress)?;
            (path, Some(log))
        }
        GnssSource::Rinex { obs, nav } => {
            rinex_items(obs, nav, options, &mut items, &mut summary, progress)?;
            (obs, None)
        }
        GnssSource::Bag {
            bag,
            time_base,
            host_latency_s,
        } => {
            let params = UbxAdapterParams {
                time_base: *time_base,
                host_latency_s: *host_latency_s,
                ..adapter_params(options)?
            };
            robot_bag_items(bag, params, &mut items, &mut summary, progress)?;
            (&bag.path, None)
        }
    };
    let gnss_path = gnss_path.display().to_string();
    if summary.gnss_epochs == 0 {
        return Err(ConvertError::NoGnss { path: gnss_path });
    }
    if let Some(imu) = &options.imu {
        imu_items(imu, options.leap_seconds, &mut items, &mut summary)?;
    }
    let truth = match &options.truth {
        TruthInput::None => Vec::new(),
        TruthInput::UbxNavPvt => {
            let log = log.as_ref().ok_or(ConvertError::TruthNeedsUbx)?;
            let t = nav_pvt_truth(log);
            if t.is_empty() {
                return Err(ConvertError::NoTruth { path: gnss_path });
            }
            t
        }
        TruthInput::Pos {
            path,
            geoid_separation_m,
        } => {
            let text = String::from_utf8_lossy(&read(path)?).into_owned();
            let pos = parse_pos(&text);
            summary.truth_skipped = pos
                .skipped
                .iter()
                .map(|(k, v)| ((*k).to_owned(), *v))
                .collect();
            if pos.records.is_empty() {
                return Err(ConvertError::NoTruth {
                    path: path.display().to_string(),
                });
            }
            pos.records
                .iter()
                .map(|r| TruthRecord {
                    gpst_s: r.time_s,
                    p: Llh::from_degrees(r.lat_deg, r.lon_deg, r.height_m + geoid_separation_m),
                    velocity_enu_mps: r.velocity_enu_mps,
                    sigma_enu_m: Some(r.sigma_enu_m),
                    label: r.quality.label(),
                })
                .collect()
        }
    };
    truth_items(&truth, options.leap_seconds, &mut items, &mut summary)?;
    // Stable: at equal times the datum and a label precede the reference they describe.
    items.sort_by_key(|(ns, _)| *ns);
    summary.span_utc_s = (
        items.first().map_or(0.0, |(ns, _)| *ns as f64 * 1e-9),
        items.last().map_or(0.0, |(ns, _)| *ns as f64 * 1e-9),
    );
    write_bag(out, &items, !truth.is_empty(), progress)?;
    Ok(summary)
}

fn write_bag(
    out: &Path,
    items: &[(u64, Item)],
    truth: bool,
    progress: ConvertProgress,
) -> Result<(), ConvertError> {
    let mut bag = BagWriter::create(out)?;
    bag.add_topic::<Imu>(IMU_TOPIC)?;
    bag.add_topic::<GnssMeasurements>(GNSS_TOPIC)?;
    if truth {
        bag.add_topic::<Odometry>(TRUTH_TOPIC)?;
        bag.add_topic::<NavSatFix>(TRUTH_DATUM_TOPIC)?;
        bag.add_topic::<DiagnosticArray>(TRUTH_ENVIRONMENT_TOPIC)?;
    }
    for (k, (ns, item)) in items.iter().enumerate() {
        progress("writing the bag", k as f64 / items.len() as f64);
        match item {
            Item::Imu(m) => bag.write(IMU_TOPIC, m.as_ref(), *ns)?,
            Item::Gnss(m) => bag.write(GNSS_TOPIC, m.as_ref(), *ns)?,
            Item::Datum(m) => bag.write(TRUTH_DATUM_TOPIC, m.as_ref(), *ns)?,
            Item::Truth(m) => bag.write(TRUTH_TOPIC, m.as_ref(), *ns)?,
            Item::Environment(m) => bag.write(TRUTH_ENVIRONMENT_TOPIC, m.as_ref(), *ns)?,
        }
    }
    bag.finish()?;
    Ok(())
}

fn gnss_items(
    log: &UbxLog,
    options: &ConvertOptions,
    items: &mut Vec<(u64, Item)>,
    summary: &mut ConvertSummary,
    progress: ConvertProgress,
) -> Result<(), ConvertError> {
    for (k, raw) in log.rawx.iter().enumerate() {
        progress("building the GNSS epochs", k as f64 / log.rawx.len() as f64);
        let built = match options.ephemeris {
            EphemerisMode::WholeLog => {
                build_epoch_with(raw, &log.store, log.klobuchar, options.ionosphere)
            }
            EphemerisMode::AsReceived => match log.epochs.get(k) {
                Some(b) => b.clone(),
                None => continue,
            },
        };
        summary.single_frequency += built.stats.single_frequency;
        summary.phase_only += built.stats.phase_only;
        if built.epoch.satellites.is_empty() || !raw.rcv_tow_s.is_finite() {
            summary.empty_epochs += 1;
            continue;
        }
        let gpst = gpst_of_week_tow(i32::from(raw.week), raw.rcv_tow_s);
        let (stamp, ns) = stamp_of(gpst, options.leap_seconds)?;
        let msg = outbound::gnss_measurements(&built.epoch, raw.week, stamp, GNSS_FRAME);
        summary.gnss_epochs += 1;
        summary.satellites += built.epoch.satellites.len();
        items.push((ns, Item::Gnss(Box::new(msg))));
    }
    Ok(())
}

/// The adapter parameters `options` set: leap seconds and ionosphere (the rest default).
fn adapter_params(options: &ConvertOptions) -> Result<UbxAdapterParams, ConvertError> {
    let leap = options.leap_seconds;
    let whole = leap.fract() == 0.0 && leap.abs() <= f64::from(MAX_LEAP_SECONDS);
    if !whole {
        return Err(ConvertError::FractionalLeapSeconds(leap));
    }
    Ok(UbxAdapterParams {
        leap_seconds: leap as i32,
        ionosphere: options.ionosphere,
        ..UbxAdapterParams::default()
    })
}

/// The GNSS epochs and IMU samples of a robot bag.
fn robot_bag_items(
    bag: &RobotBag,
    params: UbxAdapterParams,
    items: &mut Vec<(u64, Item)>,
    summary: &mut ConvertSummary,
    progress: ConvertProgress,
) -> Result<(), ConvertError> {
    let (messages, read) = read_robot_bag(bag, params, |f| progress("reading the robot bag", f))
        .map_err(|source| ConvertError::RobotBag {
            path: bag.path.display().to_string(),
            source: Box::new(source),
        })?;
    for (ns, msg) in messages.gnss {
        summary.gnss_epochs += 1;
        summary.satellites += msg.satellites.len();
        summary.klobuchar |= msg.klobuchar_alpha.iter().all(|a| a.is_finite());
        items.push((ns, Item::Gnss(Box::new(msg))));
    }
    for (ns, msg) in messages.imu {
        items.push((ns, Item::Imu(Box::new(msg))));
    }
    summary.empty_epochs = read.counts.empty_epochs as usize;
    summary.single_frequency = read.counts.satellites.single_frequency;
    summary.phase_only = read.counts.satellites.phase_only;
    summary.receiver_leap_seconds = read
        .receiver_leap_seconds
        .and_then(|s| i8::try_from(s).ok());
    summary.imu_samples = read.imu_samples;
    if read.imu_skipped > 0 {
        summary.imu_skipped.push((
            "undecodable or stamped before 1970".to_owned(),
            read.imu_skipped,
        ));
    }
    summary.robot_bag = Some(read);
    Ok(())
}

/// The epochs of a RINEX observation file with the ephemerides of its navigation file.
fn rinex_items(
    obs_path: &Path,
    nav_path: &Path,
    options: &ConvertOptions,
    items: &mut Vec<(u64, Item)>,
    summary: &mut ConvertSummary,
    progress: ConvertProgress,
) -> Result<(), ConvertError> {
    if options.ionosphere == IonosphereMode::IonoFree {
        return Err(ConvertError::RinexIonoFree);
    }
    let text = |p: &Path| read(p).map(|b| String::from_utf8_lossy(&b).into_owned());
    let rinex_error = |p: &Path, e: &dyn std::fmt::Display| ConvertError::Rinex {
        path: p.display().to_string(),
        message: e.to_string(),
    };
    let obs = parse_rinex_obs(&text(obs_path)?).map_err(|e| rinex_error(obs_path, &e))?;
    let nav = parse_rinex_nav(&text(nav_path)?).map_err(|e| rinex_error(nav_path, &e))?;
    let mut store = EphemerisStore::new();
    for eph in &nav.ephemerides {
        store.insert(*eph);
    }
    summary.klobuchar = nav.klobuchar.is_some();
    for (k, epoch) in obs.epochs.iter().enumerate() {
        progress(
            "building the GNSS epochs",
            k as f64 / obs.epochs.len() as f64,
        );
        let mut built = build_rinex_epoch(epoch, &store, nav.klobuchar);
        if options.ionosphere == IonosphereMode::None {
            for sat in &mut built.epoch.satellites {
                sat.iono_delay_m = Some(0.0);
            }
        }
        let time = built.receive_time;
        let week = u16::try_from(time.week).ok();
        let (Some(week), false) = (week, built.epoch.satellites.is_empty()) else {
            summary.empty_epochs += 1;
            continue;
        };
        let (stamp, ns) = stamp_of(
            gpst_of_week_tow(time.week, time.tow_s),
            options.leap_seconds,
        )?;
        let msg = outbound::gnss_measurements(&built.epoch, week, stamp, GNSS_FRAME);
        summary.gnss_epochs += 1;
        summary.satellites += built.epoch.satellites.len();
        items.push((ns, Item::Gnss(Box::new(msg))));
    }
    Ok(())
}

fn imu_items(
    imu: &ImuInput,
    leap_s: f64,
    items: &mut Vec<(u64, Item)>,
    summary: &mut ConvertSummary,
) -> Result<(), ConvertError> {
    let csv_path = imu.csv.display().to_string();
    let text = String::from_utf8_lossy(&read(&imu.csv)?).into_owned();
    let csv = parse_imu_csv(&text, &imu.format);
    summary.imu_skipped = csv
        .skipped
        .iter()
        .map(|(k, v)| ((*k).to_owned(), *v))
        .collect();
    let times = match &imu.time {
        ImuTime::Tag(tag_path) => {
            let tag = parse_time_tag(&read(tag_path)?).map_err(|source| ConvertError::TimeTag {
                path: tag_path.display().to_string(),
                source,
            })?;
            gpst_from_tag(&csv, &tag)
        }
        ImuTime::Column => gpst_from_column(&csv),
    }
    .map_err(|source| ConvertError::ImuCsv {
        path: csv_path,
        source,
    })?;
    for (row, gpst) in csv.rows.iter().zip(times) {
        let (stamp, ns) = stamp_of(gpst, leap_s)?;
        let sample = ImuSample {
            t_s: utc_of_gpst(gpst, leap_s),
            w_ib_b_rad_s: row.w_flu_rad_s,
            f_ib_b_m_s2: row.f_flu_m_s2,
        };
        items.push((
            ns,
            Item::Imu(Box::new(outbound::imu(&sample, stamp, IMU_FRAME))),
        ));
        summary.imu_samples += 1;
    }
    Ok(())
}

/// The NAV-PVT solutions as reference samples. NAV-PVT carries the time of week only: the
/// week is that of the RAWX epoch nearest in the log (a reference within half a week of
/// it).
fn nav_pvt_truth(log: &UbxLog) -> Vec<TruthRecord> {
    let Some(raw) = log.rawx.iter().find(|r| r.rcv_tow_s.is_finite()) else {
        return Vec::new();
    };
    let reference = gpst_of_week_tow(i32::from(raw.week), raw.rcv_tow_s);
    log.nav_pvt
        .iter()
        .filter(|p| p.gnss_fix_ok)
        .map(|p| {
            let mut gpst = gpst_of_week_tow(i32::from(raw.week), f64::from(p.itow_ms) * 1e-3);
            if gpst - reference > SECONDS_PER_WEEK / 2.0 {
                gpst -= SECONDS_PER_WEEK;
            } else if reference - gpst > SECONDS_PER_WEEK / 2.0 {
                gpst += SECONDS_PER_WEEK;
            }
            TruthRecord {
                gpst_s: gpst,
                p: Llh::new(p.lat_rad, p.lon_rad, p.height_m),
                velocity_enu_mps: Some(Vector3::new(
                    p.vel_ned_mps[1],
                    p.vel_ned_mps[0],
                    -p.vel_ned_mps[2],
                )),
                // Choice: hAcc is a horizontal radius; split it evenly over east and north.
                sigma_enu_m: Some(Vector3::new(
                    p.h_acc_m / std::f64::consts::SQRT_2,
                    p.h_acc_m / std::f64::consts::SQRT_2,
                    p.v_acc_m,
                )),
                label: nav_pvt_label(p),
            }
        })
        .collect()
}

/// The same labels as an RTKLIB `.pos` file of the solutions would carry.
fn nav_pvt_label(p: &NavPvt) -> String {
    match p.carrier_solution {
        CarrierSolution::Fixed => PosQuality::Fixed.label(),
        CarrierSolution::Float => PosQuality::Float.label(),
        // RTKLIB's Q: 4 differential, 5 single.
        CarrierSolution::None if p.diff_solution => "q4".to_owned(),
        CarrierSolution::None => "q5".to_owned(),
    }
}

fn truth_items(
    truth: &[TruthRecord],
    leap_s: f64,
    items: &mut Vec<(u64, Item)>,
    summary: &mut ConvertSummary,
) -> Result<(), ConvertError> {
    let Some(first) = truth.first() else {
        return Ok(());
    };
    let datum = first.p;
    let mut label: Option<&str> = None;
    let mut counts: std::collections::BTreeMap<String, usize> = Default::default();
    for (k, r) in truth.iter().enumerate() {
        if !r.p.is_finite() || !r.gpst_s.is_finite() {
            *counts.entry("not finite (skipped)".to_owned()).or_insert(0) += 1;
            continue;
        }
        let (stamp, ns) = stamp_of(r.gpst_s, leap_s)?;
        let header = |frame: &str| Header {
            stamp,
            frame_id: frame.to_owned(),
        };
        if k == 0 {
            items.push((ns, Item::Datum(Box::new(datum_fix(&datum, header("map"))))));
        }
        if label != Some(r.label.as_str()) {
            label = Some(r.label.as_str());
            items.push((
                ns,
                Item::Environment(Box::new(environment(&r.label, header("")))),
            ));
        }
        items.push((
            ns,
            Item::Truth(Box::new(truth_odometry(r, &datum, header("map")))),
        ));
        *counts.entry(r.label.clone()).or_insert(0) += 1;
    }
    summary.truth = counts.into_iter().collect();
    Ok(())
}

fn datum_fix(p: &Llh, header: Header) -> NavSatFix {
    NavSatFix {
        header,
        status: NavSatStatus {
            status: NavSatStatus::STATUS_GBAS_FIX,
            service: NavSatStatus::SERVICE_GPS,
        },
        latitude: p.lat_rad.to_degrees(),
        longitude: p.lon_rad.to_degrees(),
        altitude: p.height_m,
        position_covariance: [0.0; 9],
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_UNKNOWN,
    }
}

fn environment(label: &str, header: Header) -> DiagnosticArray {
    DiagnosticArray {
        header,
        status: vec![DiagnosticStatus {
            level: DiagnosticStatus::OK,
            name: "environment".to_owned(),
            message: label.to_owned(),
            hardware_id: String::new(),
            values: Vec::new(),
        }],
    }
}

/// The reference as Odometry in `header.frame_id` (ENU at `datum`), without attitude
/// (see the module documentation).
fn truth_odometry(r: &TruthRecord, datum: &Llh, header: Header) -> Odometry {
    let enu = earth::llh_to_enu(&r.p, datum);
    let mut pose_cov = [0.0; 36];
    if let Some(s) = r.sigma_enu_m {
        for i in 0..3 {
            pose_cov[7 * i] = s[i] * s[i];
        }
    }
    for i in 3..6 {
        pose_cov[7 * i] = -1.0;
    }
    let mut twist_cov = [0.0; 36];
    let v = r.velocity_enu_mps.unwrap_or_else(|| {
        twist_cov[0] = -1.0;
        Vector3::zeros()
    });
    for i in 3..6 {
        twist_cov[7 * i] = -1.0;
    }
    Odometry {
        child_frame_id: header.frame_id.clone(),
        header,
        pose: PoseWithCovariance {
            pose: Pose {
                position: Point {
                    x: enu[0],
                    y: enu[1],
                    z: enu[2],
                },
                orientation: Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    w: 0.0,
                },
            },
            covariance: pose_cov,
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: RosVector3 {
                    x: v[0],
                    y: v[1],
                    z: v[2],
                },
                angular: RosVector3::default(),
            },
            covariance: twist_cov,
        },
    }
}
