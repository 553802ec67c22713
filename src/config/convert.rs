//! Human units <-> SI, done once at load time (forward) and for the echo (backward).
//!
//! Forward conversion is always `human * FACTOR`; the backward conversion picks the human
//! value whose forward conversion gives back the very same SI bits, so echoing a loaded
//! configuration and loading the echo reproduces the configuration exactly.

use nalgebra::{UnitQuaternion, Vector3};

use super::raw::{RawClock, RawConfig, RawGnss, RawImu, RawInit, RawMounting, RawOutput};
use super::{ClockConfig, Config, GnssConfig, ImuConfig, InitConfig, MountingConfig, OutputConfig};
use crate::earth::Llh;

/// Standard gravity (m/s²) defining the unit g (and µg) of accelerometer data sheets.
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;
/// 1 degree in radians.
pub const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// 1 deg/h in rad/s.
pub const RAD_S_PER_DEG_H: f64 = RAD_PER_DEG / 3600.0;
/// 1 deg/√h in rad/√s (√h = 60 √s).
pub const RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H: f64 = RAD_PER_DEG / 60.0;
/// 1 µg in m/s²; also 1 µg/√Hz in m/s²/√Hz = m/s/√s (1/√Hz = √s).
pub const M_S2_PER_UG: f64 = STANDARD_GRAVITY_M_S2 * 1e-6;

/// The human value `h` with `h * factor == si`, when one exists next to `si / factor`.
///
/// Math note: fl(fl(h·k)/k) lies within two units in the last place of h, so when `si`
/// came from a forward conversion, one of the five neighbours of `si / factor` tried here
/// converts forward to exactly `si`. For other `si` the plain quotient is returned.
/// Choice: when several neighbours convert to `si`, the one with the shortest decimal
/// form is returned (15 deg stays 15, not 14.999999999999998), since the human value a
/// person typed is the short one.
pub fn si_to_human(si: f64, factor: f64) -> f64 {
    let quotient = si / factor;
    if !quotient.is_finite() || quotient == 0.0 {
        return quotient;
    }
    let bits = quotient.to_bits();
    [0_i64, 1, -1, 2, -2]
        .into_iter()
        .map(|step| f64::from_bits(bits.wrapping_add_signed(step)))
        .filter(|candidate| candidate * factor == si)
        .min_by_key(|candidate| candidate.to_string().len())
        .unwrap_or(quotient)
}

/// Rotation from roll, pitch, yaw (rad) as R = Rz(yaw) · Ry(pitch) · Rx(roll).
fn rotation_from_rpy(rpy_deg: &[f64; 3]) -> UnitQuaternion<f64> {
    let [roll, pitch, yaw] = rpy_deg.map(|deg| deg * RAD_PER_DEG);
    // nalgebra applies roll about x first, then pitch about y, then yaw about z.
    UnitQuaternion::from_euler_angles(roll, pitch, yaw)
}

/// Roll, pitch, yaw (deg) of `q`, rounded to 1e-12 deg.
///
/// Choice: the Euler angles recomputed from a quaternion carry rounding of about 1e-14 deg
/// (20 comes back as 19.999999999999996). Rounding to 1e-12 deg (2e-14 rad, far below any
/// mounting knowledge) gives back the angles as they were written, so the echo reads as
/// the file did and loading it reproduces the same quaternion.
fn rpy_deg_from_rotation(q: &UnitQuaternion<f64>) -> [f64; 3] {
    const STEPS_PER_DEG: f64 = 1e12;
    let (roll, pitch, yaw) = q.euler_angles();
    // `+ 0.0` turns a -0.0 into 0.0 so the echo of the identity reads [0.0, 0.0, 0.0].
    [roll, pitch, yaw].map(|rad| (rad / RAD_PER_DEG * STEPS_PER_DEG).round() / STEPS_PER_DEG + 0.0)
}

