//! Start-up with no hand-entered state.
//!
//! 1. Levelling: roll and pitch from the mean specific force over
//!    `init.leveling_duration_s`, the gyro bias from the mean angular rate less the
//!    earth rate (resolved once the position and heading are known), and the
//!    accelerometer bias along gravity from the mean specific force's magnitude less the
//!    normal gravity at the start's position ([`initial_state`]) — only when the
//!    window is at rest: the standstill test of [`super::standstill`] over the window, and
//!    no GNSS speed (when one is known) that denies it ([`REST_SPEED_MAX_MPS`]). A moving
//!    window gives no attitude and no gyro bias (a turn's rate is no bias); the next window
//!    is tried.
//! 2. Until the filter starts, the levelled attitude is carried forward by the gyros alone.
//! 3. Velocity and clock come from an iterated least-squares single-point solution
//!    (tightly coupled) or the receiver's fix (loosely coupled); the position from every
//!    single-point solution since the start-up began, combined ([`position_track`]), or
//!    the receiver's fix.
//! 4. The heading is `init.heading_deg` (a compass heading) when given; otherwise a
//!    dual-antenna pair's heading no older than [`alignment::ANTENNA_HEADING_AGE_S`] (with its σ: the
//!    heading at rest); otherwise, levelled at rest, the gyrocompass's
//!    ([`super::gyrocompass`]: the earth rate's direction in the levelling's mean rate,
//!    with its σ; only when that σ is below [`super::gyrocompass::MAX_SIGMA_RAD`], which
//!    only navigation-grade gyros reach); otherwise the direction of the GNSS velocity
//!    once the platform moves, assuming the body's forward axis points along the motion
//!    (vehicles, walking with the device ahead). Moving: the horizontal speed exceeds
//!    `init.heading_min_speed_mps` and is significant against its own covariance. Loosely coupled without a receiver velocity, the velocity is the
//!    displacement of the fixes over up to [`super::fix_track::MAX_BASELINE_S`], and the platform moves
//!    only once that displacement has been significant against the fixes' covariances for
//!    [`MOTION_EPOCHS`] consecutive fixes: fix noise at a standstill gives no heading.
//! 5. Not levelled and moving (a start in motion, a restart mid-drive): aligned in motion
//!    from GNSS. Heading from the course; roll and pitch from the recent mean specific
//!    force less the body acceleration that the GNSS speed and the gyros give (forward:
//!    the change of speed; sideways and up: the rate times the speed, the centripetal
//!    acceleration of a turn); gyro bias zero with the class's σ (`imu.gyro_bias_deg_per_h`).
//!    The covariance covers the alignment's errors: the course's own uncertainty and
//!    [`alignment::COURSE_SIGMA_RAD`] in the heading, the unknown acceleration in roll and pitch.
//!    A heading σ above [`super::heading_bank::BANK_ABOVE_RAD`] is resolved by the engine's bank of
//!    heading hypotheses ([`super::heading_bank`]).

use nalgebra::{Matrix2, Matrix3, UnitQuaternion, Vector2, Vector3};

use crate::config::Config;
use crate::earth::{self, Llh};
use crate::gnss::spp::{self, SppConfig};
use crate::gnss::GnssEpoch;
use crate::ins::error_state::{StateMatrix, CLOCK_BIAS, CLOCK_DRIFT};
use crate::ins::{ImuSample, NavState};

use super::fix_track::FixTrack;
use super::standstill::MotionStatistics;
use super::update::{sigma_model, GnssFix};

mod alignment;
mod initial_state;
mod position_track;

use position_track::PositionTrack;

/// Longest interval between two GNSS speeds whose difference gives the forward
/// acceleration of an alignment in motion, and the age up to which a GNSS speed counts in
/// the levelling's rest test (s).
const SPEED_AGE_S: f64 = 2.0;

