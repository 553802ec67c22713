//! Single-point positioning (SPP): receiver position, clock bias, velocity and clock drift
//! from one epoch of pseudo-ranges and pseudo-range rates, by iterated weighted least
//! squares (Gauss-Newton) on the measurement model of [`crate::gnss::geometry`].
//!
//! Choices:
//! - Receiver clock: one for all satellites by default (multi-constellation time offsets
//!   assumed corrected at the ephemeris level, as the message contract's satellite clock
//!   field implies), or, with [`SppConfig::clock_per_constellation`], one per
//!   constellation present. The latter absorbs the inter-system biases a real receiver
//!   has: the offsets between the systems' time scales (GST and BDT against GPST, a few
//!   to tens of ns) and the receiver's own signal delays, which differ between the
//!   frequencies and codes each system is tracked on. The reported clock bias and its
//!   covariance are those of the first constellation in [`Constellation`] order (GPS
//!   first); the others are listed in [`SppSolution::clock_biases_m`].
//! - Weights are 1/σ² with σ = σ_zenith / sin(el) ([`SigmaModel`]); the covariance is
//!   the a-priori (HᵀWH)⁻¹, not rescaled by the a-posteriori variance factor, so it is as
//!   good as the σ model.
//! - Start: the earth's centre (or a caller's guess) with zero clock bias. While the
//!   iterate is not within [`NEAR_SURFACE_HEIGHT_M`] of the ellipsoid (the first steps from
//!   the centre), neither the elevation mask, the elevation weighting nor the atmospheric
//!   delays are applied: elevations computed from such a point are meaningless and would
//!   mask good satellites. The same holds for a receiver truly above that height.
//! - Convergence: the Gauss-Newton step (position and clock, m) falls below the
//!   configured tolerance and the set of satellites used is unchanged at the new point.
//! - Outliers: after convergence the standardized residual w_i = v_i / σ_{v_i}, with
//!   σ²_{v_i} = σ_i² − h_i (HᵀWH)⁻¹ h_iᵀ the residual variance (Baarda's w-test), is
//!   computed for every satellite; if the largest |w_i| exceeds the threshold and at
//!   least 6 satellites are used (so one redundant measurement remains after the
//!   removal), that satellite is excluded and the solution is iterated again. One at a
//!   time, until no |w_i| exceeds the threshold. With a clock per constellation the
//!   unknowns are 3 + the number of clocks, and the 6 becomes that plus 2.
//! - Velocity and clock drift: linear weighted least squares on the rates of the
//!   satellites used for the position, at the converged position (exact in one step,
//!   the rate model being linear in the receiver velocity and drift), with the same
//!   w-test and threshold on the rate residuals, one exclusion at a time while 6 rates
//!   remain. (Without it one wrong rate, e.g. a satellite velocity off by 3 km/s, once
//!   put the start-up's velocity, and the run, kilometres off.)

use nalgebra::{DMatrix, DVector, Matrix3, Matrix4, Vector3, Vector4};
use thiserror::Error;

use crate::earth::{ecef_to_llh, rot_ecef_to_enu, Llh, SPEED_OF_LIGHT_M_S};
use crate::gnss::atmosphere::TroposphereModel;
use crate::gnss::geometry::{
    line_of_sight, predict_with, DelayModels, GnssModelError, SatPrediction,
};
use crate::gnss::{Constellation, GnssEpoch, SatId, SatObservation};

/// Height band (± m about the ellipsoid) within which the iterate counts as "near the
/// surface" and the elevation mask, elevation weights and atmosphere are applied.
pub const NEAR_SURFACE_HEIGHT_M: f64 = 100_000.0;

/// Unknowns of the position solution with one clock (x, y, z, clock) and of the velocity
/// solution (v_x, v_y, v_z, drift).
const UNKNOWNS: usize = 4;
/// Satellites beyond the unknowns needed for the outlier test, so that one redundant
/// measurement remains after excluding one.
const OUTLIER_TEST_REDUNDANCY: usize = 2;

/// Measurement standard deviations as a function of elevation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SigmaModel {
    /// Pseudo-range σ at the zenith (m); σ(el) = this / sin(el).
    pub pseudorange_zenith_m: f64,
    /// Pseudo-range-rate σ at the zenith (m/s); σ(el) = this / sin(el).
    pub pseudorange_rate_zenith_mps: f64,
    /// Elevation floor of the 1/sin(el) scaling (rad), so σ stays finite.
    pub min_elevation_rad: f64,
    /// Use the receiver-reported σ of an observation when it is present and positive.
    pub prefer_reported: bool,
}

