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
//! hypothesis is scored on the same measurements; a receiver's fixes weighed with the
//! running filter's fix judges, see `HeadingBank::around`) and adds its log-likelihood
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
//! The running filter splits into a bank again ([`HeadingBank::split`]) when its heading
//! 1-sigma grows beyond [`SPLIT_ABOVE_RAD`] while moving (a vertical gyro bias the drive
//! has not yet shown, e.g. after a restart with a wide gyro bias prior: on a straight road
//! nothing observes the heading, and at the next acceleration a single filter 30–40° off
//! corrects its heading and, through the wrong linearization, its tilt and accelerometer
//! biases, which it then claims to know to tenths of a degree while degrees off).
//! Choice: a split is a Gaussian-sum filter over the heading: each hypothesis is the
//! running state conditioned on its heading offset (the states correlated with the heading,
//! e.g. the vertical gyro bias, shift with it, and their variance narrows by the heading's
//! share), so the sum keeps the running filter's mean and covariance. Each hypothesis
//! carries the vertical gyro bias its offset implies (eleven hypotheses after a restart in
//! foliage spanned +2.5 to −5.2 °/s), and the one nearest the truth, within the spacing of
//! it, is where the linearization holds. Unlike the start, a split publishes the
//! sum's moment-matched state ([`HeadingBank::published`]: weighted mean, and the weighted
//! covariances plus spreads). It becomes one filter again once that state's heading
//! 1-sigma is within half the spacing (no wider than one hypothesis at the split; at 10°
//! a filter collapsed with its truth 2σ off left the roll over-confident in the next
//! turn) or one hypothesis is left, and it collapses to split afresh around the sum's
//! mean when the best's own heading 1-sigma has grown beyond [`SPLIT_ABOVE_RAD`] (the sum
//! no longer spans the heading's growth).
//!
//! Cost: one filter per hypothesis (up to 2·3σ/spacing + 1) while the bank runs.

use nalgebra::{UnitQuaternion, Vector3};

use crate::config::{Config, FilterBase, FilterVariant};
use crate::filter::ekf::FilterError;
use crate::filter::process_model::ProcessNoise;
use crate::ins::error_state::{StateMatrix, StateVector, PHI};
use crate::ins::mechanization::MechanizationError;
use crate::ins::ImuSample;

use super::adaptation::Adaptation;
use super::filter_state::{interpolate, FilterState};
use super::fix_consistency::FixConsistency;
use super::output::EpochReport;
use crate::ins::mechanization::wrap_pi;

/// A start whose heading 1-sigma exceeds this runs the bank (rad). Choice: 10°, where the
/// error-state filter's small-angle linearization starts to fail (sin 20° differs from
/// 20° by 2 %, and the velocity error grows with the heading error times the acceleration).
pub const BANK_ABOVE_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// A running filter whose heading 1-sigma exceeds this while moving splits (rad). Choice:
/// 15°, half again the start's [`BANK_ABOVE_RAD`], where the linearization is already
/// poor but a heading that a turn soon resolves does not split.
pub const SPLIT_ABOVE_RAD: f64 = 15.0 * std::f64::consts::PI / 180.0;
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
    /// The report of its last update.
    report: Option<EpochReport>,
}

/// The running hypotheses.
#[derive(Debug, Clone)]
pub struct HeadingBank {
    hypotheses: Vec<Hypothesis>,
    /// The configuration the hypotheses are updated with.
    config: Config,
    start_t_s: f64,
    updates: usize,
    /// A split of the running filter: the state it publishes (None for a start).
    published: Option<FilterState>,
}

