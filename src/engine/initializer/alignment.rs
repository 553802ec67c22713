//! The start's attitude: the levelled attitude turned to the heading found, the heading's
//! sources in their order, and the alignment in motion (see the parent module's steps 4
//! and 5).

use nalgebra::{UnitQuaternion, Vector3};

use crate::config::Config;

use super::super::gyrocompass;
use super::super::standstill::MotionStatistics;
use super::{enu_yaw_of_heading, Alignment, GnssVelocity, Initializer, StartHeading, SPEED_AGE_S};

/// 1-sigma of an acceleration along the body's forward axis that no GNSS speed difference
/// measures (m/s²). Choice: a car's brisk acceleration or braking.
const UNKNOWN_ACCELERATION_M_S2: f64 = 1.0;
/// 1-sigma of the body's forward axis against the course (rad): side-slip and the
/// mounting's yaw. Choice: 3°, a car's side-slip in a brisk turn.
const COURSE_SIGMA_RAD: f64 = 3.0 * std::f64::consts::PI / 180.0;
/// Oldest dual-antenna heading a start takes (s). Choice: 1 s, a few of the pair's epochs;
/// the body turns little in that time while levelled or parked.
const ANTENNA_HEADING_AGE_S: f64 = 1.0;

impl Initializer {
    /// The levelled attitude turned to the heading found, with the configured 1-sigmas; a
    /// heading from the `course` of a GNSS velocity has at least the course's own
    /// uncertainty and [`COURSE_SIGMA_RAD`]; one with its own σ (a dual antenna, the
    /// gyrocompass) has that.
    pub(super) fn levelled(
        q_nb: UnitQuaternion<f64>,
        course: Option<GnssVelocity>,
        heading: &StartHeading,
        config: &Config,
    ) -> Alignment {
        let i = &config.init;
        let heading_sigma = heading.sigma_rad.unwrap_or_else(|| {
            course.map_or(i.heading_sigma_rad, |v| {
                i.heading_sigma_rad
                    .max(v.course_sigma_rad().hypot(COURSE_SIGMA_RAD))
            })
        });
        // The velocity's own uncertainty where it exceeds the configured σ.
        let velocity_sigma_mps = course.map_or(i.velocity_sigma_mps, |v| {
            let own_var = 0.5 * v.cov_h_m2_s2.trace() + v.extrapolation_sigma_mps.powi(2);
            i.velocity_sigma_mps.max(own_var.max(0.0).sqrt())
        });
        Alignment {
            q_nb,
            sigma_rad: [i.attitude_sigma_rad, i.attitude_sigma_rad, heading_sigma],
            velocity_sigma_mps,
            gyrocompass: heading.gyrocompass,
        }
    }

