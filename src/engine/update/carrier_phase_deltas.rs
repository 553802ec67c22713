//! The time-differenced carrier phase (TDCP) of one epoch: each satellite's phase change
//! since the previous epoch (the [`PhaseAnchor`]), λ·(φ_k − φ_{k−1}) in metres, measures the
//! change of its pseudo-range over the interval without the ambiguity:
//!
//!   λΔφ = Δρ + c·Δdt_r − c·Δdt_s + ΔT − ΔI + noise,
//!
//! predicted as the pseudo-range predicted from the prior at this epoch minus the one
//! predicted from the updated state at the previous epoch (satellite motion, earth
//! rotation and satellite clocks from the broadcast ephemeris; the receiver clock's change
//! from the clock drift state).
//!
//! Choice: the phase's ionospheric advance has the opposite sign of the code delay the
//! prediction carries; over an interval of seconds the delay changes by millimetres, and
//! its change is left in the noise.
//!
//! Choice (the correlation with the previous epoch's state): no stochastic cloning. The
//! previous epoch's antenna position enters the prediction as a nominal value, and the
//! error of the predicted displacement Δr = r_k − r_{k−1} is the integral of the velocity
//! error over the interval, δΔr = Δt·δv_k − ½Δt²·δv̇, with δv̇ = F_v·δx the velocity rows of
//! the process model at the prior: H = Δt·h_rate + ½Δt²·uᵀF_v (h_rate the pseudo-range-rate
//! row, u the line of sight). This is exact to first order for the part of Δr's error built
//! up over the interval; what it leaves out is the process noise inside the interval,
//! added to R as the accelerometer's velocity random walk integrated over it
//! (σ² = q_v·Δt³/3). The measurement thus constrains the velocity (and through F the tilt
//! and accelerometer bias), not the absolute position, which it cannot know. The
//! consecutive differences share their middle epoch's phase noise (correlation −½ between
//! successive updates); it is not modelled.
//!
//! Choice: the receiver clock's change is estimated (the clock drift state, Δt per row),
//! not differenced out against a reference satellite: the rows stay independent, the
//! median-offset innovation gate of the pseudo-ranges applies as it is, and the drift state
//! the pseudo-range rates already use learns from the phases too.
//!
//! Cycle slips: a satellite is left out (counted in the report) when lock was lost
//! (the receiver's flag, or its lock time decreased), the half-cycle ambiguity is not
//! resolved at either epoch, the wavelength is missing or changed, or the phase change is
//! further than `gnss.tdcp_slip_threshold_m` from the one the Doppler predicts (the mean
//! of both epochs' pseudo-range rates times Δt); then by the innovation gate.

use nalgebra::{DMatrix, DVector, SMatrix, Vector3};

use crate::adaptive::common_mode::median;
use crate::config::Config;
use crate::filter::measurement_rows::{row_variance, AntennaGeometry, Row};
use crate::filter::process_model::{self, LinearizationPoint, ProcessNoise};
use crate::filter::robust_update::UpdateOutcome;
use crate::gnss::{CarrierPhase, GnssEpoch, SatObservation};
use crate::ins::error_state::{DV, N};

use super::super::filter_state::FilterState;
use super::super::output::{EpochReport, MeasurementKind, PhaseRejection, SatRejection, SatReport};
use super::super::phase_anchor::{AnchoredPhase, PhaseAnchor};
use super::model::{Linearization, MeasurementModel, NominalNoise};
use super::pseudoranges::{screen, sigma_model};

/// Fewest phase changes an update uses.
///
/// Choice: 4, the displacement's three components and the clock's change from the phases
/// alone. With fewer, the clock drift state's uncertainty (0.2 m/s per √s by default)
/// absorbs a slip of a few cycles on a lone satellite unseen, and the update adds little.
const MIN_ROWS: usize = 4;

/// One row: its satellite in the report, its row of H, its measured phase change, its
/// prediction from the prior and its variance.
#[derive(Debug, Clone, Copy)]
struct DeltaSource {
    sat_index: usize,
    row: Row,
    measured_m: f64,
    predicted_m: f64,
    r_m2: f64,
}

/// The phase changes of one epoch against `anchor`; `w_ib_b_rad_s` is the compensated
/// body rate at the epoch (for the lever-arm velocity), `process_noise` the process model
/// the filter propagates with.
pub struct CarrierPhaseDeltas<'a> {
    epoch: &'a GnssEpoch,
    anchor: &'a PhaseAnchor,
    w_ib_b_rad_s: &'a Vector3<f64>,
    config: &'a Config,
    process_noise: &'a ProcessNoise,
    /// The prior the rows were linearized at (predictions of other states are linear
    /// about it).
    prior: Option<FilterState>,
    sources: Vec<DeltaSource>,
}

impl<'a> CarrierPhaseDeltas<'a> {
    pub fn new(
        epoch: &'a GnssEpoch,
        anchor: &'a PhaseAnchor,
        w_ib_b_rad_s: &'a Vector3<f64>,
        config: &'a Config,
        process_noise: &'a ProcessNoise,
    ) -> Self {
        Self {
            epoch,
            anchor,
            w_ib_b_rad_s,
            config,
            process_noise,
            prior: None,
            sources: Vec::new(),
        }
    }
}