impl HeadingBank {
    /// The bank around `initial`, whose heading has the 1-sigma `heading_sigma_rad`;
    /// `fix_judges` are the running filter's (see `HeadingBank::around`).
    pub fn new(
        initial: &FilterState,
        heading_sigma_rad: f64,
        config: &Config,
        fix_judges: &[FixConsistency; 2],
    ) -> Self {
        let half_span = (3.0 * heading_sigma_rad).min(std::f64::consts::PI);
        let k = (half_span / SPACING_RAD).floor() as i64;
        Self::around(
            initial,
            heading_sigma_rad,
            k,
            config,
            fix_judges,
            |state, offset_rad| {
                let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), offset_rad);
                state.nav.q_nb = turn * state.nav.q_nb;
                state.p[(PHI + 2, PHI + 2)] = (SPACING_RAD / 2.0).powi(2);
            },
        )
    }

    /// The split of the running filter `running` (see the module documentation), or None
    /// when its heading is within [`SPLIT_ABOVE_RAD`]; `fix_judges` are the running
    /// filter's (see `HeadingBank::around`).
    pub fn split(
        running: &FilterState,
        config: &Config,
        fix_judges: &[FixConsistency; 2],
    ) -> Option<Self> {
        let yaw = PHI + 2;
        let variance = running.p[(yaw, yaw)];
        if !variance.is_finite() || variance <= SPLIT_ABOVE_RAD.powi(2) {
            return None;
        }
        // Conditioning on a heading offset δ: the mean moves by P e_ψ δ / P_ψψ, and the
        // covariance loses the share (1 − s²/P_ψψ) of P e_ψ e_ψᵀ P / P_ψψ, s being each
        // hypothesis' heading 1-sigma (the heading's own variance becomes s² exactly).
        // The offsets δ then carry the rest of the heading variance, P_ψψ − s², as the
        // hypotheses' weights.
        let column = running.p.column(yaw).into_owned();
        let own_variance = (SPACING_RAD / 2.0).powi(2);
        let narrowing = 1.0 - own_variance / variance;
        let offsets_sigma = (variance - own_variance).sqrt();
        // The offsets reach at least 3σ (rounded up to the spacing), or the sum would lose
        // the variance of its tails (4 % at 2.6σ).
        let half_span = (3.0 * offsets_sigma).min(std::f64::consts::PI);
        let k = ((half_span / SPACING_RAD).ceil() as i64)
            .min((std::f64::consts::PI / SPACING_RAD).round() as i64);
        let mut bank = Self::around(
            running,
            offsets_sigma,
            k,
            config,
            fix_judges,
            |state, offset_rad| {
                state.apply_correction(&(column * (offset_rad / variance)));
                state.p -= column * column.transpose() * (narrowing / variance);
                state.p = (state.p + state.p.transpose()) * 0.5;
            },
        );
        bank.published = bank.moment_matched();
        Some(bank)
    }

    /// The hypotheses at the multiples −k…k of [`SPACING_RAD`] around `center` (at most the
    /// full circle), each made from it by `offset` (the state, the heading offset in rad)
    /// and weighted by the prior N(0, `heading_sigma_rad`²) at its offset.
    ///
    /// Choice: each hypothesis weighs the receiver's fixes with the running filter's fix
    /// judges (`fix_judges`, loose coupling), not with fresh ones that take the claims for
    /// the truth until their window has filled: in foliage, whose velocities are metres
    /// per second off at a claimed 0.1 m/s, fresh judges let those velocities decide the
    /// likelihoods, and a split resolved onto a hypothesis whose vertical gyro bias was
    /// several °/s off (docs/results.md, "What that row was").
    fn around<F>(
        center: &FilterState,
        heading_sigma_rad: f64,
        k: i64,
        config: &Config,
        fix_judges: &[FixConsistency; 2],
        offset: F,
    ) -> Self
    where
        F: Fn(&mut FilterState, f64),
    {
        let mut bank_config = config.clone();
        bank_config.filter.variant = FilterVariant::Ekf;
        bank_config.filter.base = FilterBase::Auto;
        bank_config.filter.q_scaling = false;
        bank_config.gnss.innovation_gate_sigma = 0.0;
        let spacing = SPACING_RAD;
        // On the full circle the hypotheses at ±k·spacing may meet: keep one of them.
        let full_circle = 2.0 * k as f64 * spacing >= 2.0 * std::f64::consts::PI - 1e-9;
        let last = if full_circle { k - 1 } else { k };
        let hypotheses = (-k..=last)
            .map(|i| {
                let mut state = center.clone();
                offset(&mut state, i as f64 * spacing);
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
                    adaptation: Adaptation {
                        fix: fix_judges.clone(),
                        ..Adaptation::new(&bank_config)
                    },
                    report: None,
                }
            })
            .collect();
        Self {
            hypotheses,
            config: bank_config,
            start_t_s: center.nav.t_s,
            updates: 0,
            published: None,
        }
    }

    /// A split's published state (the sum's moment-matched state), or None for a start.
    pub fn published(&self) -> Option<&FilterState> {
        self.published.as_ref()
    }

    /// The hypotheses running.
    pub fn len(&self) -> usize {
        self.hypotheses.len()
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
            _ => {
                self.refresh_published();
                Ok(())
            }
        }
    }

    /// Updates every hypothesis with a measurement at `t_s` (propagated there with the
    /// sample interpolated towards `next` when it is ahead): `update` applies it to one
    /// state with the bank's configuration and adaptation. A hypothesis whose update fails
    /// is dropped. Returns the report of the best hypothesis left.
    pub fn update<F>(
        &mut self,
        t_s: f64,
        next: &ImuSample,
        noise: &ProcessNoise,
        mut update: F,
    ) -> Option<EpochReport>
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
                    h.report = Some(report);
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
        self.refresh_published();
        let best = self
            .hypotheses
            .iter()
            .max_by(|a, b| a.log_likelihood.total_cmp(&b.log_likelihood))?;
        best.report.clone()
    }

    /// Whether the bank has decided at `t_s` (see the module documentation): the state to
    /// run on from then, else None.
    pub fn resolved(&self, t_s: f64) -> Option<FilterState> {
        let collapsed = self.collapsed()?;
        if let Some(published) = &self.published {
            let decided = self.hypotheses.len() == 1
                || published.p[(PHI + 2, PHI + 2)] <= (SPACING_RAD / 2.0).powi(2)
                || collapsed.best_heading_variance > SPLIT_ABOVE_RAD.powi(2);
            return decided.then(|| published.clone());
        }
        let decided = {
            // Hypotheses that have converged onto one heading (their spread within the best
            // one's own heading σ) are one answer, whatever their weights.
            let agree = collapsed.spread <= collapsed.best_heading_variance;
            self.hypotheses.len() == 1
                || (self.updates >= MIN_UPDATES
                    && (agree || collapsed.best_share >= RESOLVED_WEIGHT))
                || t_s - self.start_t_s >= MAX_S
        };
        decided.then_some(collapsed.state)
    }

    /// The adaptation of the best hypothesis, whose fix judges learned the receiver's
    /// fixes while the bank ran (see `HeadingBank::around`); None for an empty bank.
    pub fn best_adaptation(&self) -> Option<&Adaptation> {
        let (_, best_index) = self.weights()?;
        Some(&self.hypotheses[best_index].adaptation)
    }

    /// A split keeps its published state current.
    fn refresh_published(&mut self) {
        if self.published.is_some() {
            self.published = self.moment_matched();
        }
    }

    /// The bank as one state by moment matching of the Gaussian sum: the weighted mean of
    /// the hypotheses' states (in the error state's coordinates about the best one) and
    /// the weighted sum of their covariances and spreads about that mean. Used by a split,
    /// whose hypotheses differ in every state correlated with the heading.
    fn moment_matched(&self) -> Option<FilterState> {
        let (weights, best_index) = self.weights()?;
        let best = &self.hypotheses[best_index];
        let offsets: Vec<StateVector> = self
            .hypotheses
            .iter()
            .map(|h| best.state.error_towards(&h.state))
            .collect();
        let mean = offsets
            .iter()
            .zip(&weights)
            .fold(StateVector::zeros(), |sum, (dx, w)| sum + dx * *w);
        let p = self.hypotheses.iter().zip(&offsets).zip(&weights).fold(
            StateMatrix::zeros(),
            |sum, ((h, dx), w)| {
                let d = dx - mean;
                sum + (h.state.p + d * d.transpose()) * *w
            },
        );
        let mut state = best.state.clone();
        state.apply_correction(&mean);
        state.p = p;
        Some(state)
    }

    /// The hypotheses' weights (their likelihoods, normalized) and the best one's index.
    fn weights(&self) -> Option<(Vec<f64>, usize)> {
        let best_ll = self
            .hypotheses
            .iter()
            .map(|h| h.log_likelihood)
            .fold(f64::NEG_INFINITY, f64::max);
        let relative: Vec<f64> = self
            .hypotheses
            .iter()
            .map(|h| (h.log_likelihood - best_ll).exp())
            .collect();
        let total: f64 = relative.iter().sum();
        let (best_index, _) = relative
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))?;
        Some((relative.iter().map(|w| w / total).collect(), best_index))
    }

    /// The bank as one state: the best hypothesis, its heading variance grown by the
    /// weighted spread of the hypotheses' headings about it (moment matching of the
    /// Gaussian sum about the best), so the covariance covers what the bank has not decided.
    fn collapsed(&self) -> Option<Collapsed> {
        let (weights, best_index) = self.weights()?;
        let best = &self.hypotheses[best_index].state;
        let yaw = |s: &FilterState| s.nav.q_nb.euler_angles().2;
        let spread: f64 = self
            .hypotheses
            .iter()
            .zip(&weights)
            .map(|(h, w)| {
                let d = wrap_pi(yaw(&h.state) - yaw(best));
                w * d * d
            })
            .sum();
        let mut state = best.clone();
        state.p[(PHI + 2, PHI + 2)] += spread;
        Some(Collapsed {
            state,
            spread,
            best_heading_variance: best.p[(PHI + 2, PHI + 2)],
            best_share: weights[best_index],
        })
    }
}

