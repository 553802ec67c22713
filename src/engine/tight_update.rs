//! The tightly-coupled measurement update of one GNSS epoch: prediction of every
//! satellite's pseudo-range and rate from the nominal state (eqs. 7–9), screening, clock
//! jump absorption, the noise strategy, innovation gating, the update of the configured
//! base filter and scheme ([`super::robust_update`]) and the feedback.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::config::Config;
use crate::filter::ekf::FilterError;
use crate::filter::measurement_rows::{AntennaGeometry, Row};
use crate::gnss::geometry::{self, SatPrediction};
use crate::gnss::spp::SigmaModel;
use crate::gnss::GnssEpoch;

use super::adaptation::Adaptation;
use super::adaptive_noise::{Observable, ScalarMeasurement};
use super::filter_state::FilterState;
use super::output::{EpochReport, MeasurementKind, SatRejection, SatReport};
use super::robust_update::MeasurementSet;

/// One scalar measurement that passed the screening.
struct Candidate {
    /// Index into the report's satellites.
    sat_index: usize,
    /// Index into the epoch's satellites.
    obs_index: usize,
    observable: Observable,
    row: Row,
    measured: f64,
    predicted: f64,
    r: f64,
}

impl Candidate {
    /// Predicted − measured.
    fn y(&self) -> f64 {
        self.predicted - self.measured
    }

    fn is_rate(&self) -> bool {
        self.observable == Observable::PseudorangeRate
    }
}

/// The measurement σ model of the configuration.
pub fn sigma_model(config: &Config) -> SigmaModel {
    SigmaModel {
        pseudorange_zenith_m: config.gnss.pseudorange_sigma_m,
        pseudorange_rate_zenith_mps: config.gnss.pseudorange_rate_sigma_mps,
        // Choice: with elevation weighting off, a 90° floor makes σ constant.
        min_elevation_rad: if config.gnss.elevation_weighting {
            config.gnss.elevation_mask_rad.max(5f64.to_radians())
        } else {
            std::f64::consts::FRAC_PI_2
        },
        prefer_reported: config.gnss.use_receiver_sigmas,
    }
}