/// Consecutive fixes of significant displacement before a loosely-coupled start without
/// a receiver velocity takes a heading. Choice: 3, so that one fix pulled by noise or an
/// outlier does not set the heading.
const MOTION_EPOCHS: usize = 3;
/// A horizontal GNSS speed above this, when significant, denies the levelling's rest and
/// the start position track's (m/s). Choice: 0.5 m/s, above the speed noise of a
/// single-point velocity and below a walking pace.
const REST_SPEED_MAX_MPS: f64 = 0.5;
/// Confidence of the test that a GNSS velocity differs from zero. Choice: 0.999, so that
/// fix noise at a standstill passes it once in a thousand fixes, and [`MOTION_EPOCHS`]
/// consecutive passes (loosely coupled) practically never.
const MOTION_CONFIDENCE: f64 = 0.999;

/// The horizontal specific force along the body's forward axis (m/s²) of the `recent`
/// samples' mean, resolved with the attitude `q_nb` (levelled; its yaw does not matter):
/// the forward acceleration, Coriolis and transport rate (about 1e-4 m/s²) aside.
fn forward_acceleration_m_s2(q_nb: &UnitQuaternion<f64>, recent: &MotionStatistics) -> f64 {
    let f_h = (q_nb * recent.mean_f()).xy();
    (q_nb * Vector3::x())
        .xy()
        .try_normalize(1e-9)
        .map_or(0.0, |forward| f_h.dot(&forward))
}

/// True when the horizontal vector `x` of covariance `cov` differs from zero beyond the
/// chi-square quantile (two degrees of freedom: −2 ln(1 − p)) of [`MOTION_CONFIDENCE`].
fn significant(x: &Vector2<f64>, cov: &Matrix2<f64>) -> bool {
    let quantile = -2.0 * (1.0 - MOTION_CONFIDENCE).ln();
    cov.try_inverse()
        .is_some_and(|inv| (x.transpose() * inv * x)[(0, 0)] > quantile)
}

/// What the initializer hands to the engine when it can start the filter.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialState {
    pub nav: NavState,
    pub gyro_bias_rad_s: Vector3<f64>,
    pub accel_bias_m_s2: Vector3<f64>,
    pub clock_bias_m: f64,
    pub clock_drift_mps: f64,
    pub p: StateMatrix,
    pub heading_from_motion: bool,
    /// Heading 1-sigma of the start (rad).
    pub heading_sigma_rad: f64,
}

/// Progress of the start-up, for diagnostics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InitPhase {
    /// Averaging the accelerometers for roll and pitch.
    Leveling,
    /// Levelled; waiting for a position solution.
    WaitingForPosition,
    /// Position known; the heading is not (moving too slowly).
    WaitingForHeading,
    /// Resolving a coarse heading with the bank of hypotheses.
    AligningHeading,
}

#[derive(Debug, Clone)]
struct Leveling {
    t_start_s: f64,
    stats: MotionStatistics,
}

/// A GNSS velocity (ENU) and its horizontal covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
struct GnssVelocity {
    t_s: f64,
    v_enu_mps: Vector3<f64>,
    cov_h_m2_s2: Matrix2<f64>,
    /// 1-sigma of what the velocity's extrapolation to `t_s` may have missed (m/s): 0 for
    /// a receiver's velocity; for the fixes' line, see [`Initializer::track_velocity`].
    extrapolation_sigma_mps: f64,
    /// False for a displacement of fixes not yet significant for [`MOTION_EPOCHS`].
    confirmed: bool,
}

impl GnssVelocity {
    fn speed_h_mps(&self) -> f64 {
        self.v_enu_mps.xy().norm()
    }

    /// Denies a rest (the levelling's and the start position track's): the horizontal
    /// speed exceeds [`REST_SPEED_MAX_MPS`] and is significant against its covariance, so
    /// that the speed noise of a standing receiver does not deny it.
    fn denies_rest(&self) -> bool {
        self.speed_h_mps() > REST_SPEED_MAX_MPS
            && significant(&self.v_enu_mps.xy(), &self.cov_h_m2_s2)
    }