impl Default for SigmaModel {
    /// 3 m and 0.1 m/s at the zenith (typical single-frequency code and Doppler), floor
    /// 5°, reported σ ignored.
    fn default() -> Self {
        Self {
            pseudorange_zenith_m: 3.0,
            pseudorange_rate_zenith_mps: 0.1,
            min_elevation_rad: 5f64.to_radians(),
            prefer_reported: false,
        }
    }
}

impl SigmaModel {
    /// Pseudo-range σ (m) of `obs` at `elevation_rad` (None: elevation unknown, zenith σ).
    pub fn pseudorange_sigma_m(&self, obs: &SatObservation, elevation_rad: Option<f64>) -> f64 {
        match obs.pseudorange_sigma_m {
            Some(s) if self.prefer_reported && s.is_finite() && s > 0.0 => s,
            _ => self.scaled(self.pseudorange_zenith_m, elevation_rad),
        }
    }

    /// Pseudo-range-rate σ (m/s) of `obs` at `elevation_rad`.
    pub fn pseudorange_rate_sigma_mps(
        &self,
        obs: &SatObservation,
        elevation_rad: Option<f64>,
    ) -> f64 {
        match obs.pseudorange_rate_sigma_mps {
            Some(s) if self.prefer_reported && s.is_finite() && s > 0.0 => s,
            _ => self.scaled(self.pseudorange_rate_zenith_mps, elevation_rad),
        }
    }

    /// The zenith σ `zenith` of any observable at `elevation_rad` (None: zenith σ).
    pub fn scaled(&self, zenith: f64, elevation_rad: Option<f64>) -> f64 {
        match elevation_rad {
            Some(el) => zenith / el.max(self.min_elevation_rad).sin(),
            None => zenith,
        }
    }
}

/// Settings of the single-point solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SppConfig {
    /// Satellites below this elevation are not used (rad).
    pub elevation_mask_rad: f64,
    /// Measurement σ model.
    pub sigma: SigmaModel,
    /// Starting position (ECEF, m); None starts from the earth's centre.
    pub initial_position_ecef_m: Option<Vector3<f64>>,
    /// Gauss-Newton iterations allowed per solution (after each outlier exclusion too).
    pub max_iterations: usize,
    /// Convergence tolerance on the Gauss-Newton step norm (m).
    pub convergence_m: f64,
    /// Threshold on the standardized residual |w| for excluding the worst satellite;
    /// None disables the outlier test.
    pub outlier_threshold: Option<f64>,
    /// Tropospheric delay model for satellites whose observation carries no delay.
    pub troposphere: TroposphereModel,
    /// Estimate one receiver clock per constellation instead of one for all (see the
    /// module notes).
    pub clock_per_constellation: bool,
}

impl Default for SppConfig {
    /// Mask 10°, default σ model, start at the earth's centre, 20 iterations,
    /// tolerance 0.1 mm, outlier threshold |w| > 4, Saastamoinen troposphere with the
    /// Black & Eisner mapping, one clock for all satellites.
    fn default() -> Self {
        Self {
            elevation_mask_rad: 10f64.to_radians(),
            sigma: SigmaModel::default(),
            initial_position_ecef_m: None,
            max_iterations: 20,
            convergence_m: 1e-4,
            outlier_threshold: Some(4.0),
            troposphere: TroposphereModel::default(),
            clock_per_constellation: false,
        }
    }
}

/// Errors of the single-point solution.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SppError {
    /// A configuration value is out of its domain.
    #[error("invalid SPP configuration: {what}")]
    InvalidConfig { what: &'static str },
    /// The epoch's GPS time of week is not finite.
    #[error("non-finite GPS time of week in the epoch at t = {t_s} s")]
    NonFiniteEpochTime { t_s: f64 },
    /// Too few usable measurements for the unknowns.
    #[error("{usable} usable satellites, {required} required")]
    NotEnoughSatellites { usable: usize, required: usize },
    /// The normal matrix is not positive definite (degenerate geometry).
    #[error("singular geometry with {usable} satellites")]
    SingularGeometry { usable: usize },
    /// The iterate became NaN or infinite.
    #[error("non-finite solution at iteration {iteration}")]
    NonFinite { iteration: usize },
    /// The Gauss-Newton iteration did not settle.
    #[error("no convergence after {iterations} iterations (last step {last_step_m} m)")]
    NotConverged { iterations: usize, last_step_m: f64 },
}

