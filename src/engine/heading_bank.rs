//! The bank of heading hypotheses that resolves a coarse start (a heading 1-sigma above
//! [`BANK_ABOVE_RAD`], e.g. from a course over a short baseline of noisy fixes).
//!
//! Choice: an error-state filter linearizes the attitude error; with a heading error of
//! tens of degrees the linearization is poor (sin ψ ≠ ψ, and the velocity error grows with
//! the heading error times the acceleration), and a single filter converges slowly or to
//! a wrong, over-confident answer. The bank runs one full filter per hypothesis, the
//! headings spread over ±3σ (at most the full circle) [`SPACING_RAD`] apart,
//! each with half the spacing as its heading 1-sigma, where the filter is linear, and
//! each weighted by the start's heading prior at its offset. Every
//! GNSS measurement updates each hypothesis (plain EKF, no innovation gate, so that every
//! hypothesis is scored on the same measurements) and adds its log-likelihood
//! −½(νᵀS⁻¹ν + ln det S). Hypotheses whose likelihood falls below [`PRUNE_RATIO`] of the
//! best are dropped; the filter starts from the best one once it is alone, or after
//! [`MIN_UPDATES`] updates once it holds [`RESOLVED_WEIGHT`] of the weight or the
//! hypotheses alive have converged onto one heading (their weighted spread within the best
//! one's own heading variance: neighbours of the truth converge to it, each being a filter
//! in its linear range), or when [`MAX_S`] have passed. Its heading variance then gains the weighted
//! spread of the hypotheses still alive (moment matching of the Gaussian sum), so the
//! covariance covers what the bank could not decide. A heading is told apart only by
//! motion that is not straight and steady (accelerations, turns): on a straight road at
//! constant speed the bank waits, and the engine publishes nothing meanwhile.
//!
//! Cost: one filter per hypothesis (up to 2·3σ/spacing + 1) during the bank only.

use nalgebra::{UnitQuaternion, Vector3};

use crate::config::{Config, FilterBase, FilterVariant};
use crate::filter::ekf::FilterError;
use crate::filter::process_model::ProcessNoise;
use crate::ins::error_state::PHI;
use crate::ins::mechanization::MechanizationError;
use crate::ins::ImuSample;

use super::adaptation::Adaptation;
use super::filter_state::{interpolate, FilterState};
use super::output::EpochReport;
use crate::ins::mechanization::wrap_pi;

/// A start whose heading 1-sigma exceeds this runs the bank (rad). Choice: 10°, where the
/// error-state filter's small-angle linearization starts to fail (sin 20° differs from
/// 20° by 2 %, and the velocity error grows with the heading error times the acceleration).
pub const BANK_ABOVE_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// Spacing of the hypotheses (rad); each has half of it as its heading 1-sigma.
pub const SPACING_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// Longest time the bank runs before its best hypothesis starts (s): on a straight road
/// the headings are not told apart, and the filter must start some time.
pub const MAX_S: f64 = 120.0;
/// Likelihood ratio to the best below which a hypothesis is dropped.
pub const PRUNE_RATIO: f64 = 1e-4;
/// Weight of the best hypothesis that resolves the bank.
pub const RESOLVED_WEIGHT: f64 = 0.999;
/// Updates before the weight may resolve the bank.
pub const MIN_UPDATES: usize = 5;

#[derive(Debug, Clone)]
struct Hypothesis {
    state: FilterState,
    log_likelihood: f64,
    adaptation: Adaptation,
}

/// The running hypotheses.
#[derive(Debug, Clone)]
pub struct HeadingBank {
    hypotheses: Vec<Hypothesis>,
    /// The configuration the hypotheses are updated with.
    config: Config,
    start_t_s: f64,
    updates: usize,
}