    /// Moving: the horizontal speed reaches `init.heading_min_speed_mps` and is significant
    /// against its covariance.
    fn moving(&self, config: &Config) -> bool {
        self.confirmed
            && significant(&self.v_enu_mps.xy(), &self.cov_h_m2_s2)
            && self.speed_h_mps() >= config.init.heading_min_speed_mps
    }

    /// 1-sigma of the course (rad): the velocity's spread across its direction over the
    /// speed.
    fn course_sigma_rad(&self) -> f64 {
        let v = self.v_enu_mps.xy();
        let across = Vector2::new(-v[1], v[0]) / v.norm();
        (across.transpose() * self.cov_h_m2_s2 * across)[(0, 0)]
            .max(0.0)
            .sqrt()
            / v.norm()
    }
}

/// Roll, pitch and heading of an alignment with their 1-sigmas, and the gyro bias.
#[derive(Debug, Clone, Copy)]
struct Alignment {
    q_nb: UnitQuaternion<f64>,
    /// 1-sigma of roll, pitch and heading (rad).
    sigma_rad: [f64; 3],
    velocity_sigma_mps: f64,
    /// The heading is the gyrocompass's (see [`Initializer::initial_state`]).
    gyrocompass: bool,
}

#[derive(Debug, Clone)]
struct Attitude {
    /// Gyro-propagated attitude; its yaw is arbitrary until the heading is known.
    q_nb: UnitQuaternion<f64>,
    /// Bias removed while propagating: the mean rate at rest (earth rate included).
    gyro_bias_rad_s: Vector3<f64>,
    last_t_s: f64,
    /// The levelling at rest, for the gyrocompass and the bias estimate at start.
    at_rest: Option<Rest>,
}

/// A levelling window at rest.
#[derive(Debug, Clone, Copy)]
struct Rest {
    /// The levelled attitude (yaw as it was then: 0 or `init.heading_deg`).
    q_level: UnitQuaternion<f64>,
    /// The mean angular rate over the window (earth rate included).
    mean_w_rad_s: Vector3<f64>,
    /// The mean specific force over the window: gravity's reaction plus the
    /// accelerometer bias.
    mean_f_m_s2: Vector3<f64>,
    window_s: f64,
    /// End of the window (s).
    t_end_s: f64,
}

/// The start-up state machine.
#[derive(Debug, Clone)]
pub struct Initializer {
    leveling: Option<Leveling>,
    /// The newest IMU sample seen (a late measurement re-feeds the buffered samples: each
    /// counts once).
    last_imu_t_s: Option<f64>,
    attitude: Option<Attitude>,
    position_known: bool,
    /// The recent fixes (loosely coupled).
    fixes: FixTrack,
    /// Consecutive fixes whose displacement was significant.
    moving_fixes: usize,
    /// The newest GNSS velocity.
    velocity: Option<GnssVelocity>,
    /// The gyro bias prior's σ when the bias is not measured at rest, in multiples of the
    /// IMU class's `imu.gyro_bias_deg_per_h` (1, or [`DIVERGED_GYRO_BIAS_SIGMA_FACTOR`]
    /// after a divergence).
    gyro_bias_sigma_factor: f64,
    /// The newest dual-antenna heading of the body.
    antenna_heading: Option<AntennaHeading>,
    /// The single-point solutions so far, combined (tightly coupled).
    position_track: Option<PositionTrack>,
}

/// A dual-antenna pair's heading of the body's x axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AntennaHeading {
    pub t_s: f64,
    /// Compass heading (clockwise from north, rad).
    pub heading_rad: f64,
    pub sigma_rad: f64,
}

/// The heading a start takes.
#[derive(Debug, Clone, Copy)]
struct StartHeading {
    /// ENU yaw (rad).
    yaw_rad: f64,
    from_motion: bool,
    /// Its 1-sigma when it comes with one (a dual antenna, the gyrocompass), rad.
    sigma_rad: Option<f64>,
    /// From the gyrocompass: the horizontal gyro bias is the heading's (not measured).
    gyrocompass: bool,
}