/// Why a satellite of the epoch was left out.
#[derive(Debug, Clone, PartialEq)]
pub enum Exclusion {
    /// Its data or geometry was refused by the measurement model.
    Invalid(GnssModelError),
    /// Below the elevation mask at the solution.
    BelowMask { elevation_rad: f64 },
    /// Rejected by the outlier test with this standardized residual.
    Outlier { standardized_residual: f64 },
}

/// A satellite left out of the solution, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct ExcludedSat {
    pub sat: SatId,
    pub reason: Exclusion,
}

/// Post-fit pseudo-range residual of a satellite used in the solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SppResidual {
    pub sat: SatId,
    /// Observed minus predicted pseudo-range at the solution (m).
    pub residual_m: f64,
    /// σ used for the weight (m).
    pub sigma_m: f64,
    /// Standardized residual w = v / σ_v (see the module notes); 0 when σ_v vanishes.
    pub standardized: f64,
    /// Elevation at the solution (rad); None if undefined (solution at the earth's centre).
    pub elevation_rad: Option<f64>,
}

/// Dilutions of precision of the used geometry (unweighted).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dops {
    pub gdop: f64,
    pub pdop: f64,
    pub hdop: f64,
    pub vdop: f64,
    pub tdop: f64,
}

/// Velocity and clock-drift solution.
#[derive(Debug, Clone, PartialEq)]
pub struct SppVelocity {
    /// Receiver velocity in ECEF (m/s).
    pub vel_ecef_mps: Vector3<f64>,
    /// Receiver velocity in the local ENU frame at the solution (m/s).
    pub vel_enu_mps: Vector3<f64>,
    /// Receiver clock drift c·δṫ_u (m/s).
    pub clock_drift_mps: f64,
    /// Covariance of (v_x, v_y, v_z, drift) in ECEF ((m/s)²).
    pub covariance: Matrix4<f64>,
    /// Post-fit rate residuals (m/s).
    pub residuals: Vec<(SatId, f64)>,
    /// Number of rates used.
    pub num_used: usize,
    /// Rates excluded by the outlier test, with their standardized residual.
    pub outliers: Vec<(SatId, f64)>,
}

/// Single-point solution of one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct SppSolution {
    /// Receiver position (ECEF, m).
    pub pos_ecef_m: Vector3<f64>,
    /// Receiver position (geodetic).
    pub pos_llh: Llh,
    /// Receiver clock bias c·δt_u (m); with a clock per constellation, the first
    /// constellation's (in [`Constellation`] order).
    pub clock_bias_m: f64,
    /// The clock bias (m) of each clock solved for: one entry per constellation used
    /// with [`SppConfig::clock_per_constellation`], else one entry, for the first
    /// constellation used, holding the common clock.
    pub clock_biases_m: Vec<(Constellation, f64)>,
    /// Covariance of (x, y, z, clock bias) (m²).
    pub covariance: Matrix4<f64>,
    /// Residuals of the satellites used.
    pub residuals: Vec<SppResidual>,
    /// Satellites left out.
    pub excluded: Vec<ExcludedSat>,
    /// Number of satellites used.
    pub num_used: usize,
    /// Dilutions of precision.
    pub dop: Dops,
    /// Gauss-Newton iterations performed in total.
    pub iterations: usize,
    /// Velocity and drift, or why they could not be solved (e.g. fewer than 4 rates).
    pub velocity: Result<SppVelocity, SppError>,
}

/// The receiver clocks being solved for: one for all satellites, or one per
/// constellation of the epoch (in [`Constellation`] order).
#[derive(Debug, Clone, PartialEq)]
struct Clocks {
    constellations: Vec<Constellation>,
    per_constellation: bool,
    values_m: Vec<f64>,
}

impl Clocks {
    fn new(epoch: &GnssEpoch, per_constellation: bool) -> Self {
        let mut constellations: Vec<Constellation> = epoch
            .satellites
            .iter()
            .map(|s| s.sat.constellation)
            .collect();
        constellations.sort();
        constellations.dedup();
        if !per_constellation {
            constellations.truncate(1);
        }
        let values_m = vec![0.0; constellations.len().max(1)];
        Self {
            constellations,
            per_constellation,
            values_m,
        }
    }

    /// The clock of a constellation (index into `values_m`).
    fn group(&self, c: Constellation) -> usize {
        if self.per_constellation {
            self.constellations
                .iter()
                .position(|&k| k == c)
                .unwrap_or(0)
        } else {
            0
        }
    }

