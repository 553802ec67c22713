//! `gnss_ins spp`: our single-point solution of every epoch of a stream of session inputs
//! (a bag's GNSS measurements and its reference, [`bag_spp_inputs`]), scored against the
//! reference, for checking the measurement pipeline without the filter.
//!
//! Scoring: the reference is interpolated to the epoch's time ([`TruthTrack`]) and the
//! epoch takes the label (environment) of the reference sample nearest in time.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use crate::config::Config;
use crate::earth::{self, Llh};
use crate::engine::update::sigma_model;
use crate::eval::{self, ErrorSummary, SolutionError, TruthSample, TruthTrack};
use crate::gnss::spp::{solve_spp, SppConfig};
use crate::gnss::{Constellation, GnssEpoch};

use crate::ros::adapter::{Input, InputMessage};
use crate::ros::bag::{BagError, BagReader};

use super::bag_inputs::{BagInput, BagInputs, BagTopics};
use super::scoring::Reference;
use super::session::SessionInput;

/// Reference samples further apart than this are not interpolated across (s).
const MAX_TRUTH_GAP_S: f64 = 1.0;

/// The solution of one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct SppRow {
    pub t_s: f64,
    pub position: Llh,
    pub clock_bias_m: f64,
    /// Every clock solved for (one per constellation, or the common one).
    pub clock_biases_m: Vec<(Constellation, f64)>,
    pub satellites_used: usize,
    /// Error against the reference (ENU, m) and the reference's label, when scored.
    pub error: Option<(nalgebra::Vector3<f64>, String)>,
}

/// The result of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SppReport {
    pub rows: Vec<SppRow>,
    /// Epochs without a solution, by reason.
    pub failures: BTreeMap<String, usize>,
}

impl SppReport {
    /// Mean inter-system bias of each constellation against the first clock of its
    /// epoch (m), and the epochs it was solved in; empty with one common clock.
    pub fn mean_inter_system_biases_m(&self) -> BTreeMap<Constellation, (f64, usize)> {
        let mut sums: BTreeMap<Constellation, (f64, usize)> = BTreeMap::new();
        for row in &self.rows {
            let Some(&(_, first_m)) = row.clock_biases_m.first() else {
                continue;
            };
            for &(c, clock_m) in row.clock_biases_m.iter().skip(1) {
                let e = sums.entry(c).or_insert((0.0, 0));
                e.0 += clock_m - first_m;
                e.1 += 1;
            }
        }
        sums.into_iter()
            .map(|(c, (sum, n))| (c, (sum / n as f64, n)))
            .collect()
    }

    /// Error summaries by label, and over every scored epoch under "all".
    pub fn summary_by_label(&self) -> BTreeMap<String, ErrorSummary> {
        let mut by: BTreeMap<String, Vec<SolutionError>> = BTreeMap::new();
        for row in &self.rows {
            if let Some((e, label)) = &row.error {
                let err = SolutionError {
                    t_s: row.t_s,
                    position_enu_m: *e,
                    velocity_enu_mps: None,
                    attitude_rpy_rad: None,
                    nees: f64::NAN,
                    nees_dof: 3,
                    position_nees: f64::NAN,
                };
                by.entry(label.clone()).or_default().push(err);
                by.entry("all".to_owned()).or_default().push(err);
            }
        }
        by.into_iter()
            .map(|(k, v)| (k, eval::summarize(&v)))
            .collect()
    }
}

/// The single-point settings of a filter configuration: its elevation mask and σ model,
/// with one receiver clock (as the filter has).
pub fn spp_config(config: &Config) -> SppConfig {
    SppConfig {
        elevation_mask_rad: config.gnss.elevation_mask_rad,
        sigma: sigma_model(config),
        ..SppConfig::default()
    }
}

/// The GNSS epochs and the references (on `truth_topic`) of the bag at `path`, for
/// single-point solutions: no filter runs, so the adapter's handling does not apply;
/// epochs that do not convert are skipped.
pub fn bag_spp_inputs(
    path: &Path,
    truth_topic: Option<String>,
) -> Result<impl Iterator<Item = SessionInput>, BagError> {
    let reader = BagReader::open(path)?;
    let topics = BagTopics {
        truth: truth_topic,
        ..BagTopics::default()
    };
    let inputs = BagInputs::new(reader.messages()?, topics, &[Input::Gnss]);
    Ok(inputs.filter_map(|item| match item {
        BagInput::Message(InputMessage::Gnss(m)) => {
            GnssEpoch::try_from(&m).ok().map(SessionInput::Gnss)
        }
        BagInput::Reference(r) => Some(SessionInput::Reference(r)),
        _ => None,
    }))
}

