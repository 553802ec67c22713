//! Start-up with no hand-entered state.
//!
//! 1. Levelling: roll and pitch from the mean specific force over
//!    `init.leveling_duration_s` at rest, and the gyro bias from the mean angular rate
//!    less the earth rate (resolved once the position and heading are known).
//! 2. Until the filter starts, the attitude is carried forward by the gyros alone.
//! 3. Position, velocity and clock come from an iterated least-squares single-point
//!    solution (tightly coupled) or the receiver's fix (loosely coupled).
//! 4. The heading is `init.heading_deg` (a compass heading) when given; otherwise the direction of the GNSS
//!    velocity once the speed exceeds `init.heading_min_speed_mps`, assuming the body's
//!    forward axis points along the motion (vehicles, walking with the device ahead).

use nalgebra::{UnitQuaternion, Vector3};

use crate::config::Config;
use crate::earth::{self, Llh};
use crate::gnss::spp::{self, SppConfig};
use crate::gnss::GnssEpoch;
use crate::ins::error_state::{
    StateMatrix, ACC_BIAS, CLOCK_BIAS, CLOCK_DRIFT, DP, DV, GYRO_BIAS, GYRO_GM, PHI,
};
use crate::ins::{ImuSample, NavState};

use super::update::{sigma_model, GnssFix};

/// What the initializer hands to the engine when it can start the filter.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialState {
    pub nav: NavState,
    pub gyro_bias_rad_s: Vector3<f64>,
    pub clock_bias_m: f64,
    pub clock_drift_mps: f64,
    pub p: StateMatrix,
    pub heading_from_motion: bool,
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
}

#[derive(Debug, Clone)]
struct Leveling {
    t_start_s: f64,
    /// The newest sample summed.
    last_t_s: f64,
    sum_f: Vector3<f64>,
    sum_w: Vector3<f64>,
    count: usize,
}

#[derive(Debug, Clone)]
struct Attitude {
    /// Gyro-propagated attitude; its yaw is arbitrary until the heading is known.
    q_nb: UnitQuaternion<f64>,
    /// Bias removed while propagating: the mean rate at rest (earth rate included).
    gyro_bias_rad_s: Vector3<f64>,
    last_t_s: f64,
    /// The levelled attitude and the mean rate at rest, for the bias estimate at start.
    at_rest: Option<(UnitQuaternion<f64>, Vector3<f64>)>,
}