    fn value_m(&self, c: Constellation) -> f64 {
        self.values_m.get(self.group(c)).copied().unwrap_or(0.0)
    }
}

/// One usable measurement row at the current iterate.
struct Row {
    /// Index into the epoch's satellites.
    index: usize,
    /// Partials of the pseudo-range w.r.t. (x, y, z) and the row's clock (+1).
    h: Vector4<f64>,
    /// The row's clock (index into [`Clocks::values_m`]).
    group: usize,
    residual: f64,
    sigma: f64,
    elevation_rad: Option<f64>,
    /// Elevation used for the σ model (None away from the surface).
    weighting_elevation_rad: Option<f64>,
    /// Full prediction when the iterate has geodetic coordinates.
    prediction: Option<SatPrediction>,
}

/// Rows and exclusions at one iterate.
struct Evaluation {
    rows: Vec<Row>,
    excluded: Vec<ExcludedSat>,
}

impl Evaluation {
    fn used(&self) -> Vec<usize> {
        self.rows.iter().map(|r| r.index).collect()
    }
}

/// Weighted least-squares solution of (x, y, z) and the clocks that have rows.
struct LsqSolution {
    /// Position step and one clock step per column of `groups`.
    dx: DVector<f64>,
    /// (HᵀWH)⁻¹ in the same order.
    covariance: DMatrix<f64>,
    /// The clock (index into [`Clocks::values_m`]) of each clock column, ascending.
    groups: Vec<usize>,
}

impl LsqSolution {
    /// The design row of `row` in this solution's unknowns.
    fn design_row(&self, row: &Row) -> DVector<f64> {
        let mut h = DVector::zeros(3 + self.groups.len());
        h.rows_mut(0, 3).copy_from(&row.h.fixed_rows::<3>(0));
        if let Some(col) = self.groups.iter().position(|&g| g == row.group) {
            h[3 + col] = row.h[3];
        }
        h
    }

    /// Covariance of (x, y, z, first clock).
    fn covariance4(&self) -> Matrix4<f64> {
        Matrix4::from_fn(|i, j| self.covariance[(i, j)])
    }
}

/// Single-point position, clock bias and (when rates are present) velocity and drift
/// from `epoch`. See the module notes for the algorithm and its choices.
pub fn solve_spp(epoch: &GnssEpoch, config: &SppConfig) -> Result<SppSolution, SppError> {
    validate(config)?;
    if !epoch.gps_time_of_week_s.is_finite() {
        return Err(SppError::NonFiniteEpochTime { t_s: epoch.t_s });
    }
    let mut pos = config
        .initial_position_ecef_m
        .unwrap_or_else(Vector3::zeros);
    let mut clocks = Clocks::new(epoch, config.clock_per_constellation);
    let mut outliers: Vec<(usize, f64)> = Vec::new();
    let mut iterations = 0;

    loop {
        let eval = iterate(
            epoch,
            config,
            &outliers,
            &mut pos,
            &mut clocks,
            &mut iterations,
        )?;
        let lsq = weighted_least_squares(&eval.rows)?;
        let standardized = standardized_residuals(&eval.rows, &lsq);
        if let Some(threshold) = config.outlier_threshold {
            if eval.rows.len() >= lsq.dx.len() + OUTLIER_TEST_REDUNDANCY {
                let worst = eval
                    .rows
                    .iter()
                    .zip(&standardized)
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
                if let Some((row, &w)) = worst {
                    if w.abs() > threshold {
                        outliers.push((row.index, w));
                        continue;
                    }
                }
            }
        }
        let converged = Converged {
            eval,
            lsq,
            standardized,
            pos,
            clocks,
            iterations,
        };
        return finish(epoch, config, converged, &outliers);
    }
}

/// The converged state of one Gauss-Newton run.
struct Converged {
    eval: Evaluation,
    lsq: LsqSolution,
    standardized: Vec<f64>,
    pos: Vector3<f64>,
    clocks: Clocks,
    iterations: usize,
}

