//! Deterministic vehicle trajectories: a spec of segments (stand still, change speed, cruise,
//! turn, climb) turned into the true navigation state and the true, error-free IMU output
//! at any time, consistent with the WGS84 model of [`crate::earth`].
//!
//! Kinematics: the vehicle moves along its body x axis at speed s ≥ 0 with yaw ψ (ENU, REP-103:
//! 0 = east, counter-clockwise positive) and climb angle θ (nose up positive), roll zero:
//! v^n = s (cos θ cos ψ, cos θ sin ψ, sin θ), C_b^n = R_z(ψ) R_y(−θ). Each segment multiplies
//! its plateau acceleration, yaw rate or climb angle by a [`SmoothWindow`], so all three are
//! zero at segment boundaries (the vehicle is level and goes straight between segments) and
//! C² inside.
//!
//! True IMU (REP-145, body FLU):
//! f^b = C_n^b (v̇^n + (2ω_ie^n + ω_en^n) × v^n − g^n),
//! ω_ib^b = ω_nb^b + C_n^b (ω_ie^n + ω_en^n), with ω_nb^b = (ψ̇ sin θ, −θ̇, ψ̇ cos θ).

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::earth::{
    earth_rate_enu_rad_s, gravity_enu_m_s2, meridian_radius_m, transport_rate_enu_rad_s,
    transverse_radius_m, Llh,
};
use crate::ins::{ImuSample, NavState};
use crate::sim::smooth_window::SmoothWindow;

/// Spacing (s) of the stored positions from which any time is reached by a few RK4 steps.
const CHECKPOINT_S: f64 = 0.1;
/// Largest RK4 step (s) of the position integration.
///
/// Math note: RK4's local error is O(h⁵ p⁽⁵⁾); with h = 0.02 s and the jerk-rate of the
/// smoothstep ramps (≲ 50 m/s⁵ for 2 s ramps) it is below 1e-10 m per step.
const RK4_STEP_S: f64 = 0.02;
/// Largest |latitude| (deg) a trajectory may start at or reach. Choice: the ENU mechanization
/// is singular at the poles (tan L); vehicle test sites stay far away.
const MAX_ABS_LAT_DEG: f64 = 85.0;
/// Largest |climb angle| (deg). Choice: vehicle-like and far from θ = ±90°, where yaw is
/// undefined.
const MAX_ABS_CLIMB_DEG: f64 = 45.0;
/// Longest trajectory (s). Choice: one day, so the stored checkpoints (one per 0.1 s) stay
/// around 20 MB whatever the spec says.
const MAX_DURATION_S: f64 = 86_400.0;

/// One piece of a trajectory. YAML form (internally tagged), e.g.
/// `{ kind: turn, duration_s: 15.0, yaw_change_deg: 90.0 }`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Segment {
    /// Standing still; the vehicle must be at rest when it starts.
    Stationary { duration_s: f64 },
    /// Constant speed, straight and level.
    Cruise { duration_s: f64 },
    /// Change speed smoothly to `speed_m_s` (≥ 0) by the end of the segment; 0 is a stop.
    SpeedTo { duration_s: f64, speed_m_s: f64 },
    /// Change yaw by `yaw_change_deg` (positive = left, counter-clockwise seen from above).
    Turn {
        duration_s: f64,
        yaw_change_deg: f64,
    },
    /// Pitch up to `climb_angle_deg` (negative = descent), hold, and level off again. A hill
    /// is a climb followed by a descent.
    Climb {
        duration_s: f64,
        climb_angle_deg: f64,
    },
}

impl Segment {
    /// Length of the segment (s).
    pub fn duration_s(&self) -> f64 {
        match *self {
            Segment::Stationary { duration_s }
            | Segment::Cruise { duration_s }
            | Segment::SpeedTo { duration_s, .. }
            | Segment::Turn { duration_s, .. }
            | Segment::Climb { duration_s, .. } => duration_s,
        }
    }
}

fn default_transition_s() -> f64 {
    2.0
}