/// [`HeadingBank::collapsed`].
struct Collapsed {
    state: FilterState,
    /// Weighted spread of the hypotheses' headings about the best (rad²).
    spread: f64,
    /// The best hypothesis' own heading variance (rad²), and its share of the weight.
    best_heading_variance: f64,
    best_share: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ins::error_state::GYRO_BIAS;

    /// The fix judges of a fresh filter.
    fn judges() -> [FixConsistency; 2] {
        Adaptation::new(&Config::default()).fix
    }

    /// A running state whose heading σ is `heading_sigma_deg`, correlated (0.8) with the
    /// vertical gyro bias (σ 0.5 °/s), as after a drive with an unknown vertical bias.
    fn running(heading_sigma_deg: f64) -> FilterState {
        let mut state = FilterState::moving(1.0);
        let (yaw, bias) = (PHI + 2, GYRO_BIAS + 2);
        let heading_sigma = heading_sigma_deg.to_radians();
        let bias_sigma = 0.5_f64.to_radians();
        state.p[(yaw, yaw)] = heading_sigma.powi(2);
        state.p[(bias, bias)] = bias_sigma.powi(2);
        state.p[(yaw, bias)] = 0.8 * heading_sigma * bias_sigma;
        state.p[(bias, yaw)] = state.p[(yaw, bias)];
        state
    }