impl MeasurementModel for CarrierPhaseDeltas<'_> {
    fn t_s(&self) -> f64 {
        self.epoch.t_s
    }

    fn kind(&self) -> MeasurementKind {
        MeasurementKind::CarrierPhaseDeltas
    }

    fn linearize(&mut self, state: &mut FilterState, report: &mut EpochReport) -> Linearization {
        let config = self.config;
        self.sources.clear();
        self.prior = Some(state.clone());
        let dt_s = self.epoch.t_s - self.anchor.t_s;
        if !(dt_s > 0.0 && dt_s <= config.gnss.tdcp_max_interval_s) {
            return empty();
        }
        let geo = AntennaGeometry::new(
            &state.nav,
            &config.mounting.lever_arm_b_m,
            self.w_ib_b_rad_s,
        );
        let rx_pos = geo.antenna_ecef_m(&state.nav.p);
        let rx_vel = geo.antenna_velocity_ecef_mps(&state.nav.v_n);
        let velocity_rows = velocity_dynamics(state, self.process_noise);
        let sigmas = sigma_model(config);
        // Process noise inside the interval (see the module's Choice).
        let within_interval_m2 = config.imu.accel_vrw_m_s_per_sqrt_s.powi(2) * dt_s.powi(3) / 3.0;
        for obs in &self.epoch.satellites {
            let (Some(phase), Some(anchored)) = (obs.carrier_phase, self.anchor.get(obs.sat))
            else {
                continue;
            };
            let mut sat = SatReport::new(obs.sat);
            let delta = phase_delta_m(obs, &phase, anchored, dt_s, config).and_then(|delta| {
                let prediction = screen(obs, &rx_pos, &rx_vel, state, self.epoch, config)
                    .map_err(Refusal::Sat)?;
                Ok((delta, prediction))
            });
            match delta {
                Err(refusal) => refusal.report(&mut sat),
                Ok((delta_m, pred)) => {
                    sat.elevation_rad = pred.elevation_rad;
                    let rate_row = geo.pseudorange_rate_row(&pred.los_ecef);
                    let u_v = rate_row.fixed_columns::<3>(DV);
                    let row = rate_row * dt_s - u_v * velocity_rows * (0.5 * dt_s * dt_s);
                    let sigma_m =
                        sigmas.scaled(config.gnss.tdcp_phase_sigma_m, Some(pred.elevation_rad));
                    let r = 2.0 * sigma_m * sigma_m + within_interval_m2;
                    sat.r_pseudorange_m2 = r;
                    self.sources.push(DeltaSource {
                        sat_index: report.satellites.len(),
                        row,
                        measured_m: delta_m,
                        predicted_m: pred.pseudorange_m - anchored.predicted_pseudorange_m,
                        r_m2: r,
                    });
                }
            }
            report.satellites.push(sat);
        }
        self.gate(state, report);
        self.require_redundancy(report);
        let r = DMatrix::from_diagonal(&DVector::from_iterator(
            self.sources.len(),
            self.sources.iter().map(|s| s.r_m2),
        ));
        Linearization {
            rows: self.sources.iter().map(|s| s.row).collect(),
            measured: self.sources.iter().map(|s| s.measured_m).collect(),
            predicted: self.sources.iter().map(|s| s.predicted_m).collect(),
            noise: NominalNoise::Joint(r),
        }
    }

    fn predict(&self, state: &FilterState, rows: &[usize]) -> DVector<f64> {
        let Some(prior) = &self.prior else {
            return DVector::from_element(rows.len(), f64::NAN);
        };
        let dx = prior.error_towards(state);
        DVector::from_iterator(
            rows.len(),
            rows.iter().map(|&i| {
                let source = &self.sources[i];
                // The nominal state is the true one plus the error: the corrected state's
                // prediction is the prior's minus H·δx.
                source.predicted_m - (source.row * dx)[0]
            }),
        )
    }

    fn report_update(&self, report: &mut EpochReport, rows: &[usize], outcome: &UpdateOutcome) {
        for (i, &row) in rows.iter().enumerate() {
            let sat = &mut report.satellites[self.sources[row].sat_index];
            sat.used_pseudorange = true;
            sat.innovation_pseudorange_m = -outcome.innovation[i];
            sat.normalized_innovation_pseudorange =
                -outcome.innovation[i] / outcome.s[(i, i)].sqrt();
            sat.robust_weight = outcome.robust_weights[i];
        }
    }
}