/// Gauss-Newton iterations to convergence with the given outliers left out; returns the
/// evaluation at the converged point.
fn iterate(
    epoch: &GnssEpoch,
    config: &SppConfig,
    outliers: &[(usize, f64)],
    pos: &mut Vector3<f64>,
    clocks: &mut Clocks,
    iterations: &mut usize,
) -> Result<Evaluation, SppError> {
    let mut last_step_m = f64::INFINITY;
    let mut previous_set: Option<Vec<usize>> = None;
    for _ in 0..config.max_iterations {
        let eval = evaluate(epoch, config, outliers, pos, clocks);
        let used = eval.used();
        if last_step_m < config.convergence_m && previous_set.as_ref() == Some(&used) {
            return Ok(eval);
        }
        let lsq = weighted_least_squares(&eval.rows)?;
        *iterations += 1;
        *pos += lsq.dx.fixed_rows::<3>(0);
        for (col, &g) in lsq.groups.iter().enumerate() {
            if let Some(v) = clocks.values_m.get_mut(g) {
                *v += lsq.dx[3 + col];
            }
        }
        if !(pos.iter().all(|v| v.is_finite()) && clocks.values_m.iter().all(|v| v.is_finite())) {
            return Err(SppError::NonFinite {
                iteration: *iterations,
            });
        }
        last_step_m = lsq.dx.norm();
        previous_set = Some(used);
    }
    Err(SppError::NotConverged {
        iterations: *iterations,
        last_step_m,
    })
}

/// Measurement rows at (pos, clocks); satellites the model refuses or that are below the
/// mask (near the surface only) are listed as excluded.
fn evaluate(
    epoch: &GnssEpoch,
    config: &SppConfig,
    outliers: &[(usize, f64)],
    pos: &Vector3<f64>,
    clocks: &Clocks,
) -> Evaluation {
    let llh = ecef_to_llh(pos);
    let near_surface = llh.is_some_and(|p| p.height_m.abs() <= NEAR_SURFACE_HEIGHT_M);
    let zero = Vector3::zeros();
    let models = DelayModels {
        klobuchar: epoch.klobuchar.as_ref(),
        gps_tow_s: epoch.gps_time_of_week_s,
        troposphere: config.troposphere,
    };
    let mut rows = Vec::new();
    let mut excluded = Vec::new();
    for (index, obs) in epoch.satellites.iter().enumerate() {
        if outliers.iter().any(|&(i, _)| i == index) {
            continue;
        }
        let sat = obs.sat;
        let clock_bias_m = clocks.value_m(sat.constellation);
        // A satellite kept only for its carrier phase has no range to solve with.
        let Some(pseudorange_m) = obs.pseudorange_m else {
            continue;
        };
        if !pseudorange_m.is_finite() {
            let e = GnssModelError::NonFinite {
                sat,
                what: "pseudo-range",
            };
            excluded.push(ExcludedSat {
                sat,
                reason: Exclusion::Invalid(e),
            });
            continue;
        }
        // Predicted pseudo-range, line of sight, elevation (if defined) and the prediction.
        let modelled = if llh.is_some() {
            predict_with(obs, pos, &zero, clock_bias_m, 0.0, &models).map(|p| {
                let predicted = if near_surface {
                    p.pseudorange_m
                } else {
                    p.pseudorange_m - p.iono_m - p.tropo_m
                };
                (predicted, p.los_ecef, Some(p.elevation_rad), Some(p))
            })
        } else {
            line_of_sight(sat, &obs.sat_pos_ecef_m, &obs.sat_vel_ecef_mps, pos, &zero).and_then(
                |g| {
                    let predicted =
                        g.range_m + clock_bias_m - SPEED_OF_LIGHT_M_S * obs.sat_clock_bias_s;
                    if predicted.is_finite() {
                        Ok((predicted, g.los_ecef, None, None))
                    } else {
                        Err(GnssModelError::NonFinite {
                            sat,
                            what: "satellite clock bias",
                        })
                    }
                },
            )
        };
        let (predicted, los, elevation_rad, prediction) = match modelled {
            Ok(m) => m,
            Err(e) => {
                excluded.push(ExcludedSat {
                    sat,
                    reason: Exclusion::Invalid(e),
                });
                continue;
            }
        };
        let weighting_elevation = if near_surface { elevation_rad } else { None };
        if let Some(el) = weighting_elevation {
            if el < config.elevation_mask_rad {
                excluded.push(ExcludedSat {
                    sat,
                    reason: Exclusion::BelowMask { elevation_rad: el },
                });
                continue;
            }
        }
        rows.push(Row {
            index,
            h: Vector4::new(-los[0], -los[1], -los[2], 1.0),
            group: clocks.group(sat.constellation),
            residual: pseudorange_m - predicted,
            sigma: config.sigma.pseudorange_sigma_m(obs, weighting_elevation),
            elevation_rad,
            weighting_elevation_rad: weighting_elevation,
            prediction,
        });
    }
    Evaluation { rows, excluded }
}