    #[test]
    fn a_split_keeps_the_running_filters_mean_and_covariance() {
        let before = running(20.0);
        let bank = HeadingBank::split(&before, &Config::default(), &judges()).unwrap();
        assert_eq!(
            bank.len(),
            13,
            "offsets to ±3 × 19.4° every 10°, rounded up"
        );
        let after = bank.published().unwrap();
        let dx = before.error_towards(after);
        assert!(dx.norm() < 1e-9, "mean moved by {dx:?}");
        for (i, j) in [
            (PHI + 2, PHI + 2),
            (GYRO_BIAS + 2, GYRO_BIAS + 2),
            (PHI + 2, GYRO_BIAS + 2),
        ] {
            let ratio = after.p[(i, j)] / before.p[(i, j)];
            assert!((ratio - 1.0).abs() < 0.03, "P[{i},{j}] × {ratio}");
        }
        // Each hypothesis knows its heading to half the spacing, and its bias better.
        for h in &bank.hypotheses {
            assert!((h.state.p[(PHI + 2, PHI + 2)].sqrt() - SPACING_RAD / 2.0).abs() < 1e-12);
            assert!(
                h.state.p[(GYRO_BIAS + 2, GYRO_BIAS + 2)]
                    < before.p[(GYRO_BIAS + 2, GYRO_BIAS + 2)]
            );
        }
    }

    #[test]
    fn the_judges_handed_back_are_the_best_hypothesis() {
        let mut bank = HeadingBank::split(&running(20.0), &Config::default(), &judges()).unwrap();
        for (k, h) in bank.hypotheses.iter_mut().enumerate() {
            h.log_likelihood = -((k as f64) - 3.0).powi(2);
        }
        let best = bank.best_adaptation().unwrap();
        assert!(std::ptr::eq(best, &bank.hypotheses[3].adaptation));
    }

    #[test]
    fn a_heading_within_the_linear_range_does_not_split() {
        assert!(HeadingBank::split(&running(14.0), &Config::default(), &judges()).is_none());
        assert!(HeadingBank::split(&running(16.0), &Config::default(), &judges()).is_some());
    }
}