/// Updates `state` with `epoch`; `w_ib_b_rad_s` is the compensated body rate at the epoch
/// (for the lever-arm velocity); `adaptation` gives the variances and the update and learns
/// from the epoch (not when `learn` is false: measurements re-applied after a roll-back).
/// Returns the epoch report; on a filter failure the state is unchanged and the error is
/// returned.
pub fn update(
    state: &mut FilterState,
    epoch: &GnssEpoch,
    w_ib_b_rad_s: &Vector3<f64>,
    config: &Config,
    adaptation: &mut Adaptation,
    learn: bool,
) -> Result<EpochReport, FilterError> {
    let noise = &mut adaptation.noise;
    let geo = AntennaGeometry::new(&state.nav, &config.mounting.lever_arm_b_m, w_ib_b_rad_s);
    let rx_pos = geo.antenna_ecef_m(&state.nav.p);
    let rx_vel = geo.antenna_velocity_ecef_mps(&state.nav.v_n);
    let sigmas = sigma_model(config);
    let mut report = EpochReport::new(epoch.t_s, MeasurementKind::Pseudoranges, config);
    let mut candidates = Vec::with_capacity(2 * epoch.satellites.len());
    for (obs_index, obs) in epoch.satellites.iter().enumerate() {
        let mut sat = SatReport::new(obs.sat);
        match screen(obs, &rx_pos, &rx_vel, state, epoch, config) {
            Err(reason) => sat.rejection = Some(reason),
            Ok(pred) => {
                sat.elevation_rad = pred.elevation_rad;
                let sat_index = report.satellites.len();
                let el = Some(pred.elevation_rad);
                candidates.push(Candidate {
                    sat_index,
                    obs_index,
                    observable: Observable::Pseudorange,
                    row: geo.pseudorange_row(&pred.los_ecef),
                    measured: obs.pseudorange_m,
                    predicted: pred.pseudorange_m,
                    r: sigmas.pseudorange_sigma_m(obs, el).powi(2),
                });
                if let (true, Some(rate)) =
                    (config.gnss.use_pseudorange_rate, obs.pseudorange_rate_mps)
                {
                    candidates.push(Candidate {
                        sat_index,
                        obs_index,
                        observable: Observable::PseudorangeRate,
                        row: geo.pseudorange_rate_row(&pred.los_ecef),
                        measured: rate,
                        predicted: pred.pseudorange_rate_mps,
                        r: sigmas.pseudorange_rate_sigma_mps(obs, el).powi(2),
                    });
                }
            }
        }
        report.satellites.push(sat);
    }
    report.clock_jump_m = absorb_clock_jump(state, &mut candidates, config.gnss.max_clock_jump_m);
    let scalars: Vec<ScalarMeasurement> = candidates
        .iter()
        .map(|c| ScalarMeasurement {
            sat: report.satellites[c.sat_index].sat,
            observable: c.observable,
            measured: c.measured,
            predicted: c.predicted,
            hph: (c.row * state.p * c.row.transpose())[(0, 0)],
            r_nominal: c.r,
        })
        .collect();
    let verdicts = noise.variances(epoch.t_s, &scalars, learn);
    for (c, v) in candidates.iter_mut().zip(&verdicts) {
        c.r = v.r;
        let sat = &mut report.satellites[c.sat_index];
        if c.is_rate() {
            sat.r_rate_m2_s2 = v.r;
        } else {
            sat.r_pseudorange_m2 = v.r;
            // Choice: the per-satellite KDE fields of the diagnostics describe the
            // pseudo-range, the observable the multipath acts on most.
            sat.kde_credibility = v.kde_credibility;
            sat.gaussian = v.gaussian;
            sat.ar_order = v.ar_order;
        }
    }
    let screened: Vec<(usize, ScalarMeasurement)> = candidates
        .iter()
        .map(|c| c.obs_index)
        .zip(scalars)
        .collect();
    let screened_rows: Vec<Row> = candidates.iter().map(|c| c.row).collect();
    gate(
        &mut candidates,
        &state.p,
        config.gnss.innovation_gate_sigma,
        &mut report,
    );
    report.q_scale = adaptation.q.scale();
    if !candidates.is_empty() {
        let m = candidates.len();
        let mut h = DMatrix::zeros(m, crate::ins::error_state::N);
        let mut y = DVector::zeros(m);
        let mut r = DMatrix::zeros(m, m);
        for (i, c) in candidates.iter().enumerate() {
            h.row_mut(i).copy_from(&c.row);
            y[i] = c.y();
            r[(i, i)] = c.r;
        }
        let predict =
            |s: &FilterState| predict_candidates(s, &candidates, epoch, w_ib_b_rad_s, config);
        let set = MeasurementSet {
            h,
            y,
            r,
            predict: &predict,
        };
        let result = adaptation.update.update(state, &set)?;
        for (i, c) in candidates.iter().enumerate() {
            let sat = &mut report.satellites[c.sat_index];
            let normalized = -result.innovation[i] / result.s[(i, i)].sqrt();
            if c.is_rate() {
                sat.used_rate = true;
                sat.innovation_rate_mps = -result.innovation[i];
                sat.normalized_innovation_rate = normalized;
            } else {
                sat.used_pseudorange = true;
                sat.innovation_pseudorange_m = -result.innovation[i];
                sat.normalized_innovation_pseudorange = normalized;
                // Choice: like the KDE fields, the robust weight describes the pseudo-range.
                sat.robust_weight = result.robust_weights[i];
            }
        }
        report.measurements_used = m;
        report.nis = result.nis;
        report.adaptive_factor = result.adaptive_factor;
        report.mahalanobis_d2 = result.mahalanobis_d2;
        report.chi2_threshold = result.chi2_threshold;
        if learn {
            adaptation
                .q
                .push(&result.innovation, &result.r, &result.hph);
        }
    }
    if learn && adaptation.noise.wants_posterior_predictions() {
        let posterior_hph: Vec<f64> = if adaptation.noise.wants_posterior_hph() {
            screened_rows
                .iter()
                .map(|row| (row * state.p * row.transpose())[(0, 0)])
                .collect()
        } else {
            Vec::new()
        };
        let (rows, posterior) = posterior_predictions(state, epoch, w_ib_b_rad_s, config, screened);
        adaptation
            .noise
            .after_update(epoch.t_s, &rows, &posterior, &posterior_hph);
    }
    Ok(report)
}

