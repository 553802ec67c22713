//! `gnss_ins replay`: a recorded bag streamed through the ROS adapter as the live node
//! runs it (never loaded whole), with what the adapter publishes written to an output bag
//! and/or CSV, and scored against a reference when one is given.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::config::Config;
use crate::earth::Llh;
use crate::eval::{TruthSample, TruthTrack};
use crate::ros::adapter::{OutputFrames, Published, RosAdapter, TfMode};
use crate::ros::bag::{BagError, BagReader, BagWriteOptions, BagWriter, ChunkCompression};
use crate::ros::msg::{Imu, NavSatFix, NoiseEstimates, Odometry, RosMessage, TFMessage, Time};

use super::bag_inputs::BagTopics;
use super::bag_run::{BagRun, BagRunner};
use super::scoring::Scorer;

/// Output topics of a replay.
pub const ODOMETRY_TOPIC: &str = "/odometry";
pub const FIX_OUT_TOPIC: &str = "/fix/filtered";
pub const NOISE_TOPIC: &str = "/noise_estimates";
/// Written with `publish_tf` in `tf_mode` `map_to_base_link` or `map_to_odom`; in
/// `map_to_odom` also read from the input bag (the base controller's `odom → base`), as
/// the node then subscribes it.
pub const TF_TOPIC: &str = "/tf";

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

/// Options of a replay.
#[derive(Debug, Clone, Default)]
pub struct ReplayOptions<'a> {
    pub out_bag: Option<&'a Path>,
    pub csv: Option<&'a Path>,
    /// Scores at most this often (s); 0 scores every solution that has a reference.
    pub score_interval_s: f64,
    /// The frames of the written messages and the TF (the node's `map_frame`,
    /// `base_frame`, `odom_frame`, `publish_tf`, `tf_mode`).
    pub frames: OutputFrames,
    /// Compression of the output bag's chunks.
    pub compression: ChunkCompression,
}

/// Replays `bag` with `config`; `progress` is called now and then with the fraction of
/// the bag's messages done.
pub fn replay(
    bag: &Path,
    config: &Config,
    truth: TruthSource,
    options: &ReplayOptions,
    progress: impl FnMut(f64),
) -> Result<BagRun, ReplayError> {
    let reader = BagReader::open(bag)?;
    let mut topics = BagTopics::default();
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
    if options.frames.published_tf() == TfMode::MapToOdom {
        topics.tf = Some(TF_TOPIC.to_owned());
    }
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
    let mut out = ReplayOutputs::create(options)?;
    let adapter = RosAdapter::new(config.clone(), options.frames.clone());
    let adapter = if options.out_bag.is_some() {
        adapter
    } else {
        adapter.without_messages()
    };
    let scorer = Scorer::new(options.score_interval_s, track);
    let runner = BagRunner::open(&reader, topics, adapter, scorer)?;
    let run = runner.run(|published| out.write(published), progress)?;
    out.finish()?;
    Ok(run)
}

/// The output bag and CSV of a replay.
struct ReplayOutputs {
    bag: Option<BagWriter>,
    csv: Option<(BufWriter<File>, String)>,
}

impl ReplayOutputs {
    fn create(options: &ReplayOptions) -> Result<Self, ReplayError> {
        let bag = match options.out_bag {
            Some(p) => {
                let bag_options = BagWriteOptions {
                    compression: options.compression,
                    ..BagWriteOptions::default()
                };
                let mut w = BagWriter::create_with_options(p, bag_options)?;
                if options.frames.published_tf() != TfMode::None {
                    w.add_topic::<TFMessage>(TF_TOPIC)?;
                }
                w.add_topic::<Odometry>(ODOMETRY_TOPIC)?;
                w.add_topic::<NavSatFix>(FIX_OUT_TOPIC)?;
                w.add_topic::<NoiseEstimates>(NOISE_TOPIC)?;
                Some(w)
            }
            None => None,
        };
        let csv = match options.csv {
            Some(p) => {
                let path = p.display().to_string();
                let io = |source| ReplayError::Io {
                    path: path.clone(),
                    source,
                };
                let mut w = BufWriter::new(File::create(p).map_err(io)?);
                writeln!(w, "{}", CSV_HEADER).map_err(io)?;
                Some((w, path))
            }
            None => None,
        };
        Ok(Self { bag, csv })
    }

    /// Writes one published output: its messages into the bag at their stamps, a
    /// solution's row into the CSV.
    fn write(&mut self, published: &Published) -> Result<(), ReplayError> {
        if let Some(w) = self.bag.as_mut() {
            match published {
                Published::Solution(s) => {
                    // A replay with an output bag frames every solution.
                    if let Some(m) = &s.messages {
                        let ns = log_time_ns(&m.odometry.header.stamp);
                        if let Some(tf) = &m.tf {
                            w.write(TF_TOPIC, tf, ns)?;
                        }
                        w.write(ODOMETRY_TOPIC, &m.odometry, ns)?;
                        w.write(FIX_OUT_TOPIC, &m.fix, ns)?;
                    }
                }
                Published::Epoch(epoch) => {
                    let noise = &epoch.noise;
                    w.write(NOISE_TOPIC, noise, log_time_ns(&noise.header.stamp))?;
                }
                Published::NoFix(fix) => {
                    w.write(FIX_OUT_TOPIC, fix.as_ref(), log_time_ns(&fix.header.stamp))?;
                }
            }
        }
        if let (Some((w, path)), Published::Solution(s)) = (self.csv.as_mut(), published) {
            write_csv_row(w, &s.solution).map_err(|source| ReplayError::Io {
                path: path.clone(),
                source,
            })?;
        }
        Ok(())
    }

    fn finish(self) -> Result<(), ReplayError> {
        if let Some(w) = self.bag {
            w.finish()?;
        }
        if let Some((mut w, path)) = self.csv {
            w.flush()
                .map_err(|source| ReplayError::Io { path, source })?;
        }
        Ok(())
    }
}

/// The log time of a message stamped `stamp` (ns since the UNIX epoch; 0 before it).
fn log_time_ns(stamp: &Time) -> u64 {
    u64::try_from(stamp.sec).map_or(0, |sec| sec * 1_000_000_000 + u64::from(stamp.nanosec))
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