/// A whole trajectory: where and how it starts, and its segments in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectorySpec {
    /// Time of the first state (s) on the engine's time axis.
    #[serde(default)]
    pub start_t_s: f64,
    /// Start latitude (deg), within ±85°.
    pub start_lat_deg: f64,
    /// Start longitude (deg).
    pub start_lon_deg: f64,
    /// Start height above the WGS84 ellipsoid (m).
    pub start_height_m: f64,
    /// Start yaw (deg, ENU: 0 = east, 90 = north).
    #[serde(default)]
    pub start_yaw_deg: f64,
    /// Start speed along the body x axis (m/s), ≥ 0.
    #[serde(default)]
    pub start_speed_m_s: f64,
    /// Length of the smooth ramps at each end of a segment (s), at most half the segment.
    #[serde(default = "default_transition_s")]
    pub transition_s: f64,
    /// The segments, in order.
    pub segments: Vec<Segment>,
}

/// Why a trajectory could not be built or evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TrajectoryError {
    /// The spec has no segment.
    #[error("trajectory has no segments")]
    NoSegments,
    /// A start value is out of range or not finite.
    #[error("invalid trajectory start: {reason}")]
    InvalidStart { reason: &'static str },
    /// A segment value is out of range or not finite.
    #[error("invalid segment {index}: {reason}")]
    InvalidSegment { index: usize, reason: &'static str },
    /// A stationary segment begins while the vehicle moves.
    #[error("segment {index} is stationary but the vehicle moves at {speed_m_s} m/s")]
    MovingWhenStationary { index: usize, speed_m_s: f64 },
    /// The trajectory leaves the allowed latitude band (or its integration failed).
    #[error("trajectory reaches latitude {lat_deg}° at t = {t_s} s (limit ±85°)")]
    LatitudeOutOfRange { t_s: f64, lat_deg: f64 },
    /// The segments add up to more than a day.
    #[error("trajectory lasts {duration_s} s, more than the {max_s} s allowed")]
    TooLong { duration_s: f64, max_s: f64 },
    /// A time outside [start, end] was asked for.
    #[error("t = {t_s} s is outside the trajectory [{start_t_s}, {end_t_s}] s")]
    TimeOutOfRange {
        t_s: f64,
        start_t_s: f64,
        end_t_s: f64,
    },
    /// A sampling rate that is not positive and finite.
    #[error("invalid sampling rate {rate_hz} Hz")]
    InvalidRate { rate_hz: f64 },
}

/// The true state and the true (error-free) IMU output at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthSample {
    /// True navigation state.
    pub nav: NavState,
    /// True IMU output (ω_ib^b, f_ib^b) at the same time.
    pub imu: ImuSample,
}

/// One segment prepared for evaluation: its window and plateau values in SI units.
#[derive(Debug, Clone, Copy)]
struct SegmentPlan {
    t_start_s: f64,
    window: SmoothWindow,
    speed0_m_s: f64,
    yaw0_rad: f64,
    accel_m_s2: f64,
    yaw_rate_rad_s: f64,
    climb_rad: f64,
}

/// Speed, yaw and climb angle with their rates at one time.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    speed_m_s: f64,
    accel_m_s2: f64,
    yaw_rad: f64,
    yaw_rate_rad_s: f64,
    climb_rad: f64,
    climb_rate_rad_s: f64,
}

impl Kinematics {
    /// v^n = s (cos θ cos ψ, cos θ sin ψ, sin θ).
    fn velocity_n(&self) -> Vector3<f64> {
        let (sp, cp) = self.yaw_rad.sin_cos();
        let (st, ct) = self.climb_rad.sin_cos();
        self.speed_m_s * Vector3::new(ct * cp, ct * sp, st)
    }