/// Weighted least squares dx = (HᵀWH)⁻¹ HᵀW v with its covariance (HᵀWH)⁻¹, over the
/// position and the clocks that have rows.
fn weighted_least_squares(rows: &[Row]) -> Result<LsqSolution, SppError> {
    let mut groups: Vec<usize> = rows.iter().map(|r| r.group).collect();
    groups.sort_unstable();
    groups.dedup();
    let mut lsq = LsqSolution {
        dx: DVector::zeros(0),
        covariance: DMatrix::zeros(0, 0),
        groups,
    };
    let design: Vec<(DVector<f64>, f64, f64)> = rows
        .iter()
        .map(|r| (lsq.design_row(r), r.residual, r.sigma))
        .collect();
    let (dx, covariance) = solve_normal_equations(&design, 3 + lsq.groups.len())?;
    lsq.dx = dx;
    lsq.covariance = covariance;
    Ok(lsq)
}

/// Solves the normal equations of rows (h, v, σ) with `unknowns` unknowns; at least that
/// many rows and a positive-definite normal matrix are required.
fn solve_normal_equations(
    rows: &[(DVector<f64>, f64, f64)],
    unknowns: usize,
) -> Result<(DVector<f64>, DMatrix<f64>), SppError> {
    let usable = rows.len();
    if usable < unknowns.max(UNKNOWNS) {
        return Err(SppError::NotEnoughSatellites {
            usable,
            required: unknowns.max(UNKNOWNS),
        });
    }
    let mut normal = DMatrix::zeros(unknowns, unknowns);
    let mut rhs = DVector::zeros(unknowns);
    for (h, v, sigma) in rows {
        let w = 1.0 / (sigma * sigma);
        normal += h * h.transpose() * w;
        rhs += h * (v * w);
    }
    let chol = normal
        .cholesky()
        .ok_or(SppError::SingularGeometry { usable })?;
    let dx = chol.solve(&rhs);
    let covariance = chol.inverse();
    if dx.iter().chain(covariance.iter()).all(|v| v.is_finite()) {
        Ok((dx, covariance))
    } else {
        Err(SppError::SingularGeometry { usable })
    }
}

/// Standardized residuals w_i = v_i / sqrt(σ_i² − h_i Q h_iᵀ) (0 where that vanishes).
fn standardized_residuals(rows: &[Row], lsq: &LsqSolution) -> Vec<f64> {
    rows.iter()
        .map(|r| {
            let h = lsq.design_row(r);
            let var = r.sigma * r.sigma - (h.transpose() * &lsq.covariance * &h)[0];
            if var > 1e-12 * r.sigma * r.sigma {
                r.residual / var.sqrt()
            } else {
                0.0
            }
        })
        .collect()
}

/// Dilutions of precision from the unweighted geometry at `llh` (TDOP: the first clock).
fn dops(rows: &[Row], lsq: &LsqSolution, llh: &Llh) -> Result<Dops, SppError> {
    let unit: Vec<(DVector<f64>, f64, f64)> =
        rows.iter().map(|r| (lsq.design_row(r), 0.0, 1.0)).collect();
    let (_, q) = solve_normal_equations(&unit, lsq.dx.len())?;
    let q_pos: Matrix3<f64> = Matrix3::from_fn(|i, j| q[(i, j)]);
    let c = rot_ecef_to_enu(llh);
    let q_enu = c * q_pos * c.transpose();
    Ok(Dops {
        gdop: q.trace().sqrt(),
        pdop: q_pos.trace().sqrt(),
        hdop: (q_enu[(0, 0)] + q_enu[(1, 1)]).sqrt(),
        vdop: q_enu[(2, 2)].sqrt(),
        tdop: q[(3, 3)].sqrt(),
    })
}