impl Default for Initializer {
    fn default() -> Self {
        Self {
            leveling: None,
            last_imu_t_s: None,
            attitude: None,
            position_known: false,
            fixes: FixTrack::default(),
            moving_fixes: 0,
            velocity: None,
            gyro_bias_sigma_factor: 1.0,
            antenna_heading: None,
            position_track: None,
        }
    }
}

/// The gyro bias prior's σ after a divergence, in multiples of the class's turn-on σ.
///
/// Choice: ten. A filter that diverged while GNSS was there has met an IMU error its
/// model did not hold (a bias that jumped with temperature or a knock, a fault): the
/// class's σ has just failed to cover it, so the restart allows an order of magnitude
/// more, which the GNSS then narrows within tens of seconds of driving. Measured in
/// tests/divergence_monitor.rs: after a consumer-MEMS gyro's biases jump to ten times
/// their value (0.6–1.1 °/s) the worst NEES of the restarted filter is 14–20 against a 3σ
/// bound of 25.3 (tightly coupled, ekf and iarf); restarted from the kept attitude and
/// bias with the class's σ it reached 1,009.
pub const DIVERGED_GYRO_BIAS_SIGMA_FACTOR: f64 = 10.0;

impl Initializer {
    /// Keeps what was learned about the attitude (after a reset the filter restarts from
    /// it instead of levelling again, which would need the vehicle at rest).
    pub fn with_attitude(
        q_nb: UnitQuaternion<f64>,
        gyro_bias_rad_s: Vector3<f64>,
        t_s: f64,
    ) -> Self {
        Self {
            attitude: Some(Attitude {
                q_nb,
                gyro_bias_rad_s,
                last_t_s: t_s,
                at_rest: None,
            }),
            ..Self::default()
        }
    }

    /// Starts again from nothing after a divergence, with a wide gyro bias prior
    /// ([`DIVERGED_GYRO_BIAS_SIGMA_FACTOR`]).
    ///
    /// Choice: unlike after an IMU gap, the attitude and gyro bias are not kept: a filter
    /// that diverged with GNSS present had them wrong (a gyro fault tilts and turns it by
    /// degrees while its σ says tenths), and a restart from them stays over-confident for
    /// minutes. The start-up aligns again — at rest by levelling, in motion from the GNSS
    /// course and the specific force (with the heading bank when that heading is coarse).
    pub fn after_divergence() -> Self {
        Self {
            gyro_bias_sigma_factor: DIVERGED_GYRO_BIAS_SIGMA_FACTOR,
            ..Self::default()
        }
    }

    /// The σ of a gyro bias not measured at rest (rad/s).
    fn turn_on_gyro_bias_sigma_rad_s(&self, config: &Config) -> f64 {
        config.imu.gyro_bias_sigma_rad_s * self.gyro_bias_sigma_factor
    }

    pub fn phase(&self) -> InitPhase {
        match (&self.attitude, self.position_known) {
            (None, _) => InitPhase::Leveling,
            (Some(_), false) => InitPhase::WaitingForPosition,
            (Some(_), true) => InitPhase::WaitingForHeading,
        }
    }

    /// Keeps a dual-antenna heading for the start.
    pub fn note_antenna_heading(&mut self, heading: AntennaHeading) {
        self.antenna_heading = Some(heading);
    }