impl CarrierPhaseDeltas<'_> {
    /// The innovation gate `gnss.innovation_gate_sigma` around the median innovation (the
    /// clock drift's error is common to all rows), as the pseudo-ranges' gate; drops the
    /// rows it leaves out and reports them.
    fn gate(&mut self, state: &FilterState, report: &mut EpochReport) {
        let gate_sigma = self.config.gnss.innovation_gate_sigma;
        if gate_sigma <= 0.0 {
            return;
        }
        let mut ys: Vec<f64> = self
            .sources
            .iter()
            .map(|s| s.predicted_m - s.measured_m)
            .collect();
        let offset = if ys.len() >= 3 {
            median(&mut ys).unwrap_or(0.0)
        } else {
            0.0
        };
        self.sources.retain(|source| {
            let y = source.predicted_m - source.measured_m;
            let s = row_variance(&source.row, &state.p) + source.r_m2;
            let kept = (y - offset).abs() <= gate_sigma * s.sqrt();
            if !kept {
                let sat = &mut report.satellites[source.sat_index];
                sat.rejection = Some(SatRejection::InnovationGate);
                sat.innovation_pseudorange_m = -y;
                sat.normalized_innovation_pseudorange = -y / s.sqrt();
            }
            kept
        });
    }

    /// Leaves every row out, reported, when fewer than [`MIN_ROWS`] are left.
    fn require_redundancy(&mut self, report: &mut EpochReport) {
        if self.sources.len() >= MIN_ROWS {
            return;
        }
        for source in self.sources.drain(..) {
            report.satellites[source.sat_index].phase_rejection =
                Some(PhaseRejection::TooFewPhases);
        }
    }
}

/// Why a satellite's phase change is left out.
enum Refusal {
    /// For a reason the pseudo-ranges share.
    Sat(SatRejection),
    /// For a reason of the phase's own.
    Phase(PhaseRejection),
}

impl Refusal {
    /// Notes it in the satellite's report.
    fn report(self, sat: &mut SatReport) {
        match self {
            Self::Sat(reason) => sat.rejection = Some(reason),
            Self::Phase(reason) => sat.phase_rejection = Some(reason),
        }
    }
}

/// A linearization without rows.
fn empty() -> Linearization {
    Linearization {
        rows: Vec::new(),
        measured: Vec::new(),
        predicted: Vec::new(),
        noise: NominalNoise::Joint(DMatrix::zeros(0, 0)),
    }
}

/// The velocity rows F_v of the process model at `state` (δv̇ = F_v·δx), with the specific
/// force of its last IMU interval.
fn velocity_dynamics(state: &FilterState, noise: &ProcessNoise) -> SMatrix<f64, 3, N> {
    let f_ib_b_m_s2 = state
        .prev_increment
        .map_or(Vector3::zeros(), |i| i.dv_b_m_s / i.dt_s);
    let w_ib_b_rad_s = state
        .prev_increment
        .map_or(Vector3::zeros(), |i| i.dtheta_b_rad / i.dt_s);
    let lin = LinearizationPoint {
        nav: state.nav,
        f_ib_b_m_s2,
        w_ib_b_rad_s,
    };
    process_model::system_matrix(&lin, noise)
        .fixed_rows::<3>(DV)
        .into_owned()
}

/// The phase change λ·(φ_k − φ_{k−1}) (m) of `obs` since `anchored`, or why it cannot be
/// used.
fn phase_delta_m(
    obs: &SatObservation,
    phase: &CarrierPhase,
    anchored: &AnchoredPhase,
    dt_s: f64,
    config: &Config,
) -> Result<f64, Refusal> {
    if !config.gnss.constellations.contains(&obs.sat.constellation) {
        return Err(Refusal::Sat(SatRejection::ConstellationDisabled));
    }
    let before = &anchored.phase;
    let wavelength_m = match (phase.wavelength_m, before.wavelength_m) {
        (Some(now), Some(then)) if now.is_finite() && now > 0.0 && now == then => now,
        _ => return Err(Refusal::Phase(PhaseRejection::NoWavelength)),
    };
    if phase.half_cycle_unresolved || before.half_cycle_unresolved {
        return Err(Refusal::Phase(PhaseRejection::HalfCycleUnresolved));
    }
    let lock_decreased = matches!(
        (phase.lock_time_s, before.lock_time_s),
        (Some(now), Some(then)) if now.partial_cmp(&then).is_none_or(|o| o.is_lt())
    );
    if phase.loss_of_lock || lock_decreased {
        return Err(Refusal::Phase(PhaseRejection::CycleSlip));
    }
    let delta_m = (phase.cycles - before.cycles) * wavelength_m;
    if !delta_m.is_finite() {
        return Err(Refusal::Sat(SatRejection::NotANumber));
    }
    // Choice: the trapezoid of both epochs' rates where both are there, else the one there
    // is; without Doppler the test is skipped and the innovation gate remains.
    let rates = [obs.pseudorange_rate_mps, anchored.pseudorange_rate_mps];
    let finite: Vec<f64> = rates
        .into_iter()
        .flatten()
        .filter(|r| r.is_finite())
        .collect();
    if !finite.is_empty() {
        let doppler_m = finite.iter().sum::<f64>() / finite.len() as f64 * dt_s;
        if (delta_m - doppler_m).abs() > config.gnss.tdcp_slip_threshold_m {
            return Err(Refusal::Phase(PhaseRejection::CycleSlip));
        }
    }
    Ok(delta_m)
}