/// Velocity and clock drift from the rates of the used satellites at the solution.
///
/// Choice: one clock drift for all constellations even with a clock per constellation:
/// the inter-system biases are constant over a session, so their rates vanish.
fn solve_velocity(
    epoch: &GnssEpoch,
    config: &SppConfig,
    rows: &[Row],
    llh: &Llh,
) -> Result<SppVelocity, SppError> {
    let mut rate_rows = Vec::new();
    let mut sats = Vec::new();
    for row in rows {
        let (Some(obs), Some(p)) = (epoch.satellites.get(row.index), row.prediction.as_ref())
        else {
            continue;
        };
        let Some(rate) = obs.pseudorange_rate_mps.filter(|r| r.is_finite()) else {
            continue;
        };
        let d = p.d_range_rate_d_rx_vel;
        // The prediction was made at zero receiver velocity and drift.
        let residual = rate - p.pseudorange_rate_mps;
        let sigma = config
            .sigma
            .pseudorange_rate_sigma_mps(obs, row.weighting_elevation_rad);
        rate_rows.push((
            DVector::from_vec(vec![d[0], d[1], d[2], 1.0]),
            residual,
            sigma,
        ));
        sats.push(obs.sat);
    }
    let mut outliers = Vec::new();
    let (x, covariance) = loop {
        let (x, covariance) = solve_normal_equations(&rate_rows, UNKNOWNS)?;
        let worst = config.outlier_threshold.and_then(|threshold| {
            if rate_rows.len() < UNKNOWNS + OUTLIER_TEST_REDUNDANCY {
                return None;
            }
            rate_rows
                .iter()
                .map(|(h, v, sigma)| {
                    let var = sigma * sigma - (h.transpose() * &covariance * h)[0];
                    if var > 1e-12 * sigma * sigma {
                        (v - h.dot(&x)) / var.sqrt()
                    } else {
                        0.0
                    }
                })
                .enumerate()
                .filter(|(_, w)| w.abs() > threshold)
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        });
        match worst {
            Some((k, w)) => {
                rate_rows.remove(k);
                outliers.push((sats.remove(k), w));
            }
            None => break (x, covariance),
        }
    };
    let vel_ecef_mps = Vector3::new(x[0], x[1], x[2]);
    let residuals = sats
        .iter()
        .zip(&rate_rows)
        .map(|(&sat, (h, v, _))| (sat, v - h.dot(&x)))
        .collect();
    Ok(SppVelocity {
        vel_ecef_mps,
        vel_enu_mps: rot_ecef_to_enu(llh) * vel_ecef_mps,
        clock_drift_mps: x[3],
        covariance: Matrix4::from_fn(|i, j| covariance[(i, j)]),
        residuals,
        num_used: rate_rows.len(),
        outliers,
    })
}

/// Assembles the solution from the converged state.
fn finish(
    epoch: &GnssEpoch,
    config: &SppConfig,
    converged: Converged,
    outliers: &[(usize, f64)],
) -> Result<SppSolution, SppError> {
    let Converged {
        eval,
        lsq,
        standardized,
        pos,
        clocks,
        iterations,
    } = converged;
    let pos_llh = ecef_to_llh(&pos).ok_or(SppError::NonFinite {
        iteration: iterations,
    })?;
    let dop = dops(&eval.rows, &lsq, &pos_llh)?;
    let residuals = eval
        .rows
        .iter()
        .zip(&standardized)
        .filter_map(|(r, &w)| {
            epoch.satellites.get(r.index).map(|obs| SppResidual {
                sat: obs.sat,
                residual_m: r.residual,
                sigma_m: r.sigma,
                standardized: w,
                elevation_rad: r.elevation_rad,
            })
        })
        .collect();
    let mut excluded = eval.excluded;
    for &(index, w) in outliers {
        if let Some(obs) = epoch.satellites.get(index) {
            excluded.push(ExcludedSat {
                sat: obs.sat,
                reason: Exclusion::Outlier {
                    standardized_residual: w,
                },
            });
        }
    }
    // The clocks solved for, named by the first constellation each serves.
    let clock_biases_m: Vec<(Constellation, f64)> = lsq
        .groups
        .iter()
        .filter_map(|&g| {
            let row = eval.rows.iter().find(|r| r.group == g)?;
            let c = epoch.satellites.get(row.index)?.sat.constellation;
            Some((c, *clocks.values_m.get(g)?))
        })
        .collect();
    let clock_bias_m = clock_biases_m.first().map_or_else(
        || clocks.values_m.first().copied().unwrap_or(0.0),
        |&(_, v)| v,
    );
    let velocity = solve_velocity(epoch, config, &eval.rows, &pos_llh);
    Ok(SppSolution {
        pos_ecef_m: pos,
        pos_llh,
        clock_bias_m,
        clock_biases_m,
        covariance: lsq.covariance4(),
        residuals,
        excluded,
        num_used: eval.rows.len(),
        dop,
        iterations,
        velocity,
    })
}