    /// Feeds one body-frame IMU sample.
    pub fn push_imu(&mut self, s: &ImuSample, config: &Config) {
        if let Some(att) = &mut self.attitude {
            let dt = s.t_s - att.last_t_s;
            if dt > 0.0 {
                let w = s.w_ib_b_rad_s - att.gyro_bias_rad_s;
                att.q_nb *= UnitQuaternion::from_scaled_axis(w * dt);
                att.last_t_s = s.t_s;
            }
            return;
        }
        if self.last_imu_t_s.is_some_and(|last| s.t_s <= last) {
            return;
        }
        self.last_imu_t_s = Some(s.t_s);
        let lev = self.leveling.get_or_insert(Leveling {
            t_start_s: s.t_s,
            stats: MotionStatistics::default(),
        });
        lev.stats.push(s);
        if s.t_s - lev.t_start_s >= config.init.leveling_duration_s && lev.stats.count() >= 2 {
            let imu_at_rest = lev.stats.at_rest(&config.imu);
            let gnss_moving = self
                .velocity
                .is_some_and(|v| v.t_s >= lev.t_start_s - SPEED_AGE_S && v.denies_rest());
            let (f, w) = (lev.stats.mean_f(), lev.stats.mean_w());
            let window_s = lev.stats.duration_s();
            self.leveling = None;
            if !imu_at_rest || gnss_moving {
                return;
            }
            // f^b = C_n^b (0, 0, g) at rest: roll = atan2(f_y, f_z),
            // pitch = atan2(−f_x, √(f_y² + f_z²)) (FLU body, REP-103 angles).
            let roll = f[1].atan2(f[2]);
            let pitch = (-f[0]).atan2(f[1].hypot(f[2]));
            let yaw = config.init.heading_rad.map_or(0.0, enu_yaw_of_heading);
            let q_nb = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
            self.attitude = Some(Attitude {
                q_nb,
                gyro_bias_rad_s: w,
                last_t_s: s.t_s,
                at_rest: Some(Rest {
                    q_level: q_nb,
                    mean_w_rad_s: w,
                    mean_f_m_s2: f,
                    window_s,
                    t_end_s: s.t_s,
                }),
            });
        }
    }

    /// Tries to start from a GNSS epoch (tightly coupled); `recent` holds the IMU samples
    /// of the last [`super::standstill::WINDOW_S`] (for an alignment in motion).
    pub fn try_gnss(
        &mut self,
        epoch: &GnssEpoch,
        config: &Config,
        recent: &MotionStatistics,
    ) -> Option<InitialState> {
        let spp_config = SppConfig {
            elevation_mask_rad: config.gnss.elevation_mask_rad,
            sigma: sigma_model(config),
            ..SppConfig::default()
        };
        let epoch = filter_constellations(epoch, config);
        let sol = spp::solve_spp(&epoch, &spp_config).ok()?;
        if sol.num_used < config.init.min_satellites {
            return None;
        }
        let velocity = sol.velocity.as_ref().ok();
        let v_enu = velocity.map(|v| v.vel_enu_mps);
        let previous = self.velocity;
        if let Some(v) = velocity {
            let r = earth::rot_ecef_to_enu(&sol.pos_llh);
            let cov: Matrix3<f64> = r * v.covariance.fixed_view::<3, 3>(0, 0) * r.transpose();
            self.velocity = Some(GnssVelocity {
                t_s: epoch.t_s,
                v_enu_mps: v.vel_enu_mps,
                cov_h_m2_s2: cov.fixed_view::<2, 2>(0, 0).into(),
                extrapolation_sigma_mps: 0.0,
                confirmed: true,
            });
        }
        let min_sigma_m = config.init.position_sigma_m;
        // At rest for the track: the IMU says so, and the Doppler speed (when there is
        // one) is slow or not significant against its noise.
        let gnss_moving = velocity.and(self.velocity).is_some_and(|v| v.denies_rest());
        let at_rest = recent.at_rest(&config.imu) && !gnss_moving;
        let track = match &self.position_track {
            Some(track) => track.push(epoch.t_s, &sol, min_sigma_m, at_rest),
            None => PositionTrack::new(epoch.t_s, &sol, min_sigma_m),
        };
        let antenna = earth::ecef_to_llh(&track.pos_ecef_m()).unwrap_or(sol.pos_llh);
        let position_var = track.position_var_enu_m2(&antenna);
        self.position_track = Some(track);
        let (alignment, from_motion) = match self.attitude.clone() {
            Some(attitude) => {
                self.position_known = true;
                let heading =
                    self.heading(epoch.t_s, v_enu.as_ref(), sol.pos_llh.lat_rad, config)?;
                let q_nb = replace_yaw(&attitude.q_nb, heading.yaw_rad);
                let course = self.velocity.filter(|_| heading.from_motion);
                (
                    Self::levelled(q_nb, course, &heading, config),
                    heading.from_motion,
                )
            }
            None => (self.align_in_motion(previous, recent, config)?, true),
        };
        let clock_drift = velocity.map_or(0.0, |v| v.clock_drift_mps);
        let mut init = self.initial_state(
            epoch.t_s,
            &antenna,
            v_enu.unwrap_or_else(Vector3::zeros),
            &alignment,
            config,
            position_var,
        );
        // The clock is this epoch's solution's, which its position's metre or so from the
        // combined one shifts by as much: within the clock's start σ (30 m by default).
        init.clock_bias_m = sol.clock_bias_m;
        init.clock_drift_mps = clock_drift;
        init.p[(CLOCK_BIAS, CLOCK_BIAS)] = config
            .init
            .clock_bias_sigma_m
            .powi(2)
            .max(sol.covariance[(3, 3)]);
        init.p[(CLOCK_DRIFT, CLOCK_DRIFT)] = config.init.clock_drift_sigma_mps.powi(2);
        init.heading_from_motion = from_motion;
        Some(init)
    }