    /// dv^n/dt = ṡ u + s u̇ with u the unit direction of travel.
    fn velocity_rate_n(&self) -> Vector3<f64> {
        let (sp, cp) = self.yaw_rad.sin_cos();
        let (st, ct) = self.climb_rad.sin_cos();
        let u = Vector3::new(ct * cp, ct * sp, st);
        let td = self.climb_rate_rad_s;
        let pd = self.yaw_rate_rad_s;
        let u_dot = Vector3::new(
            -st * td * cp - ct * sp * pd,
            -st * td * sp + ct * cp * pd,
            ct * td,
        );
        self.accel_m_s2 * u + self.speed_m_s * u_dot
    }

    /// C_b^n = R_z(ψ) R_y(−θ): nose up by θ is a negative rotation about the left axis.
    fn q_nb(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_euler_angles(0.0, -self.climb_rad, self.yaw_rad)
    }

    /// ω_nb^b = (ψ̇ sin θ, −θ̇, ψ̇ cos θ), from Ċ_b^n = C_b^n [ω_nb^b ×].
    fn w_nb_b(&self) -> Vector3<f64> {
        let (st, ct) = self.climb_rad.sin_cos();
        Vector3::new(
            self.yaw_rate_rad_s * st,
            -self.climb_rate_rad_s,
            self.yaw_rate_rad_s * ct,
        )
    }
}

/// A trajectory ready for evaluation at any time in [start, end].
#[derive(Debug, Clone)]
pub struct Trajectory {
    start_t_s: f64,
    end_t_s: f64,
    plans: Vec<SegmentPlan>,
    /// Positions at start_t_s + k · CHECKPOINT_S.
    checkpoints: Vec<Llh>,
}

impl Trajectory {
    /// Validates the spec, plans the segments and integrates the positions.
    pub fn new(spec: &TrajectorySpec) -> Result<Self, TrajectoryError> {
        let start = validate_start(spec)?;
        let mut plans = Vec::with_capacity(spec.segments.len());
        let mut t = spec.start_t_s;
        let mut speed = spec.start_speed_m_s;
        let mut yaw = spec.start_yaw_deg.to_radians();
        for (index, seg) in spec.segments.iter().enumerate() {
            let duration_s = seg.duration_s();
            if !(duration_s.is_finite() && duration_s > 0.0) {
                return Err(TrajectoryError::InvalidSegment {
                    index,
                    reason: "duration_s must be positive and finite",
                });
            }
            let window = SmoothWindow::new(duration_s, spec.transition_s);
            let mut plan = SegmentPlan {
                t_start_s: t,
                window,
                speed0_m_s: speed,
                yaw0_rad: yaw,
                accel_m_s2: 0.0,
                yaw_rate_rad_s: 0.0,
                climb_rad: 0.0,
            };
            match *seg {
                Segment::Stationary { .. } => {
                    if speed != 0.0 {
                        return Err(TrajectoryError::MovingWhenStationary {
                            index,
                            speed_m_s: speed,
                        });
                    }
                }
                Segment::Cruise { .. } => {}
                Segment::SpeedTo { speed_m_s, .. } => {
                    if !(speed_m_s.is_finite() && speed_m_s >= 0.0) {
                        return Err(TrajectoryError::InvalidSegment {
                            index,
                            reason: "speed_m_s must be finite and non-negative",
                        });
                    }
                    plan.accel_m_s2 = (speed_m_s - speed) / window.total_integral_s();
                    // The end speed is the target exactly (a stop is a true zero).
                    speed = speed_m_s;
                }
                Segment::Turn { yaw_change_deg, .. } => {
                    if !yaw_change_deg.is_finite() {
                        return Err(TrajectoryError::InvalidSegment {
                            index,
                            reason: "yaw_change_deg must be finite",
                        });
                    }
                    let change = yaw_change_deg.to_radians();
                    plan.yaw_rate_rad_s = change / window.total_integral_s();
                    yaw += change;
                }
                Segment::Climb {
                    climb_angle_deg, ..
                } => {
                    if !(climb_angle_deg.is_finite() && climb_angle_deg.abs() <= MAX_ABS_CLIMB_DEG)
                    {
                        return Err(TrajectoryError::InvalidSegment {
                            index,
                            reason: "climb_angle_deg must be finite and within ±45°",
                        });
                    }
                    plan.climb_rad = climb_angle_deg.to_radians();
                }
            }
            plans.push(plan);
            t += duration_s;
        }
        if plans.is_empty() {
            return Err(TrajectoryError::NoSegments);
        }
        let duration_s = t - spec.start_t_s;
        if duration_s > MAX_DURATION_S {
            return Err(TrajectoryError::TooLong {
                duration_s,
                max_s: MAX_DURATION_S,
            });
        }
        let mut traj = Self {
            start_t_s: spec.start_t_s,
            end_t_s: t,
            plans,
            checkpoints: Vec::new(),
        };
        traj.integrate_checkpoints(start)?;
        Ok(traj)
    }

