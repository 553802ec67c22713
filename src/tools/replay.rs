//! `gnss_ins replay`: a recorded bag streamed through the engine (never loaded whole),
//! with the solutions written to an output bag and/or CSV, and scored against a
//! reference when one is given.

use std::io::Write;
use std::path::Path;

use crate::config::Config;
use crate::earth::Llh;
use crate::engine::Output;
use crate::eval::{ErrorSummary, TruthSample, TruthTrack};
use crate::ros::bag::{BagError, BagReader, BagWriter};
use crate::ros::convert::seconds_to_time;
use crate::ros::msg::{Imu, NavSatFix, NoiseEstimates, Odometry, RosMessage};
use crate::ros::outbound;

use super::bag_inputs::{BagInputs, BagTopics, ReadProblems};
use super::session::{Session, SessionReport};

/// Output topics of a replay.
pub const ODOMETRY_TOPIC: &str = "/odometry";
pub const FIX_OUT_TOPIC: &str = "/fix";
pub const NOISE_TOPIC: &str = "/noise_estimates";

/// Why a replay failed (partial results are kept in the files written so far).
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error(transparent)]
    Bag(#[from] BagError),
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("truth CSV {path}, line {line}: {reason}")]
    TruthCsv {
        path: String,
        line: usize,
        reason: String,
    },
    #[error(
        "{path}: no {expected} messages on {imu_topic}: nothing to replay (the bag has: {found})"
    )]
    NoImu {
        path: String,
        imu_topic: String,
        expected: &'static str,
        /// The bag's topics as "topic (type, count)".
        found: String,
    },
}

/// Where the reference comes from.
#[derive(Debug, Clone)]
pub enum TruthSource {
    None,
    /// An Odometry topic of the bag (ENU at the datum topic's position).
    Topic(String),
    /// A preloaded track (from a CSV).
    Track(TruthTrack),
}

/// The result of a replay.
#[derive(Debug)]
pub struct ReplayResult {
    pub report: SessionReport,
    pub problems: ReadProblems,
    pub summary: Option<ErrorSummary>,
}

/// Options of a replay.
#[derive(Debug, Clone, Default)]
pub struct ReplayOptions<'a> {
    pub out_bag: Option<&'a Path>,
    pub csv: Option<&'a Path>,
    /// Scores at most this often (s); 0 scores every solution that has a reference.
    pub score_interval_s: f64,
}

/// Replays `bag` with `config`; `progress` is called now and then with the fraction of
/// the bag's messages done.
pub fn replay(
    bag: &Path,
    config: &Config,
    truth: TruthSource,
    options: &ReplayOptions,
    mut progress: impl FnMut(f64),
) -> Result<ReplayResult, ReplayError> {
    let reader = BagReader::open(bag)?;
    let mut topics = BagTopics::default();
    let total: u64 = reader.topics().iter().map(|t| t.message_count).sum();
    let track = match truth {
        TruthSource::None => {
            topics.truth = None;
            None
        }
        TruthSource::Topic(t) => {
            topics.truth = Some(t);
            None
        }
        TruthSource::Track(track) => {
            topics.truth = None;
            Some(track)
        }
    };
    let has_imu = reader
        .topics()
        .iter()
        .any(|t| t.topic == topics.imu && t.type_name == Imu::TYPE_NAME && t.message_count > 0);
    if !has_imu {
        let found: Vec<String> = reader
            .topics()
            .iter()
            .map(|t| format!("{} ({}, {})", t.topic, t.type_name, t.message_count))
            .collect();
        return Err(ReplayError::NoImu {
            path: bag.display().to_string(),
            imu_topic: topics.imu.clone(),
            expected: Imu::TYPE_NAME,
            found: if found.is_empty() {
                "no readable message".to_owned()
            } else {
                found.join(", ")
            },
        });
    }
    let mut inputs = BagInputs::new(reader.messages()?, topics);
    let mut session = Session::new(config.clone(), options.score_interval_s, track);
    let mut writer = match options.out_bag {
        Some(p) => {
            let mut w = BagWriter::create(p)?;
            w.add_topic::<Odometry>(ODOMETRY_TOPIC)?;
            w.add_topic::<NavSatFix>(FIX_OUT_TOPIC)?;
            w.add_topic::<NoiseEstimates>(NOISE_TOPIC)?;
            Some(w)
        }
        None => None,
    };
    let mut csv = match options.csv {
        Some(p) => {
            let file = std::fs::File::create(p).map_err(|source| ReplayError::Io {
                path: p.display().to_string(),
                source,
            })?;
            let mut w = std::io::BufWriter::new(file);
            writeln!(w, "{}", CSV_HEADER).map_err(|source| ReplayError::Io {
                path: p.display().to_string(),
                source,
            })?;
            Some((w, p))
        }
        None => None,
    };
    let mut datum = config.output.datum;
    let mut done = 0u64;
    for input in inputs.by_ref() {
        done += 1;
        if done % 10_000 == 0 && total > 0 {
            progress(done as f64 / total as f64);
        }
        let outputs = session.push(input);
        for o in &outputs {
            if let Some(w) = writer.as_mut() {
                write_output(w, o, &mut datum)?;
            }
            if let (Some((w, p)), Output::Solution(sol)) = (csv.as_mut(), o) {
                write_csv_row(w, sol).map_err(|source| ReplayError::Io {
                    path: p.display().to_string(),
                    source,
                })?;
            }
        }
    }
    progress(1.0);
    if let Some(w) = writer {
        w.finish()?;
    }
    if let Some((mut w, p)) = csv {
        w.flush().map_err(|source| ReplayError::Io {
            path: p.display().to_string(),
            source,
        })?;
    }
    let problems = inputs.problems();
    let report = session.finish();
    let summary = (!report.errors.is_empty()).then(|| report.summary(f64::NEG_INFINITY));
    Ok(ReplayResult {
        report,
        problems,
        summary,
    })
}