/// The start-up state machine.
#[derive(Debug, Clone, Default)]
pub struct Initializer {
    leveling: Option<Leveling>,
    attitude: Option<Attitude>,
    position_known: bool,
    last_fix: Option<GnssFix>,
}

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

    pub fn phase(&self) -> InitPhase {
        match (&self.attitude, self.position_known) {
            (None, _) => InitPhase::Leveling,
            (Some(_), false) => InitPhase::WaitingForPosition,
            (Some(_), true) => InitPhase::WaitingForHeading,
        }
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
        let lev = self.leveling.get_or_insert(Leveling {
            t_start_s: s.t_s,
            last_t_s: f64::NEG_INFINITY,
            sum_f: Vector3::zeros(),
            sum_w: Vector3::zeros(),
            count: 0,
        });
        // A late measurement re-feeds the buffered samples: each counts once.
        if s.t_s <= lev.last_t_s {
            return;
        }
        lev.last_t_s = s.t_s;
        lev.sum_f += s.f_ib_b_m_s2;
        lev.sum_w += s.w_ib_b_rad_s;
        lev.count += 1;
        if s.t_s - lev.t_start_s >= config.init.leveling_duration_s && lev.count >= 2 {
            let n = lev.count as f64;
            let f = lev.sum_f / n;
            let w = lev.sum_w / n;
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
                at_rest: Some((q_nb, w)),
            });
        }
    }

    /// Tries to start from a GNSS epoch (tightly coupled).
    pub fn try_gnss(&mut self, epoch: &GnssEpoch, config: &Config) -> Option<InitialState> {
        let attitude = self.attitude.clone()?;
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
        self.position_known = true;
        let velocity = sol.velocity.as_ref().ok();
        let v_enu = velocity.map(|v| v.vel_enu_mps);
        let (yaw, from_motion) = self.heading(v_enu.as_ref(), config)?;
        let q_nb = replace_yaw(&attitude.q_nb, yaw);
        let clock_drift = velocity.map_or(0.0, |v| v.clock_drift_mps);
        let position_var = sol.covariance.fixed_view::<3, 3>(0, 0).trace() / 3.0;
        let mut init = self.initial_state(
            epoch.t_s,
            &sol.pos_llh,
            v_enu.unwrap_or_else(Vector3::zeros),
            q_nb,
            &attitude,
            config,
            position_var,
        );
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
    /// the velocity comes from the difference of consecutive fixes.
    pub fn try_fix(&mut self, fix: &GnssFix, config: &Config) -> Option<InitialState> {
        let previous = self.last_fix.replace(fix.clone());
        let attitude = self.attitude.clone()?;
        self.position_known = true;
        let velocity = fix.velocity_enu_mps.or_else(|| {
            let prev = previous?;
            let dt = fix.t_s - prev.t_s;
            (dt > 0.0 && dt < 5.0).then(|| earth::llh_to_enu(&fix.position, &prev.position) / dt)
        });
        let (yaw, from_motion) = self.heading(velocity.as_ref(), config)?;
        let q_nb = replace_yaw(&attitude.q_nb, yaw);
        let position_var = fix
            .position_covariance_enu_m2
            .map_or(config.loose.fix_sigma_horizontal_m.powi(2), |c| {
                c.trace() / 3.0
            });
        let mut init = self.initial_state(
            fix.t_s,
            &fix.position,
            velocity.unwrap_or_else(Vector3::zeros),
            q_nb,
            &attitude,
            config,
            position_var,
        );
        init.heading_from_motion = from_motion;
        Some(init)
    }

    /// Heading (ENU yaw, rad) and whether it came from motion; None while unknown.
    fn heading(&self, v_enu: Option<&Vector3<f64>>, config: &Config) -> Option<(f64, bool)> {
        if let Some(heading) = config.init.heading_rad {
            return Some((enu_yaw_of_heading(heading), false));
        }
        let v = v_enu?;
        (v[0].hypot(v[1]) >= config.init.heading_min_speed_mps).then(|| (v[1].atan2(v[0]), true))
    }

    #[allow(clippy::too_many_arguments)]
    fn initial_state(
        &self,
        t_s: f64,
        antenna: &Llh,
        v_enu: Vector3<f64>,
        q_nb: UnitQuaternion<f64>,
        attitude: &Attitude,
        config: &Config,
        position_var_m2: f64,
    ) -> InitialState {
        // The solution is the antenna's: move it to the IMU by the lever arm.
        let lever_n = q_nb * config.mounting.lever_arm_b_m;
        let imu_ecef =
            earth::llh_to_ecef(antenna) - earth::rot_ecef_to_enu(antenna).transpose() * lever_n;
        let p = earth::ecef_to_llh(&imu_ecef).unwrap_or(*antenna);
        let nav = NavState {
            t_s,
            p,
            v_n: v_enu,
            q_nb,
        };
        let mut cov = StateMatrix::zeros();
        let i = &config.init;
        let att = i.attitude_sigma_rad.powi(2);
        let set3 = |cov: &mut StateMatrix, start: usize, v: [f64; 3]| {
            for (k, value) in v.iter().enumerate() {
                cov[(start + k, start + k)] = *value;
            }
        };
        set3(&mut cov, PHI, [att, att, i.heading_sigma_rad.powi(2)]);
        let vel = i.velocity_sigma_mps.powi(2);
        set3(&mut cov, DV, [vel, vel, vel]);
        let pos = i.position_sigma_m.powi(2).max(position_var_m2);
        let (north, east) = earth::metres_per_radian(&p);
        set3(
            &mut cov,
            DP,
            [pos / (north * north), pos / (east * east), pos],
        );
        let gb = config.imu.gyro_bias_sigma_rad_s.powi(2);
        set3(&mut cov, GYRO_BIAS, [gb, gb, gb]);
        let gm = config.imu.gyro_markov_sigma_rad_s.powi(2);
        set3(&mut cov, GYRO_GM, [gm, gm, gm]);
        let ab = config.imu.accel_bias_sigma_m_s2.powi(2);
        set3(&mut cov, ACC_BIAS, [ab, ab, ab]);
        cov[(CLOCK_BIAS, CLOCK_BIAS)] = i.clock_bias_sigma_m.powi(2);
        cov[(CLOCK_DRIFT, CLOCK_DRIFT)] = i.clock_drift_sigma_mps.powi(2);
        // The bias at rest is the mean rate less the earth rate seen in the body frame,
        // which needs the heading: the levelled attitude turned by the yaw found since.
        let gyro_bias_rad_s =
            attitude
                .at_rest
                .map_or(attitude.gyro_bias_rad_s, |(q_level, w_rest)| {
                    let yaw_offset = q_nb.euler_angles().2 - attitude.q_nb.euler_angles().2;
                    let q_rest = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw_offset) * q_level;
                    w_rest - q_rest.inverse() * earth::earth_rate_enu_rad_s(p.lat_rad)
                });
        InitialState {
            nav,
            gyro_bias_rad_s,
            clock_bias_m: 0.0,
            clock_drift_mps: 0.0,
            p: cov,
            heading_from_motion: false,
        }
    }
}

/// Only the satellites of the enabled constellations.
fn filter_constellations(epoch: &GnssEpoch, config: &Config) -> GnssEpoch {
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
