//! Gyrocompassing at rest: the heading from the earth's rotation, for gyros good enough
//! to see it (navigation grade).
//!
//! At rest the gyros measure the earth rate, ω_ie^n = (0, Ω cos L, Ω sin L) in ENU, plus
//! their bias. Resolved in the levelled frame (roll and pitch from the accelerometers, yaw
//! arbitrary), the horizontal part of the mean rate points north: the turn about the
//! vertical that brings it onto north is the levelled frame's heading error.
//!
//! Its 1-sigma is the horizontal rate's error across north over the horizontal earth rate:
//!
//!   σ_ψ² = (σ_b² + σ_m² + ARW²/T + (σ_tilt Ω sin L)²) / (Ω cos L)²   (rad²)
//!
//! with σ_b the turn-on gyro bias (`imu.gyro_bias_deg_per_h`), σ_m the Gauss–Markov drift
//! (`imu.gyro_markov_sigma_deg_per_h`), ARW the angle random walk
//! (`imu.gyro_arw_deg_per_sqrt_h`) averaged over the window of T seconds, and σ_tilt the
//! levelling's roll and pitch σ (`init.attitude_sigma_deg`), which turns part of the
//! vertical earth rate into a horizontal one. Near the poles (cos L → 0) σ_ψ grows
//! without bound and the heading is refused.
//!
//! At rest the horizontal gyro bias across north and the heading are one unknown: a bias
//! b across north turns the heading found by b/(Ω cos L) (0.015 °/h at 30° latitude:
//! 0.07°), and no averaging removes it; only a rotation of the IMU (driving) separates
//! them. The start therefore keeps the class's σ for the horizontal gyro bias (see
//! `initializer`).

use nalgebra::{UnitQuaternion, Vector3};

use crate::config::Config;
use crate::earth::EARTH_RATE_RAD_S;

/// Largest heading 1-sigma a gyrocompass start takes (rad).
///
/// Choice: 1°. Navigation-grade gyros (0.01 °/h, 0.003 °/√h) give 0.15–0.35° at mid
/// latitudes after 10–60 s at rest and tactical ones (1 °/h and worse) 4° and more (the
/// project's defaults, 0.5 °/h over 1 s: 3.8° even at the equator), so 1° separates
/// the classes with a wide margin either side. It is a third of a course start's
/// [`super::initializer`] σ (3°): a gyrocompass heading this good is worth starting at
/// rest for, and a coarser one from a gyro whose class σ may be optimistic is not worth
/// the risk of a confident wrong heading. Above 1°, the start waits for a course as before.
pub const MAX_SIGMA_RAD: f64 = 1.0 * std::f64::consts::PI / 180.0;

/// Largest difference between the horizontal mean rate's magnitude and the horizontal
/// earth rate, in its 1-sigmas, for the gyrocompass to be trusted.
///
/// Choice: 3σ. The magnitude checks the model along north: a platform turning about a
/// horizontal axis (a ship's roll, a sway that does not average out) or a gyro bias
/// beyond its class shows as a horizontal rate the earth does not give, and the heading
/// from it would be wrong by more than its σ says.
pub const MAX_MAGNITUDE_SIGMAS: f64 = 3.0;

/// A heading found by gyrocompassing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gyrocompass {
    /// ENU yaw of the levelled attitude (from East towards North, rad).
    pub yaw_rad: f64,
    /// Its 1-sigma (rad).
    pub sigma_rad: f64,
}

/// The 1-sigma of one horizontal component of the mean rate at rest over `window_s` at
/// latitude `lat_rad` (rad/s): bias, drift, the window's rate noise and the tilt's share
/// of the vertical earth rate (see the module documentation).
pub fn horizontal_rate_sigma_rad_s(config: &Config, window_s: f64, lat_rad: f64) -> f64 {
    let imu = &config.imu;
    let tilt_rad_s = config.init.attitude_sigma_rad * EARTH_RATE_RAD_S * lat_rad.sin();
    (imu.gyro_bias_sigma_rad_s.powi(2)
        + imu.gyro_markov_sigma_rad_s.powi(2)
        + imu.gyro_arw_rad_per_sqrt_s.powi(2) / window_s.max(f64::MIN_POSITIVE)
        + tilt_rad_s.powi(2))
    .sqrt()
}