/// Predicts satellites' measurements from one filter state: the antenna's position and
/// velocity are computed once, then each satellite is predicted from them.
struct StatePredictor<'a> {
    rx_pos: Vector3<f64>,
    rx_vel: Vector3<f64>,
    state: &'a FilterState,
    epoch: &'a GnssEpoch,
}

impl<'a> StatePredictor<'a> {
    fn new(
        state: &'a FilterState,
        epoch: &'a GnssEpoch,
        w_ib_b_rad_s: &Vector3<f64>,
        config: &Config,
    ) -> Self {
        let geo = AntennaGeometry::new(&state.nav, &config.mounting.lever_arm_b_m, w_ib_b_rad_s);
        Self {
            rx_pos: geo.antenna_ecef_m(&state.nav.p),
            rx_vel: geo.antenna_velocity_ecef_mps(&state.nav.v_n),
            state,
            epoch,
        }
    }

    /// The prediction of the epoch's satellite `obs_index`; None when it fails.
    fn predict(&self, obs_index: usize) -> Option<SatPrediction> {
        let obs = self.epoch.satellites.get(obs_index)?;
        geometry::predict(
            obs,
            &self.rx_pos,
            &self.rx_vel,
            self.state.clock_bias_m,
            self.state.clock_drift_mps,
            self.epoch.klobuchar.as_ref(),
            self.epoch.gps_time_of_week_s,
        )
        .ok()
    }
}

/// The predicted value of `observable`.
fn predicted(p: &SatPrediction, observable: Observable) -> f64 {
    match observable {
        Observable::Pseudorange => p.pseudorange_m,
        Observable::PseudorangeRate => p.pseudorange_rate_mps,
    }
}

/// The predictions of the candidates (same order) from `state`; None when one fails.
fn predict_candidates(
    state: &FilterState,
    candidates: &[Candidate],
    epoch: &GnssEpoch,
    w_ib_b_rad_s: &Vector3<f64>,
    config: &Config,
) -> Option<DVector<f64>> {
    let predictor = StatePredictor::new(state, epoch, w_ib_b_rad_s, config);
    let mut out = DVector::zeros(candidates.len());
    for (i, c) in candidates.iter().enumerate() {
        out[i] = predicted(&predictor.predict(c.obs_index)?, c.observable);
    }
    Some(out)
}

/// The screened measurements with their predictions from the corrected state (NaN where
/// the prediction fails).
fn posterior_predictions(
    state: &FilterState,
    epoch: &GnssEpoch,
    w_ib_b_rad_s: &Vector3<f64>,
    config: &Config,
    screened: Vec<(usize, ScalarMeasurement)>,
) -> (Vec<ScalarMeasurement>, Vec<f64>) {
    let predictor = StatePredictor::new(state, epoch, w_ib_b_rad_s, config);
    let mut posterior = Vec::with_capacity(screened.len());
    let mut rows = Vec::with_capacity(screened.len());
    // A satellite's pseudo-range and rate rows are adjacent: predict it once for both.
    let mut last: Option<(usize, Option<SatPrediction>)> = None;
    for (obs_index, row) in screened {
        let value = match last {
            Some((index, value)) if index == obs_index => value,
            _ => {
                let value = predictor.predict(obs_index);
                last = Some((obs_index, value));
                value
            }
        };
        posterior.push(value.map_or(f64::NAN, |p| predicted(&p, row.observable)));
        rows.push(row);
    }
    (rows, posterior)
}

