//! The antenna's position before the filter starts (tightly coupled): every single-point
//! solution since the start-up began, not the last one alone.
//!
//! A small Kalman filter on the ECEF position. Each epoch's single-point position is a
//! measurement of it, with the least squares' covariance, scaled up where the root of its
//! components' mean variance is below `init.position_sigma_m`. Between epochs it stays where it is
//! when the platform is at rest (the caller's verdict: the IMU's standstill test and a
//! slow GNSS speed), and otherwise moves by the mean of the two epochs' Doppler
//! velocities times the interval, with their covariances and
//! [`UNMODELLED_ACCELERATION_M_S2`]. The usual start — levelled at rest, the heading once
//! the platform moves — then begins from the combined solutions of the whole rest instead
//! of one epoch's.
//!
//! Choice: each epoch is weighed as independent, as the filter weighs its ranges after the
//! start: the track holds what the filter would have had it run through those epochs.
//! The range errors are correlated over seconds (walk_0827: 0.83 between 0.25 s epochs),
//! so this σ is optimistic by the same factor as the filter's own after the start; raising
//! it for the track alone would let every later epoch outweigh an earlier one that carries
//! as much. Measured on walk_0827 (docs/results.md): the 60 epochs before the start take
//! the EKF with TDCP from 0.556 to 0.444 m (fixed epochs, offset removed).
//!
//! The track starts again from the epoch's solution when it cannot carry its position
//! over: moving without a Doppler velocity at both epochs, an interval outside (0,
//! [`MAX_INTERVAL_S`]], or a solution beyond the chi-square gate of [`GATE_CONFIDENCE`] (a
//! platform moved without its Doppler, a solution pulled by a bad range).

use nalgebra::{Matrix3, Vector3};

use crate::adaptive::mahalanobis::chi_square_quantile;
use crate::earth::{self, Llh};
use crate::gnss::spp::SppSolution;

/// 1-sigma of the change of acceleration over one interval that the mean of two
/// velocities misses (m/s²). Choice: 1 m/s², a car's brisk acceleration or braking
/// started within the interval; moving, it costs (1 × 0.25²/2)² m² per 0.25 s epoch.
const UNMODELLED_ACCELERATION_M_S2: f64 = 1.0;
/// Longest interval the track carries its position over (s). Choice: 2 s, eight epochs at
/// 4 Hz; beyond it an unmodelled acceleration's metres are the track's error.
const MAX_INTERVAL_S: f64 = 2.0;
/// Confidence of the test that a solution agrees with the track. Choice: 0.999, one
/// restart in a thousand honest epochs.
const GATE_CONFIDENCE: f64 = 0.999;

/// The track's state after an epoch.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PositionTrack {
    t_s: f64,
    pos_ecef_m: Vector3<f64>,
    cov_ecef_m2: Matrix3<f64>,
    /// The epoch's Doppler velocity (ECEF) and its covariance.
    velocity: Option<(Vector3<f64>, Matrix3<f64>)>,
}

impl PositionTrack {
    /// A track of one epoch's solution.
    pub fn new(t_s: f64, sol: &SppSolution, min_sigma_m: f64) -> Self {
        Self {
            t_s,
            pos_ecef_m: sol.pos_ecef_m,
            cov_ecef_m2: measurement_covariance(sol, min_sigma_m),
            velocity: doppler_velocity(sol),
        }
    }

    /// The track carried to `t_s` (held still `at_rest`) and updated with that epoch's
    /// solution, or a new track from the solution where it cannot be carried (see the
    /// module documentation). The same epoch again leaves it as it is.
    pub fn push(&self, t_s: f64, sol: &SppSolution, min_sigma_m: f64, at_rest: bool) -> Self {
        if t_s == self.t_s {
            return self.clone();
        }
        let dt = t_s - self.t_s;
        if !(dt > 0.0 && dt <= MAX_INTERVAL_S) {
            return Self::new(t_s, sol, min_sigma_m);
        }
        let now = doppler_velocity(sol);
        let (predicted, p) = match (self.velocity, now) {
            _ if at_rest => (self.pos_ecef_m, self.cov_ecef_m2),
            (Some((v0, c0)), Some((v1, c1))) => {
                let unmodelled_m = UNMODELLED_ACCELERATION_M_S2 * dt * dt / 2.0;
                (
                    self.pos_ecef_m + 0.5 * (v0 + v1) * dt,
                    self.cov_ecef_m2
                        + (c0 + c1) * (0.25 * dt * dt)
                        + Matrix3::identity() * unmodelled_m.powi(2),
                )
            }
            _ => return Self::new(t_s, sol, min_sigma_m),
        };
        let r = measurement_covariance(sol, min_sigma_m);
        let innovation = sol.pos_ecef_m - predicted;
        let Some(s_inv) = (p + r).try_inverse() else {
            return Self::new(t_s, sol, min_sigma_m);
        };
        let gate = chi_square_quantile(GATE_CONFIDENCE, 3).unwrap_or(f64::INFINITY);
        if (innovation.transpose() * s_inv * innovation)[(0, 0)] > gate {
            return Self::new(t_s, sol, min_sigma_m);
        }
        let gain = p * s_inv;
        let cov = (Matrix3::identity() - gain) * p;
        Self {
            t_s,
            pos_ecef_m: predicted + gain * innovation,
            cov_ecef_m2: 0.5 * (cov + cov.transpose()),
            velocity: now,
        }
    }

    pub fn pos_ecef_m(&self) -> Vector3<f64> {
        self.pos_ecef_m
    }

    /// The variances of the east, north and up components at `p` (m²).
    pub fn position_var_enu_m2(&self, p: &Llh) -> Vector3<f64> {
        let r = earth::rot_ecef_to_enu(p);
        (r * self.cov_ecef_m2 * r.transpose()).diagonal()
    }
}

/// The solution's position covariance, scaled up so that its mean variance is at least
/// `min_sigma_m`² (the shape, which the geometry gives, is kept).
fn measurement_covariance(sol: &SppSolution, min_sigma_m: f64) -> Matrix3<f64> {
    let cov: Matrix3<f64> = sol.covariance.fixed_view::<3, 3>(0, 0).into();
    let mean_var = cov.trace() / 3.0;
    let floor = min_sigma_m.powi(2);
    if mean_var > 0.0 && mean_var < floor {
        cov * (floor / mean_var)
    } else {
        cov
    }
}

/// The solution's Doppler velocity (ECEF) and its covariance, when it has one.
fn doppler_velocity(sol: &SppSolution) -> Option<(Vector3<f64>, Matrix3<f64>)> {
    sol.velocity
        .as_ref()
        .ok()
        .map(|v| (v.vel_ecef_mps, v.covariance.fixed_view::<3, 3>(0, 0).into()))
}