impl HeadingBank {
    /// The bank around `initial`, whose heading has the 1-sigma `heading_sigma_rad`.
    pub fn new(initial: &FilterState, heading_sigma_rad: f64, config: &Config) -> Self {
        let mut bank_config = config.clone();
        bank_config.filter.variant = FilterVariant::Ekf;
        bank_config.filter.base = FilterBase::Auto;
        bank_config.filter.q_scaling = false;
        bank_config.gnss.innovation_gate_sigma = 0.0;
        let spacing = SPACING_RAD;
        let half_span = (3.0 * heading_sigma_rad).min(std::f64::consts::PI);
        let k = (half_span / spacing).floor() as i64;
        // On the full circle the hypotheses at ±k·spacing may meet: keep one of them.
        let full_circle = 2.0 * k as f64 * spacing >= 2.0 * std::f64::consts::PI - 1e-9;
        let last = if full_circle { k - 1 } else { k };
        let hypotheses = (-k..=last)
            .map(|i| {
                let mut state = initial.clone();
                let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), i as f64 * spacing);
                state.nav.q_nb = turn * state.nav.q_nb;
                state.p[(PHI + 2, PHI + 2)] = (spacing / 2.0).powi(2);
                // Choice: each hypothesis starts with the log-density of the start's own
                // heading estimate, N(0, σ²), at its offset, so the bank is the Gaussian
                // sum of that prior: where the measurements cannot tell the headings apart
                // (at rest, on a straight road) the start's heading keeps the weight, not
                // whichever hypothesis the noise favours (with equal weights a car parked
                // 120 s started 72° off its configured 20° prior).
                let offset_sigmas = i as f64 * spacing / heading_sigma_rad;
                Hypothesis {
                    state,
                    log_likelihood: -0.5 * offset_sigmas.powi(2),
                    adaptation: Adaptation::new(&bank_config),
                }
            })
            .collect();
        Self {
            hypotheses,
            config: bank_config,
            start_t_s: initial.nav.t_s,
            updates: 0,
        }
    }

    /// True when every hypothesis has failed.
    pub fn is_empty(&self) -> bool {
        self.hypotheses.is_empty()
    }

    /// Time of the hypotheses' last IMU sample.
    pub fn last_imu_t_s(&self) -> f64 {
        self.hypotheses
            .first()
            .map_or(f64::NEG_INFINITY, |h| h.state.last_imu.t_s)
    }

    /// Propagates every hypothesis to the raw body-frame sample `s`; the ones that fail
    /// are dropped, and the error is returned when none is left.
    pub fn propagate(
        &mut self,
        s: &ImuSample,
        noise: &ProcessNoise,
    ) -> Result<(), MechanizationError> {
        let mut error = None;
        self.hypotheses
            .retain_mut(|h| match h.state.propagate(s, noise) {
                Ok(()) => true,
                Err(e) => {
                    error = Some(e);
                    false
                }
            });
        match (self.hypotheses.is_empty(), error) {
            (true, Some(e)) => Err(e),
            _ => Ok(()),
        }
    }

    /// Updates every hypothesis with a measurement at `t_s` (propagated there with the
    /// sample interpolated towards `next` when it is ahead): `update` applies it to one
    /// state with the bank's configuration and adaptation. A hypothesis whose update fails
    /// is dropped.
    pub fn update<F>(&mut self, t_s: f64, next: &ImuSample, noise: &ProcessNoise, mut update: F)
    where
        F: FnMut(&mut FilterState, &mut Adaptation, &Config) -> Result<EpochReport, FilterError>,
    {
        let config = &self.config;
        self.hypotheses.retain_mut(|h| {
            if h.state.last_imu.t_s < t_s {
                let at_t = interpolate(&h.state.last_imu, next, t_s);
                if h.state.propagate(&at_t, noise).is_err() {
                    return false;
                }
            }
            match update(&mut h.state, &mut h.adaptation, config) {
                Ok(report) if h.state.is_finite() => {
                    if report.prior_nis.is_finite() && report.prior_log_det_s.is_finite() {
                        h.log_likelihood -= 0.5 * (report.prior_nis + report.prior_log_det_s);
                    }
                    true
                }
                _ => false,
            }
        });
        self.updates += 1;
        let best = self
            .hypotheses
            .iter()
            .map(|h| h.log_likelihood)
            .fold(f64::NEG_INFINITY, f64::max);
        let floor = best + PRUNE_RATIO.ln();
        self.hypotheses.retain(|h| h.log_likelihood >= floor);
    }

    /// The state to start the filter from once the bank has decided at `t_s` (see the
    /// module documentation), else None.
    pub fn resolved(&self, t_s: f64) -> Option<FilterState> {
        let best_ll = self
            .hypotheses
            .iter()
            .map(|h| h.log_likelihood)
            .fold(f64::NEG_INFINITY, f64::max);
        let weights: Vec<f64> = self
            .hypotheses
            .iter()
            .map(|h| (h.log_likelihood - best_ll).exp())
            .collect();
        let total: f64 = weights.iter().sum();
        let (best_index, best_weight) = weights
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))?;
        let best = &self.hypotheses[best_index].state;
        let yaw = |s: &FilterState| s.nav.q_nb.euler_angles().2;
        let spread: f64 = self
            .hypotheses
            .iter()
            .zip(&weights)
            .map(|(h, w)| {
                let d = wrap_pi(yaw(&h.state) - yaw(best));
                w / total * d * d
            })
            .sum();
        // Hypotheses that have converged onto one heading (their spread within the best
        // one's own heading σ) are one answer, whatever their weights.
        let agree = spread <= best.p[(PHI + 2, PHI + 2)];
        let decided = self.hypotheses.len() == 1
            || (self.updates >= MIN_UPDATES && (agree || best_weight / total >= RESOLVED_WEIGHT))
            || t_s - self.start_t_s >= MAX_S;
        if !decided {
            return None;
        }
        let mut state = best.clone();
        state.p[(PHI + 2, PHI + 2)] += spread;
        Some(state)
    }
}