impl From<&RawConfig> for Config {
    /// Converts to SI. The conversion cannot fail; validation is a separate step.
    fn from(raw: &RawConfig) -> Self {
        let RawConfig {
            filter,
            imu,
            mounting,
            clock,
            gnss,
            loose,
            adaptive,
            robust,
            init,
            engine,
            output,
        } = raw;
        Config {
            filter: filter.clone(),
            imu: ImuConfig {
                gyro_arw_rad_per_sqrt_s: imu.gyro_arw_deg_per_sqrt_h
                    * RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
                gyro_bias_sigma_rad_s: imu.gyro_bias_deg_per_h * RAD_S_PER_DEG_H,
                gyro_markov_sigma_rad_s: imu.gyro_markov_sigma_deg_per_h * RAD_S_PER_DEG_H,
                gyro_markov_time_s: imu.gyro_markov_correlation_time_s,
                accel_vrw_m_s_per_sqrt_s: imu.accel_vrw_ug_per_sqrt_hz * M_S2_PER_UG,
                accel_bias_sigma_m_s2: imu.accel_bias_ug * M_S2_PER_UG,
                accel_markov_time_s: imu.accel_bias_correlation_time_s,
            },
            mounting: MountingConfig {
                imu_to_body: rotation_from_rpy(&mounting.imu_rotation_rpy_deg),
                lever_arm_b_m: Vector3::from(mounting.antenna_lever_arm_m),
            },
            clock: ClockConfig {
                bias_noise_m_per_sqrt_s: clock.bias_noise_m_per_sqrt_s,
                drift_noise_m_s_per_sqrt_s: clock.drift_noise_mps_per_sqrt_s,
                drift_time_s: clock.drift_correlation_time_s,
            },
            gnss: GnssConfig {
                elevation_mask_rad: gnss.elevation_mask_deg * RAD_PER_DEG,
                cn0_mask_dbhz: gnss.cn0_mask_dbhz,
                pseudorange_sigma_m: gnss.pseudorange_sigma_m,
                pseudorange_rate_sigma_mps: gnss.pseudorange_rate_sigma_mps,
                elevation_weighting: gnss.elevation_weighting,
                use_receiver_sigmas: gnss.use_receiver_sigmas,
                use_pseudorange_rate: gnss.use_pseudorange_rate,
                innovation_gate_sigma: gnss.innovation_gate_sigma,
                constellations: gnss.constellations.iter().map(|&c| c.into()).collect(),
                max_clock_jump_m: gnss.clock_jump_threshold_m,
            },
            loose: loose.clone(),
            adaptive: adaptive.clone(),
            robust: robust.clone(),
            init: InitConfig {
                heading_rad: init.heading_deg.map(|deg| deg * RAD_PER_DEG),
                heading_min_speed_mps: init.heading_min_speed_mps,
                leveling_duration_s: init.leveling_duration_s,
                min_satellites: init.min_satellites,
                attitude_sigma_rad: init.attitude_sigma_deg * RAD_PER_DEG,
                heading_sigma_rad: init.heading_sigma_deg * RAD_PER_DEG,
                velocity_sigma_mps: init.velocity_sigma_mps,
                position_sigma_m: init.position_sigma_m,
                clock_bias_sigma_m: init.clock_bias_sigma_m,
                clock_drift_sigma_mps: init.clock_drift_sigma_mps,
            },
            engine: engine.clone(),
            output: OutputConfig {
                datum: output.datum_llh_deg_m.map(|[lat_deg, lon_deg, height_m]| {
                    Llh::new(lat_deg * RAD_PER_DEG, lon_deg * RAD_PER_DEG, height_m)
                }),
                rate_hz: output.rate_hz,
            },
        }
    }
}

