//! The tightly-coupled measurement model of one GNSS epoch: every satellite's pseudo-range
//! and rate predicted from the nominal state (eqs. 7–9), their rows of H and elevation-
//! weighted σ, the masks, and the absorption of a receiver clock jump.

use nalgebra::{DVector, Vector3};

use crate::adaptive::common_mode::median;
use crate::config::Config;
use crate::filter::measurement_rows::AntennaGeometry;
use crate::filter::robust_update::UpdateOutcome;
use crate::gnss::geometry::{self, SatPrediction};
use crate::gnss::spp::SigmaModel;
use crate::gnss::{GnssEpoch, SatObservation};

use super::super::adaptive_noise::{NoiseVerdict, Observable};
use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind, SatRejection, SatReport};
use super::model::{Linearization, MeasurementModel, NoiseChannel, NominalNoise};

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

/// Where a row of the linearization comes from.
#[derive(Debug, Clone, Copy)]
struct RowSource {
    /// Index into the report's satellites.
    sat_index: usize,
    /// Index into the epoch's satellites.
    obs_index: usize,
    observable: Observable,
}

/// The pseudo-ranges and rates of one epoch; `w_ib_b_rad_s` is the compensated body rate
/// at the epoch (for the lever-arm velocity).
pub struct Pseudoranges<'a> {
    epoch: &'a GnssEpoch,
    w_ib_b_rad_s: &'a Vector3<f64>,
    config: &'a Config,
    sources: Vec<RowSource>,
}

impl<'a> Pseudoranges<'a> {
    pub fn new(epoch: &'a GnssEpoch, w_ib_b_rad_s: &'a Vector3<f64>, config: &'a Config) -> Self {
        Self {
            epoch,
            w_ib_b_rad_s,
            config,
            sources: Vec::new(),
        }
    }

    /// Receivers that do not steer their clock jump it by whole milliseconds (about 300 km
    /// of range), common to every pseudo-range. When the median pseudo-range innovation
    /// exceeds `threshold_m`, it is absorbed into the clock state instead of rejecting
    /// every satellite. Returns the jump (m), 0 if none.
    fn absorb_clock_jump(
        &self,
        state: &mut FilterState,
        measured: &[f64],
        predicted: &mut [f64],
        threshold_m: f64,
    ) -> f64 {
        let ranges: Vec<usize> = (0..self.sources.len())
            .filter(|&i| self.sources[i].observable == Observable::Pseudorange)
            .collect();
        let mut ys: Vec<f64> = ranges.iter().map(|&i| predicted[i] - measured[i]).collect();
        match median(&mut ys) {
            Some(common) if common.abs() > threshold_m => {
                // y = predicted − measured: a jump +J of the receiver clock gives y = −J.
                state.clock_bias_m -= common;
                for i in ranges {
                    predicted[i] -= common;
                }
                -common
            }
            _ => 0.0,
        }
    }
}