fn validate(config: &SppConfig) -> Result<(), SppError> {
    let s = &config.sigma;
    let checks = [
        (
            config.elevation_mask_rad.is_finite(),
            "elevation mask must be finite",
        ),
        (
            s.pseudorange_zenith_m.is_finite() && s.pseudorange_zenith_m > 0.0,
            "pseudo-range zenith sigma must be positive",
        ),
        (
            s.pseudorange_rate_zenith_mps.is_finite() && s.pseudorange_rate_zenith_mps > 0.0,
            "pseudo-range-rate zenith sigma must be positive",
        ),
        (
            s.min_elevation_rad.is_finite() && s.min_elevation_rad > 0.0,
            "sigma elevation floor must be positive",
        ),
        (config.max_iterations >= 1, "at least one iteration"),
        (
            config.convergence_m.is_finite() && config.convergence_m > 0.0,
            "convergence tolerance must be positive",
        ),
        (
            config
                .outlier_threshold
                .is_none_or(|t| t.is_finite() && t > 0.0),
            "outlier threshold must be positive",
        ),
        (
            config
                .initial_position_ecef_m
                .is_none_or(|p| p.iter().all(|v| v.is_finite())),
            "initial position must be finite",
        ),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some(&(_, what)) => Err(SppError::InvalidConfig { what }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::Constellation;

    fn observation(sigma_m: Option<f64>) -> SatObservation {
        SatObservation {
            sat: SatId {
                constellation: Constellation::Gps,
                prn: 7,
            },
            pseudorange_m: Some(2.2e7),
            pseudorange_rate_mps: None,
            pseudorange_sigma_m: sigma_m,
            pseudorange_rate_sigma_mps: None,
            cn0_dbhz: None,
            sat_pos_ecef_m: Vector3::new(2.6e7, 0.0, 0.0),
            sat_vel_ecef_mps: Vector3::zeros(),
            sat_clock_bias_s: 0.0,
            sat_clock_drift_s_s: 0.0,
            iono_delay_m: None,
            tropo_delay_m: None,
            carrier_phase: None,
        }
    }

    #[test]
    fn sigma_scales_with_one_over_sine_of_elevation_with_a_floor() {
        let model = SigmaModel::default();
        let obs = observation(Some(0.7));
        let s30 = model.pseudorange_sigma_m(&obs, Some(30f64.to_radians()));
        assert!((s30 - 6.0).abs() < 1e-12, "{s30}");
        let s90 = model.pseudorange_sigma_m(&obs, Some(std::f64::consts::FRAC_PI_2));
        assert!((s90 - 3.0).abs() < 1e-12);
        // Below the 5° floor σ stops growing.
        let s1 = model.pseudorange_sigma_m(&obs, Some(1f64.to_radians()));
        let s5 = model.pseudorange_sigma_m(&obs, Some(5f64.to_radians()));
        assert_eq!(s1, s5);
        assert_eq!(model.pseudorange_sigma_m(&obs, None), 3.0);
        let rate = model.pseudorange_rate_sigma_mps(&obs, Some(30f64.to_radians()));
        assert!((rate - 0.2).abs() < 1e-12);
        // Reported σ when preferred and valid.
        let reported = SigmaModel {
            prefer_reported: true,
            ..model
        };
        assert_eq!(reported.pseudorange_sigma_m(&obs, Some(0.5)), 0.7);
        let bad = observation(Some(-1.0));
        assert_eq!(reported.pseudorange_sigma_m(&bad, None), 3.0);
    }

    #[test]
    fn invalid_configuration_and_epoch_time_are_typed_errors() {
        let epoch = GnssEpoch {
            t_s: 1.0,
            gps_time_of_week_s: 0.0,
            satellites: vec![observation(None)],
            klobuchar: None,
        };
        let mut config = SppConfig::default();
        config.sigma.pseudorange_zenith_m = 0.0;
        assert!(matches!(
            solve_spp(&epoch, &config),
            Err(SppError::InvalidConfig { .. })
        ));
        let config = SppConfig {
            initial_position_ecef_m: Some(Vector3::new(f64::NAN, 0.0, 0.0)),
            ..SppConfig::default()
        };
        assert!(matches!(
            solve_spp(&epoch, &config),
            Err(SppError::InvalidConfig { .. })
        ));
        let bad_time = GnssEpoch {
            gps_time_of_week_s: f64::NAN,
            ..epoch.clone()
        };
        assert_eq!(
            solve_spp(&bad_time, &SppConfig::default()),
            Err(SppError::NonFiniteEpochTime { t_s: 1.0 })
        );
        assert_eq!(
            solve_spp(&epoch, &SppConfig::default()),
            Err(SppError::NotEnoughSatellites {
                usable: 1,
                required: 4
            })
        );
    }
}