/// Solves every GNSS epoch of `inputs` with the constellations and settings of `config`
/// (one receiver clock, as the filter) and scores the solutions against the reference
/// samples of `inputs`.
pub fn run_spp(inputs: impl Iterator<Item = SessionInput>, config: &Config) -> SppReport {
    run_spp_with(inputs, config, false, |_| {})
}

/// [`run_spp`] with one receiver clock per constellation when `clock_per_constellation`
/// (see [`SppConfig::clock_per_constellation`]), calling `progress` with the fraction of
/// the epochs solved.
pub fn run_spp_with(
    inputs: impl Iterator<Item = SessionInput>,
    config: &Config,
    clock_per_constellation: bool,
    mut progress: impl FnMut(f64),
) -> SppReport {
    let settings = SppConfig {
        clock_per_constellation,
        ..spp_config(config)
    };
    let mut epochs: Vec<GnssEpoch> = Vec::new();
    let mut truth: Vec<TruthSample> = Vec::new();
    let mut labels: Vec<(f64, String)> = Vec::new();
    let mut environment = "unlabelled".to_owned();
    for input in inputs {
        match input {
            SessionInput::Gnss(e) => epochs.push(e),
            SessionInput::Reference(Reference::Truth(t)) => {
                labels.push((t.t_s, environment.clone()));
                truth.push(t);
            }
            SessionInput::Reference(Reference::Environment { name, .. }) => environment = name,
            _ => {}
        }
    }
    let track = TruthTrack::new(truth, MAX_TRUTH_GAP_S);
    let mut report = SppReport::default();
    let total = epochs.len();
    for (k, mut epoch) in epochs.into_iter().enumerate() {
        progress(k as f64 / total as f64);
        epoch
            .satellites
            .retain(|s| config.gnss.constellations.contains(&s.sat.constellation));
        match solve_spp(&epoch, &settings) {
            Err(e) => *report.failures.entry(e.to_string()).or_insert(0) += 1,
            Ok(sol) => {
                let error = track.at(epoch.t_s).map(|reference| {
                    (
                        earth::llh_to_enu(&sol.pos_llh, &reference.p),
                        nearest_label(&labels, epoch.t_s),
                    )
                });
                report.rows.push(SppRow {
                    t_s: epoch.t_s,
                    position: sol.pos_llh,
                    clock_bias_m: sol.clock_bias_m,
                    clock_biases_m: sol.clock_biases_m.clone(),
                    satellites_used: sol.num_used,
                    error,
                });
            }
        }
    }
    report
}

fn nearest_label(labels: &[(f64, String)], t_s: f64) -> String {
    let i = labels.partition_point(|(t, _)| *t <= t_s);
    let candidates = [i.checked_sub(1), Some(i)];
    candidates
        .into_iter()
        .flatten()
        .filter_map(|k| labels.get(k))
        .min_by(|a, b| (a.0 - t_s).abs().total_cmp(&(b.0 - t_s).abs()))
        .map_or_else(|| "unlabelled".to_owned(), |(_, l)| l.clone())
}

/// Writes the solutions as CSV: time (s, the bag's stamps), latitude and longitude (deg),
/// ellipsoidal height (m), clock bias (m), satellites used, then the ENU error (m) and the
/// reference label when scored (empty otherwise).
pub fn write_spp_csv(path: &Path, report: &SppReport) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "t_s,lat_deg,lon_deg,height_m,clock_bias_m,satellites_used,err_e_m,err_n_m,err_u_m,reference"
    )?;
    for r in &report.rows {
        let (e, label) = match &r.error {
            Some((e, l)) => (format!("{},{},{}", e[0], e[1], e[2]), l.as_str()),
            None => (",,".to_owned(), ""),
        };
        writeln!(
            w,
            "{},{},{},{},{},{},{},{}",
            r.t_s,
            r.position.lat_rad.to_degrees(),
            r.position.lon_rad.to_degrees(),
            r.position.height_m,
            r.clock_bias_m,
            r.satellites_used,
            e,
            label
        )?;
    }
    w.flush()
}
