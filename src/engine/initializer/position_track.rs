//! The antenna's position before the filter starts (tightly coupled): every single-point
//! solution since the start-up began, not the last one alone.
//!
//! A small Kalman filter on the ECEF position. Each epoch's single-point position is a
//! measurement of it, with the least squares' covariance, scaled up where the root of
//! its components' mean variance is below `init.position_sigma_m`. Between epochs it
//! stays where it is when the platform is at rest (the caller's verdict: the IMU's
//! standstill test and a slow GNSS speed), and otherwise moves by the mean of the two
//! epochs' Doppler velocities times the interval, with their covariances and
//! [`UNMODELLED_ACCELERATION_M_S2`]. The usual start — levelled at rest, the heading once
//! the platform moves — then begins from the combined solutions of the whole rest instead
//! of one epoch's.
//!
//! Choice: each epoch is weighed as independent, as the filter weighs its ranges after the
//! start: the track holds what the filter would have had it run through those epochs.
//! The range errors are correlated over seconds (walk_0827: 0.83 between 0.25 s epochs),
//! so this σ is optimistic by the same factor as the filter's own after the start; raising
//! it for the track alone would let every later epoch outweigh an earlier one that carries
//! as much. Its memory is [`MEMORY_S`] (a fading memory): a long rest does not shrink
//! the σ without bound while the slow part of the range errors does not average out.
//! Measured on walk_0827 (docs/results.md): the 60 epochs before the start take
//! the EKF with TDCP from 0.556 to 0.451 m (fixed epochs, offset removed).
//!
//! The track starts again from the epoch's solution when it cannot carry its position
//! over: moving without a Doppler velocity at both epochs, an interval outside (0,
//! [`MAX_INTERVAL_S`]], or a solution beyond the chi-square gate of [`GATE_CONFIDENCE`] (a
//! platform moved without its Doppler, a solution pulled by a bad range) or not finite.

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
/// The track's memory (s): before each update its covariance grows by the factor
/// 1 + Δt / [`MEMORY_S`], so that at rest it settles at the variance of the last
/// [`MEMORY_S`] of epochs combined (one epoch's variance over T/Δt + 1). Choice: a minute,
/// about how long the filter itself averages at rest: on the simulator at 1 Hz, after a
/// minute at rest, the filter's σ is 0.7 / 1.1 / 1.9 m E/N/U (tests/engine_static.rs),
/// 1.33 m as the root of the mean variance, the track's 1.15 m; and longer than
/// walk_0827's 15 s before its start.
const MEMORY_S: f64 = 60.0;
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
        let remembered = self.cov_ecef_m2 * (1.0 + dt / MEMORY_S);
        let (predicted, p) = match (self.velocity, now) {
            _ if at_rest => (self.pos_ecef_m, remembered),
            (Some((v0, c0)), Some((v1, c1))) => {
                let unmodelled_m = UNMODELLED_ACCELERATION_M_S2 * dt * dt / 2.0;
                (
                    self.pos_ecef_m + 0.5 * (v0 + v1) * dt,
                    remembered
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
        let m2 = (innovation.transpose() * s_inv * innovation)[(0, 0)];
        if m2.is_nan() || m2 > gate {
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
/// `min_sigma_m`² (the shape, which the geometry gives, is kept); `min_sigma_m` in every
/// component when it is not a covariance (a non-finite value, a non-positive trace).
fn measurement_covariance(sol: &SppSolution, min_sigma_m: f64) -> Matrix3<f64> {
    let cov: Matrix3<f64> = sol.covariance.fixed_view::<3, 3>(0, 0).into();
    let mean_var = cov.trace() / 3.0;
    let floor = min_sigma_m.powi(2);
    if !(cov.iter().all(|v| v.is_finite()) && mean_var > 0.0) {
        Matrix3::identity() * floor
    } else if mean_var < floor {
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

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix4, Vector3, Vector4};

    use super::*;
    use crate::gnss::spp::{Dops, SppError, SppVelocity};

    const MIN_SIGMA_M: f64 = 0.5;
    /// A point in Colorado (ECEF, m), where the test positions sit.
    const ORIGIN: [f64; 3] = [-1_276_960.0, -4_717_230.0, 4_087_230.0];

    /// A solution at `offset_m` from [`ORIGIN`] with `var_m2` in each component, and a
    /// Doppler velocity when given.
    fn solution(offset_m: [f64; 3], var_m2: f64, velocity: Option<Vector3<f64>>) -> SppSolution {
        let pos_ecef_m = Vector3::from(ORIGIN) + Vector3::from(offset_m);
        SppSolution {
            pos_ecef_m,
            pos_llh: earth::ecef_to_llh(&pos_ecef_m).unwrap(),
            clock_bias_m: 0.0,
            clock_biases_m: Vec::new(),
            covariance: Matrix4::from_diagonal(&Vector4::new(var_m2, var_m2, var_m2, 100.0)),
            residuals: Vec::new(),
            excluded: Vec::new(),
            num_used: 8,
            dop: Dops {
                gdop: 2.0,
                pdop: 1.8,
                hdop: 1.0,
                vdop: 1.5,
                tdop: 0.8,
            },
            iterations: 3,
            velocity: velocity.map_or(Err(SppError::SingularGeometry { usable: 3 }), |v| {
                Ok(SppVelocity {
                    vel_ecef_mps: v,
                    vel_enu_mps: v,
                    clock_drift_mps: 0.0,
                    covariance: Matrix4::identity() * 0.01,
                    residuals: Vec::new(),
                    num_used: 8,
                    outliers: Vec::new(),
                })
            }),
        }
    }

    fn offset_m(track: &PositionTrack) -> Vector3<f64> {
        track.pos_ecef_m() - Vector3::from(ORIGIN)
    }

    #[test]
    fn a_rest_is_averaged_with_a_fading_memory() {
        // ±1 m alternately along x, variance 4 m² each, 1 s apart, held still.
        let mut track = PositionTrack::new(0.0, &solution([1.0, 0.0, 0.0], 4.0, None), MIN_SIGMA_M);
        for k in 1..40 {
            let x = if k % 2 == 0 { 1.0 } else { -1.0 };
            let sol = solution([x, 0.0, 0.0], 4.0, None);
            track = track.push(k as f64, &sol, MIN_SIGMA_M, true);
        }
        // 40 epochs, faded by the one-minute memory to (1 − λ⁻⁴⁰)/(1 − λ⁻¹) = 29.5 with
        // λ = 1 + 1/60: the mean of ±1 m is within a few centimetres of zero (the newer
        // epochs weigh a little more), the variance 4/29.5.
        assert!(offset_m(&track).norm() < 0.05, "{}", offset_m(&track));
        let var = track.cov_ecef_m2[(0, 0)];
        assert!((var - 4.0 / 29.5).abs() < 0.002, "{var}");
    }

    #[test]
    fn a_solution_beyond_the_gate_restarts_the_track() {
        let mut track = PositionTrack::new(0.0, &solution([0.0; 3], 4.0, None), MIN_SIGMA_M);
        for k in 1..10 {
            track = track.push(k as f64, &solution([0.0; 3], 4.0, None), MIN_SIGMA_M, true);
        }
        track = track.push(
            10.0,
            &solution([30.0, 0.0, 0.0], 4.0, None),
            MIN_SIGMA_M,
            true,
        );
        assert_eq!(offset_m(&track), Vector3::new(30.0, 0.0, 0.0));
        assert_eq!(track.cov_ecef_m2, Matrix3::identity() * 4.0);
    }

    #[test]
    fn moving_it_follows_the_doppler_velocity_and_without_one_starts_again() {
        let v = Vector3::new(2.0, 0.0, 0.0);
        let mut track = PositionTrack::new(0.0, &solution([0.0; 3], 4.0, Some(v)), MIN_SIGMA_M);
        for k in 1..=4 {
            let sol = solution([2.0 * k as f64, 0.0, 0.0], 4.0, Some(v));
            track = track.push(k as f64, &sol, MIN_SIGMA_M, false);
        }
        assert!((offset_m(&track) - Vector3::new(8.0, 0.0, 0.0)).norm() < 1e-9);
        assert!(track.cov_ecef_m2[(0, 0)] < 2.0, "{}", track.cov_ecef_m2);
        let lost = solution([10.5, 0.0, 0.0], 4.0, None);
        track = track.push(5.0, &lost, MIN_SIGMA_M, false);
        assert_eq!(offset_m(&track), Vector3::new(10.5, 0.0, 0.0));
    }

    #[test]
    fn a_covariance_that_is_not_one_never_reaches_the_track() {
        let mut sol = solution([0.0; 3], 4.0, None);
        sol.covariance[(0, 1)] = f64::NAN;
        let track = PositionTrack::new(0.0, &sol, MIN_SIGMA_M);
        assert_eq!(track.cov_ecef_m2, Matrix3::identity() * MIN_SIGMA_M.powi(2));
        let track = track.push(1.0, &sol, MIN_SIGMA_M, true);
        assert!(track.cov_ecef_m2.iter().all(|v| v.is_finite()));
        assert!(track.pos_ecef_m().iter().all(|v| v.is_finite()));
    }

    #[test]
    fn a_small_covariance_is_raised_to_the_least_sigma() {
        let track = PositionTrack::new(0.0, &solution([0.0; 3], 0.01, None), 1.0);
        assert!((track.cov_ecef_m2 - Matrix3::identity()).norm() < 1e-12);
    }
}
