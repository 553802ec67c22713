//! Scoring of a run's solutions against a reference: a preloaded track (a CSV) or
//! reference samples streamed with the inputs (a bag's `/ground_truth`), the estimated
//! noise σ against the true one, by environment. `replay` and `compare` feed it what the
//! adapter published (so nothing the node would not publish is scored); a
//! [`Session`](super::session::Session) over a simulated scenario feeds it the engine's
//! outputs.

use std::collections::{BTreeMap, HashMap};

use crate::engine::{EpochReport, Solution};
use crate::eval::{self, ErrorSummary, SolutionError, TruthSample, TruthTrack};
use crate::gnss::SatId;
use crate::ros::adapter::Published;

/// A reference input of a run, in time order with the sensor inputs.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// A reference sample at an IMU time (scored against the solution of that time).
    Truth(TruthSample),
    /// The true noise σ of each satellite at an epoch: (sat, range σ m, rate σ m/s).
    TruthSigmas {
        t_s: f64,
        sigmas: Vec<(SatId, f64, f64)>,
    },
    /// The environment in force from `t_s` on (simulated data).
    Environment { t_s: f64, name: String },
}

/// The estimated pseudo-range σ of one satellite at one epoch beside the true one.
#[derive(Debug, Clone, PartialEq)]
pub struct SigmaSample {
    pub t_s: f64,
    pub sat: SatId,
    pub environment: String,
    pub estimated_sigma_m: f64,
    pub true_sigma_m: f64,
}

/// A session's results.
#[derive(Debug, Clone, Default)]
pub struct SessionReport {
    /// Errors of the scored solutions with the environment they were in.
    pub errors: Vec<(String, SolutionError)>,
    pub sigmas: Vec<SigmaSample>,
    pub solutions: usize,
    pub epochs: usize,
}

impl SessionReport {
    /// The errors of the scored solutions, without their environments.
    pub fn into_solution_errors(self) -> Vec<SolutionError> {
        self.errors.into_iter().map(|(_, e)| e).collect()
    }

    /// The time of the first scored solution (the filter's start, as far as the reference
    /// reaches), if any.
    pub fn first_scored_t_s(&self) -> Option<f64> {
        self.errors.iter().map(|(_, e)| e.t_s).reduce(f64::min)
    }

    /// Summary over all scored solutions at or after `from_t_s`.
    pub fn summary(&self, from_t_s: f64) -> ErrorSummary {
        let errors: Vec<SolutionError> = self
            .errors
            .iter()
            .filter(|(_, e)| e.t_s >= from_t_s)
            .map(|(_, e)| *e)
            .collect();
        eval::summarize(&errors)
    }

    /// Summary per environment.
    pub fn summary_by_environment(&self, from_t_s: f64) -> BTreeMap<String, ErrorSummary> {
        let mut by_env: BTreeMap<String, Vec<SolutionError>> = BTreeMap::new();
        for (env, e) in self.errors.iter().filter(|(_, e)| e.t_s >= from_t_s) {
            by_env.entry(env.clone()).or_default().push(*e);
        }
        by_env
            .into_iter()
            .map(|(k, v)| (k, eval::summarize(&v)))
            .collect()
    }

    /// RMS of (estimated − true) pseudo-range σ over the satellites and epochs of an
    /// environment (m); NaN without samples.
    pub fn sigma_rms_error_m(&self, environment: &str) -> f64 {
        let d: Vec<f64> = self
            .sigmas
            .iter()
            .filter(|s| s.environment == environment)
            .map(|s| s.estimated_sigma_m - s.true_sigma_m)
            .collect();
        if d.is_empty() {
            f64::NAN
        } else {
            (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
        }
    }
}

/// Largest time between a streamed reference sample and the solution it is scored against
/// when none coincides with it (a real reference at GNSS epochs, solutions at IMU samples).
/// Choice: a few IMU intervals at 100-200 Hz; the reference is moved to the solution's time
/// with its own velocity (when it has one), so a walk or a drive loses nothing to the
/// offset, and without a velocity it costs at most speed · 20 ms.
pub const MAX_TRUTH_OFFSET_S: f64 = 0.02;

/// Scores solutions against the reference; see the module documentation.
pub struct Scorer {
    /// Scores at most this often (s); 0 scores every match.
    score_interval_s: f64,
    last_scored_t_s: f64,
    /// A preloaded reference (e.g. a CSV); otherwise references come as inputs.
    track: Option<TruthTrack>,
    latest: Option<Box<Solution>>,
    /// A streamed reference sample newer than the latest solution, with its environment,
    /// waiting for the next solution.
    waiting_truth: Option<(TruthSample, String)>,
    environment: String,
    truth_sigmas: HashMap<u64, Vec<(SatId, f64, f64)>>,
    report: SessionReport,
}

/// Times are matched to the microsecond.
fn time_key(t_s: f64) -> u64 {
    (t_s * 1e6).round() as u64
}

impl Scorer {
    /// A scorer scoring at most every `score_interval_s` (0: every match), against `track`
    /// when given, else against the streamed [`Reference::Truth`] samples.
    pub fn new(score_interval_s: f64, track: Option<TruthTrack>) -> Self {
        Self {
            score_interval_s,
            last_scored_t_s: f64::NEG_INFINITY,
            track,
            latest: None,
            waiting_truth: None,
            environment: "unlabelled".to_owned(),
            truth_sigmas: HashMap::new(),
            report: SessionReport::default(),
        }
    }