    /// Time of the first state (s).
    pub fn start_t_s(&self) -> f64 {
        self.start_t_s
    }

    /// Time of the last state (s).
    pub fn end_t_s(&self) -> f64 {
        self.end_t_s
    }

    /// The true state and IMU output at `t_s` in [start, end].
    pub fn truth_at(&self, t_s: f64) -> Result<TruthSample, TrajectoryError> {
        if !(t_s >= self.start_t_s && t_s <= self.end_t_s) {
            return Err(TrajectoryError::TimeOutOfRange {
                t_s,
                start_t_s: self.start_t_s,
                end_t_s: self.end_t_s,
            });
        }
        Ok(self.evaluate(t_s))
    }

    /// Truth samples at `rate_hz` from the start to the end (inclusive when the duration is
    /// a whole number of periods): t_k = start + k / rate, computed without accumulation.
    pub fn samples(&self, rate_hz: f64) -> Result<TruthSamples<'_>, TrajectoryError> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(TrajectoryError::InvalidRate { rate_hz });
        }
        // Choice: a slack of 1e-6 period so that 600 s at 100 Hz gives 60 001 samples despite
        // rounding in the product.
        let periods = ((self.end_t_s - self.start_t_s) * rate_hz + 1e-6).floor();
        Ok(TruthSamples {
            trajectory: self,
            rate_hz,
            next: 0,
            count: periods as u64 + 1,
        })
    }

    fn evaluate(&self, t_s: f64) -> TruthSample {
        let t = t_s.clamp(self.start_t_s, self.end_t_s);
        let k = self.kinematics(t);
        let p = self.position(t);
        let v_n = k.velocity_n();
        let q_nb = k.q_nb();
        let c_nb = q_nb.inverse();
        let w_ie_n = earth_rate_enu_rad_s(p.lat_rad);
        let w_en_n = transport_rate_enu_rad_s(&p, &v_n);
        let f_b = c_nb
            * (k.velocity_rate_n() + (2.0 * w_ie_n + w_en_n).cross(&v_n) - gravity_enu_m_s2(&p));
        let w_ib_b = k.w_nb_b() + c_nb * (w_ie_n + w_en_n);
        TruthSample {
            nav: NavState {
                t_s: t,
                p,
                v_n,
                q_nb,
            },
            imu: ImuSample {
                t_s: t,
                w_ib_b_rad_s: w_ib_b,
                f_ib_b_m_s2: f_b,
            },
        }
    }

    /// The segment holding `t` (the later one at a boundary) and its kinematics.
    fn kinematics(&self, t: f64) -> Kinematics {
        let idx = self
            .plans
            .partition_point(|p| p.t_start_s <= t)
            .saturating_sub(1);
        // `plans` is non-empty by construction; the fallback only keeps this total.
        let Some(plan) = self.plans.get(idx) else {
            return Kinematics {
                speed_m_s: 0.0,
                accel_m_s2: 0.0,
                yaw_rad: 0.0,
                yaw_rate_rad_s: 0.0,
                climb_rad: 0.0,
                climb_rate_rad_s: 0.0,
            };
        };
        let w = plan.window.at(t - plan.t_start_s);
        Kinematics {
            speed_m_s: plan.speed0_m_s + plan.accel_m_s2 * w.integral_s,
            accel_m_s2: plan.accel_m_s2 * w.value,
            yaw_rad: plan.yaw0_rad + plan.yaw_rate_rad_s * w.integral_s,
            yaw_rate_rad_s: plan.yaw_rate_rad_s * w.value,
            climb_rad: plan.climb_rad * w.value,
            climb_rate_rad_s: plan.climb_rad * w.rate_per_s,
        }
    }

    /// d(lat, lon, h)/dt at time `t` and position `p`.
    fn position_rate(&self, t: f64, p: &Llh) -> Vector3<f64> {
        let v = self.kinematics(t).velocity_n();
        Vector3::new(
            v[1] / (meridian_radius_m(p.lat_rad) + p.height_m),
            v[0] / ((transverse_radius_m(p.lat_rad) + p.height_m) * p.lat_rad.cos()),
            v[2],
        )
    }

    /// Classical RK4 from (t, p) over `h`.
    fn rk4_step(&self, t: f64, p: &Llh, h: f64) -> Llh {
        let y = p.to_vector();
        let k1 = self.position_rate(t, p);
        let k2 = self.position_rate(t + 0.5 * h, &Llh::from_vector(&(y + 0.5 * h * k1)));
        let k3 = self.position_rate(t + 0.5 * h, &Llh::from_vector(&(y + 0.5 * h * k2)));
        let k4 = self.position_rate(t + h, &Llh::from_vector(&(y + h * k3)));
        Llh::from_vector(&(y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)))
    }

    /// Integrates from (t0, p0) to t1 ≥ t0 in equal RK4 steps of at most RK4_STEP_S.
    fn propagate(&self, t0: f64, p0: &Llh, t1: f64) -> Llh {
        let span = t1 - t0;
        if span <= 0.0 {
            return *p0;
        }
        let n = (span / RK4_STEP_S).ceil().max(1.0);
        let h = span / n;
        let mut p = *p0;
        let mut k = 0.0;
        while k < n {
            p = self.rk4_step(t0 + k * h, &p, h);
            k += 1.0;
        }
        p
    }

    fn integrate_checkpoints(&mut self, start: Llh) -> Result<(), TrajectoryError> {
        let n = ((self.end_t_s - self.start_t_s) / CHECKPOINT_S).ceil() as usize + 1;
        let mut checkpoints = Vec::with_capacity(n);
        let mut p = start;
        checkpoints.push(p);
        for k in 1..n {
            let t0 = self.start_t_s + (k - 1) as f64 * CHECKPOINT_S;
            let t1 = self.start_t_s + k as f64 * CHECKPOINT_S;
            p = self.propagate(t0, &p, t1);
            let lat_deg = p.lat_rad.to_degrees();
            if !(p.is_finite() && lat_deg.abs() <= MAX_ABS_LAT_DEG) {
                return Err(TrajectoryError::LatitudeOutOfRange { t_s: t1, lat_deg });
            }
            checkpoints.push(p);
        }
        self.checkpoints = checkpoints;
        Ok(())
    }

    /// Position at `t` in [start, end]: RK4 from the last checkpoint at or before `t`.
    fn position(&self, t: f64) -> Llh {
        let k_max = self.checkpoints.len().saturating_sub(1);
        let k = (((t - self.start_t_s) / CHECKPOINT_S).floor().max(0.0) as usize).min(k_max);
        let t_k = self.start_t_s + k as f64 * CHECKPOINT_S;
        match self.checkpoints.get(k) {
            Some(p) => self.propagate(t_k, p, t),
            // Unreachable: there is always at least the start checkpoint.
            None => Llh::new(f64::NAN, f64::NAN, f64::NAN),
        }
    }
}