/// Checks one observation against the masks and predicts it.
fn screen(
    obs: &crate::gnss::SatObservation,
    rx_pos: &Vector3<f64>,
    rx_vel: &Vector3<f64>,
    state: &FilterState,
    epoch: &GnssEpoch,
    config: &Config,
) -> Result<SatPrediction, SatRejection> {
    if !config.gnss.constellations.contains(&obs.sat.constellation) {
        return Err(SatRejection::ConstellationDisabled);
    }
    if !obs.pseudorange_m.is_finite() {
        return Err(SatRejection::NotANumber);
    }
    if config.gnss.cn0_mask_dbhz > 0.0 {
        match obs.cn0_dbhz {
            Some(cn0) if cn0 >= config.gnss.cn0_mask_dbhz => {}
            _ => return Err(SatRejection::Cn0Mask),
        }
    }
    let pred = geometry::predict(
        obs,
        rx_pos,
        rx_vel,
        state.clock_bias_m,
        state.clock_drift_mps,
        epoch.klobuchar.as_ref(),
        epoch.gps_time_of_week_s,
    )
    .map_err(|_| SatRejection::NoSatelliteState)?;
    if pred.elevation_rad < config.gnss.elevation_mask_rad {
        return Err(SatRejection::ElevationMask);
    }
    Ok(pred)
}

fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// Receivers that do not steer their clock jump it by whole milliseconds (about 300 km of
/// range), common to every pseudo-range. When the median pseudo-range innovation exceeds
/// `threshold_m`, it is absorbed into the clock state instead of rejecting every
/// satellite. Returns the jump (m), 0 if none.
fn absorb_clock_jump(
    state: &mut FilterState,
    candidates: &mut [Candidate],
    threshold_m: f64,
) -> f64 {
    let mut ys: Vec<f64> = candidates
        .iter()
        .filter(|c| !c.is_rate())
        .map(Candidate::y)
        .collect();
    match median(&mut ys) {
        Some(common) if common.abs() > threshold_m => {
            // y = predicted − measured: a jump +J of the receiver clock gives y = −J.
            state.clock_bias_m -= common;
            for c in candidates.iter_mut().filter(|c| !c.is_rate()) {
                c.predicted -= common;
            }
            -common
        }
        _ => 0.0,
    }
}

/// Innovation gate on each scalar measurement.
///
/// Choice: with three or more measurements of a kind, the gate tests each innovation's
/// distance from the median innovation of its kind, scaled by its own √S. A receiver clock
/// offset or drift error shifts all innovations of a kind together; that is for the update
/// to estimate, not a reason to reject every satellite. With fewer, the plain |y|/√S test.
fn gate(
    candidates: &mut Vec<Candidate>,
    p: &crate::ins::error_state::StateMatrix,
    gate_sigma: f64,
    report: &mut EpochReport,
) {
    if gate_sigma <= 0.0 {
        return;
    }
    let common = |is_rate: bool, cands: &[Candidate]| {
        let mut ys: Vec<f64> = cands
            .iter()
            .filter(|c| c.is_rate() == is_rate)
            .map(Candidate::y)
            .collect();
        if ys.len() >= 3 {
            median(&mut ys).unwrap_or(0.0)
        } else {
            0.0
        }
    };
    let common_range = common(false, candidates);
    let common_rate = common(true, candidates);
    candidates.retain(|c| {
        let s = (c.row * p * c.row.transpose())[(0, 0)] + c.r;
        let offset = if c.is_rate() {
            common_rate
        } else {
            common_range
        };
        let keep = (c.y() - offset).abs() <= gate_sigma * s.sqrt();
        if !keep {
            let sat = &mut report.satellites[c.sat_index];
            if sat.rejection.is_none() {
                sat.rejection = Some(SatRejection::InnovationGate);
            }
            if c.is_rate() {
                sat.innovation_rate_mps = -c.y();
                sat.normalized_innovation_rate = -c.y() / s.sqrt();
            } else {
                sat.innovation_pseudorange_m = -c.y();
                sat.normalized_innovation_pseudorange = -c.y() / s.sqrt();
            }
        }
        keep
    });
}