/// The heading of the levelled attitude `q_level` (its yaw arbitrary) from the mean rate
/// `mean_w_b_rad_s` over `window_s` at rest, at latitude `lat_rad`; None when its σ
/// exceeds [`MAX_SIGMA_RAD`] or the rate is not the earth's ([`MAX_MAGNITUDE_SIGMAS`]).
pub fn gyrocompass(
    q_level: &UnitQuaternion<f64>,
    mean_w_b_rad_s: &Vector3<f64>,
    window_s: f64,
    lat_rad: f64,
    config: &Config,
) -> Option<Gyrocompass> {
    let horizontal_earth_rad_s = EARTH_RATE_RAD_S * lat_rad.cos();
    let rate_sigma_rad_s = horizontal_rate_sigma_rad_s(config, window_s, lat_rad);
    let sigma_rad = rate_sigma_rad_s / horizontal_earth_rad_s;
    // Also refuses a NaN and a latitude beyond the pole (cos L ≤ 0).
    if !(horizontal_earth_rad_s > 0.0 && sigma_rad <= MAX_SIGMA_RAD) {
        return None;
    }
    let h = (q_level * mean_w_b_rad_s).xy();
    if (h.norm() - horizontal_earth_rad_s).abs() > MAX_MAGNITUDE_SIGMAS * rate_sigma_rad_s {
        return None;
    }
    // North lies at the angle atan2(h_y, h_x) in the levelled frame and at π/2 in ENU: the
    // frame turns by the difference about the vertical, and its yaw with it.
    let turn_rad = std::f64::consts::FRAC_PI_2 - h[1].atan2(h[0]);
    let yaw = q_level.euler_angles().2 + turn_rad;
    Some(Gyrocompass {
        yaw_rad: yaw.sin().atan2(yaw.cos()),
        sigma_rad,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth;

    const RAD_S_PER_DEG_H: f64 = std::f64::consts::PI / 180.0 / 3600.0;

    /// The navigation-grade class of params/imu_navigation_grade.yaml.
    fn navigation_grade() -> Config {
        let mut config = Config::default();
        config.imu.gyro_bias_sigma_rad_s = 0.01 * RAD_S_PER_DEG_H;
        config.imu.gyro_markov_sigma_rad_s = 0.005 * RAD_S_PER_DEG_H;
        config.imu.gyro_arw_rad_per_sqrt_s = 0.003 * RAD_S_PER_DEG_H * 60.0;
        config.init.attitude_sigma_rad = 0.05_f64.to_radians();
        config
    }

    /// The mean body rate at rest with attitude `q_nb`, body-frame bias `bias_b_rad_s`.
    fn rate_at_rest(
        q_nb: &UnitQuaternion<f64>,
        lat_rad: f64,
        bias_b_rad_s: Vector3<f64>,
    ) -> Vector3<f64> {
        q_nb.inverse() * earth::earth_rate_enu_rad_s(lat_rad) + bias_b_rad_s
    }

    fn wrapped(a: f64) -> f64 {
        a.sin().atan2(a.cos())
    }

    #[test]
    fn finds_the_heading_to_the_bias_across_north_over_the_horizontal_earth_rate() {
        let config = navigation_grade();
        let window_s = 10.0;
        for lat_deg in [-60.0, 0.0, 30.4, 47.4, 70.0] {
            let lat = f64::to_radians(lat_deg);
            for yaw_deg in [-175.7_f64, -95.7, 0.0, 30.0, 120.0] {
                let (roll, pitch) = (0.02, -0.03);
                let q_nb = UnitQuaternion::from_euler_angles(roll, pitch, yaw_deg.to_radians());
                // Biases at the class's σ per axis, the vertical one larger.
                let bias_b = Vector3::new(0.01, -0.01, 0.05) * RAD_S_PER_DEG_H;
                let w = rate_at_rest(&q_nb, lat, bias_b);
                let q_level = UnitQuaternion::from_euler_angles(roll, pitch, 1.0);
                let found = gyrocompass(&q_level, &w, window_s, lat, &config)
                    .unwrap_or_else(|| panic!("refused at {lat_deg}°, yaw {yaw_deg}°"));
                let error_rad = wrapped(found.yaw_rad - yaw_deg.to_radians());
                // The ENU yaw error is the bias's east component over Ω cos L.
                let bias_east_rad_s = (q_nb * bias_b)[0];
                let predicted_rad = bias_east_rad_s / (EARTH_RATE_RAD_S * lat.cos());
                assert!(
                    (error_rad - predicted_rad).abs() < 0.02 * predicted_rad.abs() + 1e-7,
                    "{lat_deg}°, yaw {yaw_deg}°: error {error_rad:e} rad, predicted {predicted_rad:e}"
                );
                assert!(error_rad.abs() <= 3.0 * found.sigma_rad);
            }
        }
    }

    #[test]
    fn states_the_sigma_of_its_formula() {
        let config = navigation_grade();
        let lat = 30.4_f64.to_radians();
        let q = UnitQuaternion::identity();
        let w = rate_at_rest(&q, lat, Vector3::zeros());
        let found = gyrocompass(&q, &w, 10.0, lat, &config).unwrap();
        // (0.01² + 0.005² + (0.003 · 60 / √10)² + (0.05° · 15.04 sin L)²)^½ °/h over
        // 15.04 cos L °/h.
        let rate_deg_h: f64 = (0.01f64.powi(2)
            + 0.005f64.powi(2)
            + (0.003 * 60.0 / 10f64.sqrt()).powi(2)
            + (0.05f64.to_radians() * 15.041_07 * lat.sin()).powi(2))
        .sqrt();
        let expected_rad = rate_deg_h / (15.041_07 * lat.cos());
        assert!((found.sigma_rad - expected_rad).abs() < 1e-3 * expected_rad);
        // The body's x axis east: ENU yaw 0.
        assert!(found.yaw_rad.abs() < 1e-12, "yaw {}", found.yaw_rad);
    }

    #[test]
    fn refuses_a_tactical_gyro_the_poles_and_a_rate_the_earth_does_not_give() {
        let lat = 47.4_f64.to_radians();
        let q = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3);
        let w = rate_at_rest(&q, lat, Vector3::zeros());
        let level = UnitQuaternion::identity();
        // A tactical gyro (1 °/h, 0.1 °/√h): σ of several degrees, even over a minute.
        let mut tactical = navigation_grade();
        tactical.imu.gyro_bias_sigma_rad_s = RAD_S_PER_DEG_H;
        tactical.imu.gyro_arw_rad_per_sqrt_s = 0.1 * RAD_S_PER_DEG_H * 60.0;
        assert_eq!(gyrocompass(&level, &w, 60.0, lat, &tactical), None);
        // The project's defaults (0.5 °/h) over their 1 s levelling, at the equator.
        let w0 = rate_at_rest(&q, 0.0, Vector3::zeros());
        assert_eq!(gyrocompass(&level, &w0, 1.0, 0.0, &Config::default()), None);
        let nav = navigation_grade();
        assert!(gyrocompass(&level, &w0, 1.0, 0.0, &nav).is_some());
        // Near the pole the horizontal earth rate vanishes.
        let polar = 89.9_f64.to_radians();
        let wp = rate_at_rest(&q, polar, Vector3::zeros());
        assert_eq!(gyrocompass(&level, &wp, 10.0, polar, &nav), None);
        // A horizontal bias of 0.3 °/h along north: the magnitude is not the earth's.
        let along_north = q.inverse() * Vector3::new(0.0, 0.3 * RAD_S_PER_DEG_H, 0.0);
        let wb = rate_at_rest(&q, lat, along_north);
        assert_eq!(gyrocompass(&level, &wb, 10.0, lat, &nav), None);
        assert!(gyrocompass(&level, &w, 10.0, lat, &nav).is_some());
    }
}