fn validate_start(spec: &TrajectorySpec) -> Result<Llh, TrajectoryError> {
    if spec.segments.is_empty() {
        return Err(TrajectoryError::NoSegments);
    }
    let fields = [
        spec.start_t_s,
        spec.start_lat_deg,
        spec.start_lon_deg,
        spec.start_height_m,
        spec.start_yaw_deg,
        spec.start_speed_m_s,
        spec.transition_s,
    ];
    if !fields.iter().all(|x| x.is_finite()) {
        return Err(TrajectoryError::InvalidStart {
            reason: "every start field must be finite",
        });
    }
    if spec.start_lat_deg.abs() > MAX_ABS_LAT_DEG {
        return Err(TrajectoryError::InvalidStart {
            reason: "start_lat_deg must be within ±85°",
        });
    }
    if spec.start_speed_m_s < 0.0 {
        return Err(TrajectoryError::InvalidStart {
            reason: "start_speed_m_s must be non-negative",
        });
    }
    if spec.transition_s <= 0.0 {
        return Err(TrajectoryError::InvalidStart {
            reason: "transition_s must be positive",
        });
    }
    Ok(Llh::from_degrees(
        spec.start_lat_deg,
        spec.start_lon_deg,
        spec.start_height_m,
    ))
}

/// Iterator over the truth at a fixed rate; see [`Trajectory::samples`].
#[derive(Debug, Clone)]
pub struct TruthSamples<'a> {
    trajectory: &'a Trajectory,
    rate_hz: f64,
    next: u64,
    count: u64,
}