    /// Takes one reference input.
    pub fn on_reference(&mut self, reference: Reference) {
        match reference {
            Reference::Truth(t) => self.score_streamed(&t),
            Reference::TruthSigmas { t_s, sigmas } => {
                self.truth_sigmas.insert(time_key(t_s), sigmas);
            }
            Reference::Environment { name, .. } => self.environment = name,
        }
    }

    /// Takes what the adapter published.
    pub fn on_published(&mut self, published: Published) {
        match published {
            Published::Solution(s) => self.on_solution(s.solution),
            Published::Epoch(epoch) => self.on_epoch(&epoch.report),
            Published::NoFix(_) => {}
        }
    }

    /// Scores one solution.
    pub fn on_solution(&mut self, sol: Box<Solution>) {
        self.report.solutions += 1;
        if let Some(track) = &self.track {
            let t = sol.nav.t_s;
            if t - self.last_scored_t_s >= self.score_interval_s {
                if let Some(truth) = track.at(t) {
                    let environment = self.environment.clone();
                    self.record(&sol, &truth, environment);
                }
            }
        }
        self.score_waiting(&sol);
        self.latest = Some(sol);
    }

    /// Compares one epoch's estimated noise with the true one.
    pub fn on_epoch(&mut self, report: &EpochReport) {
        self.report.epochs += 1;
        self.record_sigmas(report);
    }

    /// Scores a streamed reference sample against the solution of its time, or holds it
    /// for the next solution when it falls between two (see [`MAX_TRUTH_OFFSET_S`]).
    fn score_streamed(&mut self, truth: &TruthSample) {
        let Some(sol) = self.latest.take() else {
            return;
        };
        if truth.t_s - self.last_scored_t_s >= self.score_interval_s {
            let environment = self.environment.clone();
            if (sol.nav.t_s - truth.t_s).abs() < 1e-6 {
                self.record(&sol, truth, environment);
            } else if sol.nav.t_s < truth.t_s {
                // An older sample still waiting has no nearer solution than the latest.
                if let Some((old, env)) = self.waiting_truth.take() {
                    self.record_nearest(&sol, None, &old, env);
                }
                self.waiting_truth = Some((*truth, environment));
            } else {
                self.record_nearest(&sol, None, truth, environment);
            }
        }
        self.latest = Some(sol);
    }

    /// Scores the waiting reference sample once `sol` reaches its time, against the nearer
    /// of `sol` and the latest solution before it.
    fn score_waiting(&mut self, sol: &Solution) {
        let due = self
            .waiting_truth
            .as_ref()
            .is_some_and(|(truth, _)| sol.nav.t_s >= truth.t_s);
        if !due {
            return;
        }
        if let Some((truth, environment)) = self.waiting_truth.take() {
            let before = self.latest.take();
            self.record_nearest(sol, before.as_deref(), &truth, environment);
            self.latest = before;
        }
    }

    /// Scores `truth` against the nearer of `a` and `b` when within [`MAX_TRUTH_OFFSET_S`],
    /// moving the reference to the solution's time with its velocity.
    fn record_nearest(
        &mut self,
        a: &Solution,
        b: Option<&Solution>,
        truth: &TruthSample,
        environment: String,
    ) {
        let offset = |s: &Solution| (s.nav.t_s - truth.t_s).abs();
        let sol = match b {
            Some(b) if offset(b) < offset(a) => b,
            _ => a,
        };
        if offset(sol) > MAX_TRUTH_OFFSET_S {
            return;
        }
        let dt = sol.nav.t_s - truth.t_s;
        let p = truth
            .v_n
            .and_then(|v| crate::earth::enu_to_llh(&(v * dt), &truth.p))
            .unwrap_or(truth.p);
        let moved = TruthSample {
            t_s: sol.nav.t_s,
            p,
            ..*truth
        };
        self.record(sol, &moved, environment);
    }

    fn record(&mut self, sol: &Solution, truth: &TruthSample, environment: String) {
        self.last_scored_t_s = sol.nav.t_s;
        let error = eval::solution_error(sol, truth);
        self.report.errors.push((environment, error));
    }

    fn record_sigmas(&mut self, report: &EpochReport) {
        let Some(truth) = self.truth_sigmas.remove(&time_key(report.t_s)) else {
            return;
        };
        // Older entries can no longer be matched (reports come in time order).
        let key = time_key(report.t_s);
        self.truth_sigmas.retain(|&k, _| k > key);
        for sat in report.satellites.iter().filter(|s| s.used_pseudorange) {
            if let Some(&(_, sigma_m, _)) = truth.iter().find(|(id, _, _)| *id == sat.sat) {
                self.report.sigmas.push(SigmaSample {
                    t_s: report.t_s,
                    sat: sat.sat,
                    environment: self.environment.clone(),
                    estimated_sigma_m: sat.r_pseudorange_m2.sqrt(),
                    true_sigma_m: sigma_m,
                });
            }
        }
    }

    /// Ends the scoring.
    pub fn finish(self) -> SessionReport {
        self.report
    }
}