    /// Tries to start from a receiver fix (loosely coupled). Without a velocity in the fix,
    /// the velocity comes from the displacement of the recent fixes (see the module
    /// documentation).
    pub fn try_fix(
        &mut self,
        fix: &GnssFix,
        config: &Config,
        recent: &MotionStatistics,
    ) -> Option<InitialState> {
        let previous = self.velocity;
        let fix_var = fix
            .position_covariance_enu_m2
            .map_or(config.loose.fix_sigma_horizontal_m.powi(2), |c| {
                c.trace() / 3.0
            });
        let (velocity, position, position_var) = match fix.velocity_enu_mps {
            Some(v) => {
                let cov = super::update::velocity_covariance(fix, config);
                let velocity = GnssVelocity {
                    t_s: fix.t_s,
                    v_enu_mps: v,
                    cov_h_m2_s2: cov.fixed_view::<2, 2>(0, 0).into(),
                    extrapolation_sigma_mps: 0.0,
                    confirmed: true,
                };
                (Some(velocity), fix.position, fix_var)
            }
            None => match self.track_velocity(fix, recent, config) {
                Some((velocity, position, var)) => (Some(velocity), position, var),
                None => (None, fix.position, fix_var),
            },
        };
        if velocity.is_some() {
            self.velocity = velocity;
        }
        let (alignment, from_motion) = match self.attitude.clone() {
            Some(attitude) => {
                self.position_known = true;
                let v = velocity.filter(|v| fix.velocity_enu_mps.is_some() || v.moving(config));
                let v_enu = v.map(|v| v.v_enu_mps);
                let heading = self.heading(fix.t_s, v_enu.as_ref(), position.lat_rad, config)?;
                let q_nb = replace_yaw(&attitude.q_nb, heading.yaw_rad);
                let course = v.filter(|_| heading.from_motion);
                (
                    Self::levelled(q_nb, course, &heading, config),
                    heading.from_motion,
                )
            }
            None => (self.align_in_motion(previous, recent, config)?, true),
        };
        let mut init = self.initial_state(
            fix.t_s,
            &position,
            self.velocity.map_or_else(Vector3::zeros, |v| v.v_enu_mps),
            &alignment,
            config,
            Vector3::repeat(position_var.max(config.init.position_sigma_m.powi(2))),
        );
        init.heading_from_motion = from_motion;
        Some(init)
    }