    /// Roll, pitch and heading of a moving platform from the newest GNSS velocity and the
    /// `recent` IMU samples (see the module documentation); None while not moving.
    pub(super) fn align_in_motion(
        &self,
        previous: Option<GnssVelocity>,
        recent: &MotionStatistics,
        config: &Config,
    ) -> Option<Alignment> {
        let v = self.velocity.filter(|v| v.moving(config))?;
        if recent.count() < 2 {
            return None;
        }
        let speed = v.v_enu_mps.norm();
        let speed_sigma = v.cov_h_m2_s2.trace().max(0.0).sqrt();
        // The forward acceleration from the previous GNSS speed, when that is close enough
        // in time and precise enough to beat the unknown acceleration.
        let (accel, accel_sigma) = previous
            .filter(|p| p.confirmed && p.t_s < v.t_s && v.t_s - p.t_s <= SPEED_AGE_S)
            .map(|p| {
                let dt = v.t_s - p.t_s;
                let sigma = (v.cov_h_m2_s2.trace() + p.cov_h_m2_s2.trace())
                    .max(0.0)
                    .sqrt()
                    / dt;
                ((speed - p.v_enu_mps.norm()) / dt, sigma)
            })
            .filter(|(_, sigma)| *sigma < UNKNOWN_ACCELERATION_M_S2)
            .unwrap_or((0.0, UNKNOWN_ACCELERATION_M_S2));
        // The body's acceleration with its velocity along x: d/dt (s, 0, 0) + ω × (s, 0, 0).
        let w = recent.mean_w();
        let a_b = Vector3::new(accel, w[2] * speed, -w[1] * speed);
        let up = recent.mean_f() - a_b;
        let roll = up[1].atan2(up[2]);
        let pitch = (-up[0]).atan2(up[1].hypot(up[2]));
        let yaw = match config.init.heading_rad {
            Some(heading) => enu_yaw_of_heading(heading),
            None => v.v_enu_mps[1].atan2(v.v_enu_mps[0]),
        };
        let g = up.norm().max(1.0);
        let i = &config.init;
        let sideways = self.turn_on_gyro_bias_sigma_rad_s(config) * speed;
        let heading_sigma = match config.init.heading_rad {
            Some(_) => i.heading_sigma_rad,
            None => v.course_sigma_rad().hypot(COURSE_SIGMA_RAD),
        };
        Some(Alignment {
            q_nb: UnitQuaternion::from_euler_angles(roll, pitch, yaw),
            sigma_rad: [
                i.attitude_sigma_rad.hypot(sideways / g),
                i.attitude_sigma_rad.hypot(accel_sigma / g),
                heading_sigma,
            ],
            velocity_sigma_mps: i.velocity_sigma_mps.max(speed_sigma),
            gyrocompass: false,
        })
    }

    /// The heading of a start at `t_s` at latitude `lat_rad` (see the module
    /// documentation); None while unknown.
    pub(super) fn heading(
        &self,
        t_s: f64,
        v_enu: Option<&Vector3<f64>>,
        lat_rad: f64,
        config: &Config,
    ) -> Option<StartHeading> {
        if let Some(heading) = config.init.heading_rad {
            return Some(StartHeading {
                yaw_rad: enu_yaw_of_heading(heading),
                from_motion: false,
                sigma_rad: None,
                gyrocompass: false,
            });
        }
        if let Some(a) = self
            .antenna_heading
            .filter(|a| (t_s - a.t_s).abs() <= ANTENNA_HEADING_AGE_S)
        {
            return Some(StartHeading {
                yaw_rad: enu_yaw_of_heading(a.heading_rad),
                from_motion: false,
                sigma_rad: Some(a.sigma_rad),
                gyrocompass: false,
            });
        }
        // The levelled attitude's heading, carried to now by the turn the gyros have seen
        // since the levelling.
        let compass = self.attitude.as_ref().and_then(|attitude| {
            let rest = attitude.at_rest?;
            let found = gyrocompass::gyrocompass(
                &rest.q_level,
                &rest.mean_w_rad_s,
                rest.window_s,
                lat_rad,
                config,
            )?;
            let turned_rad = attitude.q_nb.euler_angles().2 - rest.q_level.euler_angles().2;
            Some(StartHeading {
                yaw_rad: found.yaw_rad + turned_rad,
                from_motion: false,
                sigma_rad: Some(found.sigma_rad),
                gyrocompass: true,
            })
        });
        if compass.is_some() {
            return compass;
        }
        let v = v_enu?;
        (v[0].hypot(v[1]) >= config.init.heading_min_speed_mps).then(|| StartHeading {
            yaw_rad: v[1].atan2(v[0]),
            from_motion: true,
            sigma_rad: None,
            gyrocompass: false,
        })
    }

    /// The attitude at the levelling turned to the start's yaw `q_nb` (by the yaw found
    /// since), and the mean rate at rest; None without a levelling at rest.
    pub(super) fn levelled_at_rest(
        &self,
        q_nb: &UnitQuaternion<f64>,
    ) -> Option<(UnitQuaternion<f64>, Vector3<f64>)> {
        let attitude = self.attitude.as_ref()?;
        let rest = attitude.at_rest?;
        let yaw_offset = q_nb.euler_angles().2 - attitude.q_nb.euler_angles().2;
        let q_rest = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw_offset) * rest.q_level;
        Some((q_rest, rest.mean_w_rad_s))
    }
}