fn write_output(w: &mut BagWriter, o: &Output, datum: &mut Option<Llh>) -> Result<(), ReplayError> {
    match o {
        Output::Solution(sol) => {
            let t = sol.nav.t_s;
            let Ok(stamp) = seconds_to_time(t) else {
                return Ok(());
            };
            let ns = (t * 1e9).round().max(0.0) as u64;
            let origin = *datum.get_or_insert(sol.nav.p);
            w.write(
                ODOMETRY_TOPIC,
                &outbound::odometry(sol, &origin, stamp, "map", "base_link"),
                ns,
            )?;
            w.write(
                FIX_OUT_TOPIC,
                &outbound::nav_sat_fix(sol, stamp, "base_link"),
                ns,
            )?;
        }
        Output::Epoch(report) => {
            let t = report.t_s;
            if let Ok(stamp) = seconds_to_time(t) {
                let ns = (t * 1e9).round().max(0.0) as u64;
                w.write(
                    NOISE_TOPIC,
                    &outbound::noise_estimates(report, stamp, "base_link"),
                    ns,
                )?;
            }
        }
        Output::Status(_) => {}
    }
    Ok(())
}

const CSV_HEADER: &str = "t_s,lat_deg,lon_deg,height_m,v_e_mps,v_n_mps,v_u_mps,roll_deg,pitch_deg,yaw_deg,sigma_e_m,sigma_n_m,sigma_u_m,clock_bias_m,clock_drift_mps";

/// One solution as a CSV row. Choice: numbers in Rust's shortest round-trip form (every
/// digit the f64 holds, and no more), so a CSV can serve as a golden reference of the
/// engine's output and nothing is lost to rounding.
fn write_csv_row(w: &mut impl Write, sol: &crate::engine::Solution) -> std::io::Result<()> {
    let nav = &sol.nav;
    let (roll, pitch, yaw) = nav.q_nb.euler_angles();
    let p = sol.position_covariance_enu_m2();
    writeln!(
        w,
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
        nav.t_s,
        nav.p.lat_rad.to_degrees(),
        nav.p.lon_rad.to_degrees(),
        nav.p.height_m,
        nav.v_n[0],
        nav.v_n[1],
        nav.v_n[2],
        roll.to_degrees(),
        pitch.to_degrees(),
        yaw.to_degrees(),
        p[(0, 0)].sqrt(),
        p[(1, 1)].sqrt(),
        p[(2, 2)].sqrt(),
        sol.clock_bias_m,
        sol.clock_drift_mps
    )
}

/// Reads a reference CSV: unix time s, latitude deg, longitude deg, ellipsoidal height m,
/// then optionally vE vN vU (m/s), then optionally roll pitch yaw (deg, ENU/FLU as the
/// solutions). Lines starting with `#` and a non-numeric first line are skipped.
pub fn read_truth_csv(path: &Path) -> Result<TruthTrack, ReplayError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReplayError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let mut samples = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Result<Vec<f64>, _> =
            line.split(',').map(|f| f.trim().parse::<f64>()).collect();
        let Ok(v) = fields else {
            if i == 0 {
                continue;
            }
            return Err(ReplayError::TruthCsv {
                path: path.display().to_string(),
                line: i + 1,
                reason: "a field is not a number".to_owned(),
            });
        };
        if !(v.len() == 4 || v.len() == 7 || v.len() == 10) {
            return Err(ReplayError::TruthCsv {
                path: path.display().to_string(),
                line: i + 1,
                reason: format!("{} fields; expected 4, 7 or 10", v.len()),
            });
        }
        samples.push(TruthSample {
            t_s: v[0],
            p: Llh::from_degrees(v[1], v[2], v[3]),
            v_n: (v.len() >= 7).then(|| nalgebra::Vector3::new(v[4], v[5], v[6])),
            q_nb: (v.len() == 10).then(|| {
                nalgebra::UnitQuaternion::from_euler_angles(
                    v[7].to_radians(),
                    v[8].to_radians(),
                    v[9].to_radians(),
                )
            }),
        });
    }
    Ok(TruthTrack::new(samples, 1.0))
}

/// The inputs of a bag (for `compare`, which runs several configurations over one bag).
pub fn bag_inputs(bag: &Path, truth_topic: Option<String>) -> Result<BagInputs, ReplayError> {
    let reader = BagReader::open(bag)?;
    let topics = BagTopics {
        truth: truth_topic,
        ..BagTopics::default()
    };
    Ok(BagInputs::new(reader.messages()?, topics))
}