impl From<&Config> for RawConfig {
    /// Converts back to the human units of the parameter file.
    fn from(config: &Config) -> Self {
        let Config {
            filter,
            imu,
            mounting,
            clock,
            gnss,
            loose,
            adaptive,
            robust,
            init,
            engine,
            output,
        } = config;
        let deg = |rad: f64| si_to_human(rad, RAD_PER_DEG);
        RawConfig {
            filter: filter.clone(),
            imu: RawImu {
                gyro_arw_deg_per_sqrt_h: si_to_human(
                    imu.gyro_arw_rad_per_sqrt_s,
                    RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
                ),
                gyro_bias_deg_per_h: si_to_human(imu.gyro_bias_sigma_rad_s, RAD_S_PER_DEG_H),
                gyro_markov_sigma_deg_per_h: si_to_human(
                    imu.gyro_markov_sigma_rad_s,
                    RAD_S_PER_DEG_H,
                ),
                gyro_markov_correlation_time_s: imu.gyro_markov_time_s,
                accel_vrw_ug_per_sqrt_hz: si_to_human(imu.accel_vrw_m_s_per_sqrt_s, M_S2_PER_UG),
                accel_bias_ug: si_to_human(imu.accel_bias_sigma_m_s2, M_S2_PER_UG),
                accel_bias_correlation_time_s: imu.accel_markov_time_s,
            },
            mounting: RawMounting {
                imu_rotation_rpy_deg: rpy_deg_from_rotation(&mounting.imu_to_body),
                antenna_lever_arm_m: mounting.lever_arm_b_m.into(),
            },
            clock: RawClock {
                bias_noise_m_per_sqrt_s: clock.bias_noise_m_per_sqrt_s,
                drift_noise_mps_per_sqrt_s: clock.drift_noise_m_s_per_sqrt_s,
                drift_correlation_time_s: clock.drift_time_s,
            },
            gnss: RawGnss {
                elevation_mask_deg: deg(gnss.elevation_mask_rad),
                cn0_mask_dbhz: gnss.cn0_mask_dbhz,
                pseudorange_sigma_m: gnss.pseudorange_sigma_m,
                pseudorange_rate_sigma_mps: gnss.pseudorange_rate_sigma_mps,
                elevation_weighting: gnss.elevation_weighting,
                use_receiver_sigmas: gnss.use_receiver_sigmas,
                use_pseudorange_rate: gnss.use_pseudorange_rate,
                innovation_gate_sigma: gnss.innovation_gate_sigma,
                constellations: gnss.constellations.iter().map(|&c| c.into()).collect(),
                clock_jump_threshold_m: gnss.max_clock_jump_m,
            },
            loose: loose.clone(),
            adaptive: adaptive.clone(),
            robust: robust.clone(),
            init: RawInit {
                heading_deg: init.heading_rad.map(deg),
                heading_min_speed_mps: init.heading_min_speed_mps,
                leveling_duration_s: init.leveling_duration_s,
                min_satellites: init.min_satellites,
                attitude_sigma_deg: deg(init.attitude_sigma_rad),
                heading_sigma_deg: deg(init.heading_sigma_rad),
                velocity_sigma_mps: init.velocity_sigma_mps,
                position_sigma_m: init.position_sigma_m,
                clock_bias_sigma_m: init.clock_bias_sigma_m,
                clock_drift_sigma_mps: init.clock_drift_sigma_mps,
            },
            engine: engine.clone(),
            output: RawOutput {
                datum_llh_deg_m: output
                    .datum
                    .map(|p| [deg(p.lat_rad), deg(p.lon_rad), p.height_m]),
                rate_hz: output.rate_hz,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_factors_match_hand_computed_values() {
        // 1 deg/h = π/180/3600 rad/s = 4.84813681e-6 rad/s.
        assert!((RAD_S_PER_DEG_H - 4.848_136_811_095_36e-6).abs() < 1e-18);
        // 1 deg/√h = π/180/60 rad/√s = 2.90888209e-4 rad/√s.
        assert!((RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H - 2.908_882_086_657_216e-4).abs() < 1e-17);
        // 1 µg = 9.80665e-6 m/s².
        assert!((M_S2_PER_UG - 9.806_65e-6).abs() < 1e-20);
        assert!((RAD_PER_DEG - 0.017_453_292_519_943_295).abs() < 1e-18);
    }

    #[test]
    fn si_to_human_inverts_the_forward_conversion_bit_exactly() {
        let factors = [
            RAD_PER_DEG,
            RAD_S_PER_DEG_H,
            RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
            M_S2_PER_UG,
        ];
        let mut human = 1e-3_f64;
        while human < 1e5 {
            for factor in factors {
                for h in [human, -human] {
                    let si = h * factor;
                    let back = si_to_human(si, factor);
                    assert_eq!(back * factor, si, "h = {h}, factor = {factor}");
                }
            }
            human *= 1.0137;
        }
        assert_eq!(si_to_human(0.0, RAD_PER_DEG), 0.0);
    }

    #[test]
    fn si_to_human_gives_back_the_short_value_typed() {
        for h in [15.0, 12.5, 10.0, 0.3, 95.0] {
            assert_eq!(si_to_human(h * RAD_PER_DEG, RAD_PER_DEG), h);
        }
    }

    #[test]
    fn rotation_follows_z_y_x_order() {
        let rpy_deg = [10.0, -20.0, 30.0];
        let q = rotation_from_rpy(&rpy_deg);
        let [r, p, y] = rpy_deg.map(f64::to_radians);
        let rx = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), r);
        let ry = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), p);
        let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), y);
        let expected = rz * ry * rx;
        let diff = q.to_rotation_matrix().matrix() - expected.matrix();
        assert!(diff.amax() < 1e-15, "{diff}");
        assert_eq!(rpy_deg_from_rotation(&q), rpy_deg);
        let odd = [1.0 / 3.0, -89.0 / 7.0, 179.0 - 1.0 / 9.0];
        let back = rpy_deg_from_rotation(&rotation_from_rpy(&odd));
        for (a, b) in back.iter().zip(odd) {
            assert!((a - b).abs() < 1e-12, "{back:?}");
        }
    }
}