    /// The velocity of the line through the recent fixes ([`FixTrack`]) carried over its
    /// lag to the newest fix, and the line's position there, carried forward likewise, and
    /// its variance; confirmed once the velocity has been significant for [`MOTION_EPOCHS`]
    /// consecutive fixes.
    ///
    /// Over the lag (about half the baseline, 2 s at 1 Hz) a turn's course has moved on by
    /// the rate about the vertical times the lag, and, once levelled, the speed by the
    /// forward acceleration times the lag (the horizontal specific force along the body's
    /// forward axis, which points along the course as the heading from it assumes); without
    /// the second a car pulling away at 0.5 m/s² started 1 m/s slow and its first fixes
    /// threw the heading by degrees. Choice: the acceleration is the recent samples' mean
    /// (the last second), taken to hold over the whole lag; half of each correction is kept
    /// as its 1-sigma (`extrapolation_sigma_mps`, and in the position's variance) for the
    /// change it may have missed. Not levelled (a start in motion), nothing is corrected.
    fn track_velocity(
        &mut self,
        fix: &GnssFix,
        recent: &MotionStatistics,
        config: &Config,
    ) -> Option<(GnssVelocity, Llh, f64)> {
        self.fixes.push(fix);
        let fit = self.fixes.fit(config)?;
        let v_h = fit.v_enu_mps.xy();
        self.moving_fixes = if significant(&v_h, &fit.cov_v_h_m2_s2) {
            self.moving_fixes + 1
        } else {
            0
        };
        let up = recent
            .mean_f()
            .try_normalize(1e-9)
            .unwrap_or_else(Vector3::z);
        let rotation = nalgebra::Rotation2::new(recent.mean_w().dot(&up) * fit.lag_s);
        let mut v_h = rotation * v_h;
        let accel_m_s2 = self
            .attitude
            .as_ref()
            .filter(|_| recent.count() >= 2)
            .map_or(0.0, |a| forward_acceleration_m_s2(&a.q_nb, recent));
        let speed_change_mps = accel_m_s2 * fit.lag_s;
        let shortfall_m = accel_m_s2 * fit.quadratic_lag_s2;
        let mut position = fit.position;
        if let Some(course) = v_h.try_normalize(1e-9) {
            v_h += course * speed_change_mps;
            let ahead = course * shortfall_m;
            position = earth::enu_to_llh(&Vector3::new(ahead[0], ahead[1], 0.0), &position)
                .unwrap_or(position);
        }
        let velocity = GnssVelocity {
            t_s: fit.t_s,
            v_enu_mps: Vector3::new(v_h[0], v_h[1], fit.v_enu_mps[2]),
            cov_h_m2_s2: rotation.matrix() * fit.cov_v_h_m2_s2 * rotation.matrix().transpose(),
            extrapolation_sigma_mps: 0.5 * speed_change_mps.abs(),
            confirmed: self.moving_fixes >= MOTION_EPOCHS,
        };
        let position_var_m2 = fit.position_var_m2 + (0.5 * shortfall_m).powi(2);
        Some((velocity, position, position_var_m2))
    }
}

/// Only the satellites of the enabled constellations.
pub(super) fn filter_constellations(epoch: &GnssEpoch, config: &Config) -> GnssEpoch {
    GnssEpoch {
        satellites: epoch
            .satellites
            .iter()
            .filter(|s| config.gnss.constellations.contains(&s.sat.constellation))
            .cloned()
            .collect(),
        ..epoch.clone()
    }
}

/// ENU yaw (from East towards North) of a compass heading (from North towards East).
fn enu_yaw_of_heading(heading_rad: f64) -> f64 {
    std::f64::consts::FRAC_PI_2 - heading_rad
}

/// The same roll and pitch with a new yaw (ENU, from East towards North).
fn replace_yaw(q_nb: &UnitQuaternion<f64>, yaw: f64) -> UnitQuaternion<f64> {
    let (roll, pitch, _) = q_nb.euler_angles();
    UnitQuaternion::from_euler_angles(roll, pitch, yaw)
}