impl Iterator for TruthSamples<'_> {
    type Item = TruthSample;

    fn next(&mut self) -> Option<TruthSample> {
        if self.next >= self.count {
            return None;
        }
        let t = self.trajectory.start_t_s + self.next as f64 / self.rate_hz;
        self.next += 1;
        Some(self.trajectory.evaluate(t))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = usize::try_from(self.count - self.next).unwrap_or(usize::MAX);
        (left, Some(left))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::llh_to_enu;

    fn spec() -> TrajectorySpec {
        TrajectorySpec {
            start_t_s: 100.0,
            start_lat_deg: 39.1,
            start_lon_deg: 117.2,
            start_height_m: 10.0,
            start_yaw_deg: 30.0,
            start_speed_m_s: 0.0,
            transition_s: 2.0,
            segments: vec![
                Segment::Stationary { duration_s: 5.0 },
                Segment::SpeedTo {
                    duration_s: 10.0,
                    speed_m_s: 15.0,
                },
                Segment::Turn {
                    duration_s: 10.0,
                    yaw_change_deg: 90.0,
                },
                Segment::Climb {
                    duration_s: 10.0,
                    climb_angle_deg: 5.0,
                },
                Segment::Cruise { duration_s: 5.0 },
                Segment::SpeedTo {
                    duration_s: 10.0,
                    speed_m_s: 0.0,
                },
                Segment::Stationary { duration_s: 5.0 },
            ],
        }
    }

    #[test]
    fn segment_targets_are_reached() {
        let traj = Trajectory::new(&spec()).unwrap();
        assert_eq!(traj.end_t_s(), 155.0);
        // End of acceleration: 15 m/s towards yaw 30°.
        let s = traj.truth_at(115.0).unwrap();
        assert!((s.nav.v_n.norm() - 15.0).abs() < 1e-12);
        let yaw = s.nav.v_n[1].atan2(s.nav.v_n[0]);
        assert!((yaw - 30f64.to_radians()).abs() < 1e-12);
        // After the turn, 120°.
        let s = traj.truth_at(125.0).unwrap();
        let yaw = s.nav.v_n[1].atan2(s.nav.v_n[0]);
        assert!((yaw - 120f64.to_radians()).abs() < 1e-12);
        // Mid-climb, 5° nose up; velocity along body x.
        let s = traj.truth_at(130.0).unwrap();
        let x_n = s.nav.q_nb * Vector3::x();
        assert!((x_n[2].asin() - 5f64.to_radians()).abs() < 1e-12);
        assert!((s.nav.v_n.normalize() - x_n).norm() < 1e-12);
        // Stopped and at rest at the end: f = −g^n in body, ω = earth rate only.
        let s = traj.truth_at(155.0).unwrap();
        assert!(s.nav.v_n.norm() < 1e-12);
        let c_nb = s.nav.q_nb.inverse();
        let g = gravity_enu_m_s2(&s.nav.p);
        assert!((s.imu.f_ib_b_m_s2 + c_nb * g).norm() < 1e-12);
        let w_ie = earth_rate_enu_rad_s(s.nav.p.lat_rad);
        assert!((s.imu.w_ib_b_rad_s - c_nb * w_ie).norm() < 1e-18);
    }

    /// Five-point central difference (f(−2h), f(−h), f(h), f(2h)) → f'(0), error O(h⁴).
    fn five_point(
        m2: Vector3<f64>,
        m1: Vector3<f64>,
        p1: Vector3<f64>,
        p2: Vector3<f64>,
        h: f64,
    ) -> Vector3<f64> {
        (m2 - 8.0 * m1 + 8.0 * p1 - p2) / (12.0 * h)
    }

    /// Independent checks of the analytic derivatives by central differences of the truth:
    /// velocity against position, ω_nb^b against attitude, and f^b against the velocity rate.
    ///
    /// Tolerances. Where the motion is smooth the stencil errs by O(h⁴) (negligible). The
    /// climb angle θ is only C², so θ̇ (in ω) and v (through θ) have a third derivative that
    /// jumps at ramp ends by J = θ_max · S'''(0) / r³ = 0.087 · 60 / 8 ≈ 0.65 rad/s³ (×15 m/s
    /// for v); there the five-point stencil errs by at most 0.034 J h² (computed for a
    /// one-sided cubic), i.e. 2e-8 rad/s and 3e-7 m/s² with h = 1 ms. Position values are
    /// rounded to one ulp of longitude (≈ 2 nm on the ground), which the stencil
    /// (Σ|coefficients| = 18, over 12h) amplifies to ≤ 6e-7 m/s with h = 5 ms, while the
    /// velocity (s C³, θ C²) is smooth enough that its truncation stays near 1e-9 m/s.
    #[test]
    fn truth_is_consistent_with_finite_differences() {
        let traj = Trajectory::new(&spec()).unwrap();
        let h_pos = 5e-3;
        let h = 1e-3;
        let mut t = 100.0 + 2.0 * h_pos;
        let mut checked = 0;
        while t < 155.0 - 2.0 * h_pos {
            let at = |k: f64| traj.truth_at(t + k).unwrap();
            let m = at(0.0);
            // Velocity: ENU displacements from the mid point.
            let enu = |k: f64| llh_to_enu(&at(k * h_pos).nav.p, &m.nav.p);
            let v_fd = five_point(enu(-2.0), enu(-1.0), enu(1.0), enu(2.0), h_pos);
            assert!(
                (v_fd - m.nav.v_n).norm() < 2e-6,
                "t={t}: {v_fd} vs {}",
                m.nav.v_n
            );
            // Attitude rate relative to n: φ(τ) = log(C(t)ᵀ C(t+τ)) has φ'(0) = ω_nb^b(t).
            let phi = |k: f64| (m.nav.q_nb.inverse() * at(k * h).nav.q_nb).scaled_axis();
            let w_nb_fd = five_point(phi(-2.0), phi(-1.0), phi(1.0), phi(2.0), h);
            let w_ie = earth_rate_enu_rad_s(m.nav.p.lat_rad);
            let w_en = transport_rate_enu_rad_s(&m.nav.p, &m.nav.v_n);
            let c_nb = m.nav.q_nb.inverse();
            let w_nb = m.imu.w_ib_b_rad_s - c_nb * (w_ie + w_en);
            assert!((w_nb_fd - w_nb).norm() < 1e-7, "t={t}: {w_nb_fd} vs {w_nb}");
            // Specific force from the velocity rate.
            let v = |k: f64| at(k * h).nav.v_n;
            let v_dot = five_point(v(-2.0), v(-1.0), v(1.0), v(2.0), h);
            let f =
                c_nb * (v_dot + (2.0 * w_ie + w_en).cross(&m.nav.v_n) - gravity_enu_m_s2(&m.nav.p));
            let f_true = m.imu.f_ib_b_m_s2;
            assert!((f - f_true).norm() < 1e-6, "t={t}: {f} vs {f_true}");
            t += 0.0371;
            checked += 1;
        }
        assert!(checked > 1000);
    }

    #[test]
    fn position_does_not_depend_on_the_checkpoint_used() {
        let traj = Trajectory::new(&spec()).unwrap();
        // From the start directly vs from the nearest checkpoint.
        let t = 137.345;
        let direct = traj.propagate(100.0, &traj.checkpoints[0], t);
        let via = traj.truth_at(t).unwrap().nav.p;
        let d = llh_to_enu(&direct, &via).norm();
        assert!(d < 1e-6, "{d}");
    }

    #[test]
    fn samples_cover_the_span() {
        let traj = Trajectory::new(&spec()).unwrap();
        let v: Vec<_> = traj.samples(100.0).unwrap().collect();
        assert_eq!(v.len(), 5501);
        assert_eq!(v[0].nav.t_s, 100.0);
        assert!((v[5500].nav.t_s - 155.0).abs() < 1e-9);
        assert!(traj.samples(0.0).is_err());
    }

    #[test]
    fn invalid_specs_are_rejected() {
        let mut s = spec();
        s.segments
            .insert(2, Segment::Stationary { duration_s: 1.0 });
        assert!(matches!(
            Trajectory::new(&s),
            Err(TrajectoryError::MovingWhenStationary { index: 2, .. })
        ));
        let mut s = spec();
        s.segments.clear();
        assert_eq!(
            Trajectory::new(&s).unwrap_err(),
            TrajectoryError::NoSegments
        );
        let mut s = spec();
        s.start_lat_deg = 89.0;
        assert!(matches!(
            Trajectory::new(&s),
            Err(TrajectoryError::InvalidStart { .. })
        ));
        let mut s = spec();
        s.segments.push(Segment::Cruise { duration_s: -1.0 });
        assert!(matches!(
            Trajectory::new(&s),
            Err(TrajectoryError::InvalidSegment { index: 7, .. })
        ));
        let mut s = spec();
        s.segments.push(Segment::Climb {
            duration_s: 1.0,
            climb_angle_deg: 60.0,
        });
        assert!(Trajectory::new(&s).is_err());
        let mut s = spec();
        s.segments.push(Segment::Cruise { duration_s: 1e9 });
        assert!(matches!(
            Trajectory::new(&s),
            Err(TrajectoryError::TooLong { .. })
        ));
        let traj = Trajectory::new(&spec()).unwrap();
        assert!(matches!(
            traj.truth_at(99.0),
            Err(TrajectoryError::TimeOutOfRange { .. })
        ));
        assert!(traj.truth_at(f64::NAN).is_err());
    }

    #[test]
    fn spec_reads_from_yaml() {
        let yaml = "
start_lat_deg: 39.1
start_lon_deg: 117.2
start_height_m: 10.0
segments:
  - { kind: stationary, duration_s: 10.0 }
  - { kind: speed_to, duration_s: 20.0, speed_m_s: 12.0 }
  - { kind: turn, duration_s: 15.0, yaw_change_deg: -90.0 }
  - { kind: climb, duration_s: 30.0, climb_angle_deg: 3.0 }
";
        let s: TrajectorySpec = serde_yaml::from_str(yaml).unwrap();
        assert_eq!(s.transition_s, 2.0);
        assert_eq!(s.segments.len(), 4);
        assert_eq!(
            s.segments[2],
            Segment::Turn {
                duration_s: 15.0,
                yaw_change_deg: -90.0
            }
        );
        let bad = "{ kind: turn, duration_s: 1.0, yaw_rate: 3.0 }";
        assert!(serde_yaml::from_str::<Segment>(bad).is_err());
    }
}