impl MeasurementModel for Pseudoranges<'_> {
    fn t_s(&self) -> f64 {
        self.epoch.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::Pseudoranges
    }

    fn linearize(&mut self, state: &mut FilterState, report: &mut EpochReport) -> Linearization {
        let config = self.config;
        let geo = AntennaGeometry::new(
            &state.nav,
            &config.mounting.lever_arm_b_m,
            self.w_ib_b_rad_s,
        );
        let rx_pos = geo.antenna_ecef_m(&state.nav.p);
        let rx_vel = geo.antenna_velocity_ecef_mps(&state.nav.v_n);
        let sigmas = sigma_model(config);
        let slow_sigmas = SigmaModel {
            pseudorange_zenith_m: config.adaptive.pseudorange_slow_sigma_m,
            prefer_reported: false,
            ..sigmas
        };
        let capacity = 2 * self.epoch.satellites.len();
        let mut rows = Vec::with_capacity(capacity);
        let mut measured = Vec::with_capacity(capacity);
        let mut predicted = Vec::with_capacity(capacity);
        let mut channels = Vec::with_capacity(capacity);
        self.sources.clear();
        for (obs_index, obs) in self.epoch.satellites.iter().enumerate() {
            let mut sat = SatReport::new(obs.sat);
            match screen(obs, &rx_pos, &rx_vel, state, self.epoch, config) {
                Err(reason) => sat.rejection = Some(reason),
                Ok(pred) => {
                    sat.elevation_rad = pred.elevation_rad;
                    let sat_index = report.satellites.len();
                    let el = Some(pred.elevation_rad);
                    let mut push = |observable, row, value, prediction, sigma: f64, slow: f64| {
                        rows.push(row);
                        measured.push(value);
                        predicted.push(prediction);
                        channels.push(NoiseChannel {
                            sat: obs.sat,
                            observable,
                            r_nominal: sigma.powi(2),
                            r_slow: slow.powi(2),
                            cn0_dbhz: obs.cn0_dbhz,
                        });
                        self.sources.push(RowSource {
                            sat_index,
                            obs_index,
                            observable,
                        });
                    };
                    // A satellite kept for its carrier phase alone gives its rate only.
                    if let Some(pseudorange_m) = obs.pseudorange_m {
                        push(
                            Observable::Pseudorange,
                            geo.pseudorange_row(&pred.los_ecef),
                            pseudorange_m,
                            pred.pseudorange_m,
                            sigmas.pseudorange_sigma_m(obs, el),
                            slow_sigmas.pseudorange_sigma_m(obs, el),
                        );
                    }
                    if let (true, Some(rate)) =
                        (config.gnss.use_pseudorange_rate, obs.pseudorange_rate_mps)
                    {
                        push(
                            Observable::PseudorangeRate,
                            geo.pseudorange_rate_row(&pred.los_ecef),
                            rate,
                            pred.pseudorange_rate_mps,
                            sigmas.pseudorange_rate_sigma_mps(obs, el),
                            0.0,
                        );
                    }
                }
            }
            report.satellites.push(sat);
        }
        report.clock_jump_m = self.absorb_clock_jump(
            state,
            &measured,
            &mut predicted,
            config.gnss.max_clock_jump_m,
        );
        Linearization {
            rows,
            measured,
            predicted,
            noise: NominalNoise::PerRow {
                channels,
                gate_sigma: config.gnss.innovation_gate_sigma,
            },
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let predictor = StatePredictor::new(state, self.epoch, self.w_ib_b_rad_s, self.config);
        let mut out = DVector::zeros(rows.len());
        // A satellite's pseudo-range and rate rows are adjacent: predict it once for both.
        let mut last: Option<(usize, Option<SatPrediction>)> = None;
        for (value, &row) in out.iter_mut().zip(rows) {
            let source = self.sources[row];
            let prediction = match last {
                Some((index, prediction)) if index == source.obs_index => prediction,
                _ => {
                    let prediction = predictor.predict(source.obs_index);
                    last = Some((source.obs_index, prediction));
                    prediction
                }
            };
            *value = prediction.map_or(f64::NAN, |p| predicted(&p, source.observable));
        }
        out
    }

    fn report_noise(&self, report: &mut EpochReport, row: usize, verdict: &NoiseVerdict) {
        let source = self.sources[row];
        let sat = &mut report.satellites[source.sat_index];
        match source.observable {
            Observable::PseudorangeRate => sat.r_rate_m2_s2 = verdict.r,
            Observable::Pseudorange => {
                sat.r_pseudorange_m2 = verdict.r;
                // Choice: the per-satellite KDE fields of the diagnostics describe the
                // pseudo-range, the observable the multipath acts on most.
                sat.kde_credibility = verdict.kde_credibility;
                sat.gaussian = verdict.gaussian;
                sat.ar_order = verdict.ar_order;
            }
        }
    }

    fn report_gated(&self, report: &mut EpochReport, row: usize, innovation: f64, normalized: f64) {
        let source = self.sources[row];
        let sat = &mut report.satellites[source.sat_index];
        if sat.rejection.is_none() {
            sat.rejection = Some(SatRejection::InnovationGate);
        }
        match source.observable {
            Observable::PseudorangeRate => {
                sat.innovation_rate_mps = innovation;
                sat.normalized_innovation_rate = normalized;
            }
            Observable::Pseudorange => {
                sat.innovation_pseudorange_m = innovation;
                sat.normalized_innovation_pseudorange = normalized;
            }
        }
    }

    fn report_update(&self, report: &mut EpochReport, rows: &[usize], outcome: &UpdateOutcome) {
        for (i, &row) in rows.iter().enumerate() {
            let source = self.sources[row];
            let sat = &mut report.satellites[source.sat_index];
            let normalized = -outcome.innovation[i] / outcome.s[(i, i)].sqrt();
            match source.observable {
                Observable::PseudorangeRate => {
                    sat.used_rate = true;
                    sat.innovation_rate_mps = -outcome.innovation[i];
                    sat.normalized_innovation_rate = normalized;
                }
                Observable::Pseudorange => {
                    sat.used_pseudorange = true;
                    sat.innovation_pseudorange_m = -outcome.innovation[i];
                    sat.normalized_innovation_pseudorange = normalized;
                    // Choice: like the KDE fields, the robust weight describes the
                    // pseudo-range.
                    sat.robust_weight = outcome.robust_weights[i];
                }
            }
        }
    }
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

/// Checks one observation against the masks and predicts it.
pub(super) fn screen(
    obs: &SatObservation,
    rx_pos: &Vector3<f64>,
    rx_vel: &Vector3<f64>,
    state: &FilterState,
    epoch: &GnssEpoch,
    config: &Config,
) -> Result<SatPrediction, SatRejection> {
    if !config.gnss.constellations.contains(&obs.sat.constellation) {
        return Err(SatRejection::ConstellationDisabled);
    }
    if obs.pseudorange_m.is_some_and(|p| !p.is_finite()) {
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
