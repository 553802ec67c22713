//! The filter's first state and covariance from an alignment: the position moved from the
//! antenna to the IMU, the configured and measured 1-sigmas, and the gyro bias measured at
//! rest weighed against the IMU class's prior.

use nalgebra::{Matrix3, Vector3};

use crate::config::{Config, Coupling};
use crate::earth::{self, Llh};
use crate::ins::error_state::{
    StateMatrix, ACC_BIAS, ACC_SCALE, CLOCK_BIAS, CLOCK_DRIFT, DP, DV, GYRO_BIAS, GYRO_GM,
    GYRO_SCALE, PHI, WHEEL_SCALE,
};
use crate::ins::NavState;

use super::{Alignment, InitialState, Initializer, Rest};

/// 1-sigma of the normal gravity model's magnitude against the true gravity (m/s²).
///
/// Choice: 1 mm/s² (100 mGal). The model (Somigliana with the free-air correction) leaves
/// out the gravity anomaly, which is tens of mGal over most land and reaches a few
/// hundred only in high mountains; 100 mGal covers the common case with room to spare.
const NORMAL_GRAVITY_SIGMA_M_S2: f64 = 1.0e-3;

/// The accelerometer bias measured by a levelling window at rest, and its covariance.
///
/// At rest the mean specific force is gravity's reaction, of magnitude γ, plus the bias b:
/// its magnitude less the normal gravity γ(p) measures uᵀb, the bias along the window's
/// mean specific force u (the body's up, for any tilt; the bias across it tilts the
/// levelling instead and stays unseen). That scalar is weighed against the class's prior
/// (zero, σ_p² I) as one Kalman update: b = σ_p² u m / (σ_p² + σ_m²) and
/// P = σ_p² I − σ_p⁴ u uᵀ / (σ_p² + σ_m²). Its σ_m² holds the velocity random walk's mean
/// over the window, the bias's Gauss–Markov drift from the window to the start at `t_s`
/// (which the filter's propagation, from the start on, does not see), the gravity model's
/// error ([`NORMAL_GRAVITY_SIGMA_M_S2`]) and, when the scale factors are states of their
/// own, the scale factor's share of the magnitude (without them the bias state takes that
/// share, as it does in motion, where the vertical specific force stays near γ).
///
/// Choice: without it the filter started with the class's σ on the vertical bias (1250 µg
/// for the defaults' tactical grade) and then learnt it from the GNSS while moving. On
/// the default drive the rates' correlated errors in the foliage moved it 1740 µg off (3σ)
/// within 20 s, and the height 16 m at a σ of 2.6 m (docs/results.md).
fn accel_bias_along_gravity(
    rest: &Rest,
    t_s: f64,
    p: &Llh,
    config: &Config,
) -> (Vector3<f64>, Matrix3<f64>) {
    let f = rest.mean_f_m_s2;
    let u = f.normalize();
    let misfit_m_s2 = f.norm() - earth::normal_gravity_m_s2(p.lat_rad, p.height_m);
    let imu = &config.imu;
    let prior_var = imu.accel_bias_sigma_m_s2.powi(2);
    let scale_var = if imu.scale_factor_states {
        (imu.accel_scale_factor_sigma * f.norm()).powi(2)
    } else {
        0.0
    };
    let measured_var = imu.accel_vrw_m_s_per_sqrt_s.powi(2) / rest.window_s
        + prior_var
            * (1.0 - (-2.0 * (t_s - rest.t_end_s).max(0.0) / imu.accel_markov_time_s).exp())
        + NORMAL_GRAVITY_SIGMA_M_S2.powi(2)
        + scale_var;
    let gain = prior_var / (prior_var + measured_var);
    let bias = u * (gain * misfit_m_s2);
    let cov = Matrix3::identity() * prior_var - u * u.transpose() * (gain * prior_var);
    (bias, cov)
}

impl Initializer {
    pub(super) fn initial_state(
        &self,
        t_s: f64,
        antenna: &Llh,
        v_enu: Vector3<f64>,
        alignment: &Alignment,
        config: &Config,
        position_var_enu_m2: Vector3<f64>,
    ) -> InitialState {
        let q_nb = alignment.q_nb;
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
        let set3 = |cov: &mut StateMatrix, start: usize, v: [f64; 3]| {
            for (k, value) in v.iter().enumerate() {
                cov[(start + k, start + k)] = *value;
            }
        };
        set3(&mut cov, PHI, alignment.sigma_rad.map(|s| s.powi(2)));
        let vel = alignment.velocity_sigma_mps.powi(2);
        set3(&mut cov, DV, [vel, vel, vel]);
        let [east_m2, north_m2, up_m2] = position_var_enu_m2.into();
        let (north, east) = earth::metres_per_radian(&p);
        set3(
            &mut cov,
            DP,
            [north_m2 / (north * north), east_m2 / (east * east), up_m2],
        );
        // Choice: a bias measured at rest (the levelling window's mean rate less the earth
        // rate) holds the rate noise's mean over the window and the in-run drift, σ_m; it
        // is weighed, per axis, against the class's turn-on prior (zero, σ_p): the start
        // keeps σ_p²/(σ_p² + σ_m²) of it, with σ² = σ_p² σ_m²/(σ_p² + σ_m²). Taking all
        // of it with min(σ_p, σ_m), as before, was over-confident where the window is
        // short against the rate noise: a claimed 0.5 °/h for an error of 0.88 °/h with
        // the defaults' 1 s, 0.01 °/h for 0.057 °/h with navigation grade over 10 s.
        // The window's length is the one measured, which the gyrocompass uses too.
        let levelled_s = self
            .attitude
            .as_ref()
            .and_then(|a| a.at_rest.map(|rest| rest.window_s));
        let turn_on_sigma_rad_s = self.turn_on_gyro_bias_sigma_rad_s(config);
        let (gb, measured_weight) = levelled_s.map_or((turn_on_sigma_rad_s, 0.0), |t| {
            let measured_var = config.imu.gyro_arw_rad_per_sqrt_s.powi(2) / t
                + config.imu.gyro_markov_sigma_rad_s.powi(2);
            let prior_var = turn_on_sigma_rad_s.powi(2);
            let weight = prior_var / (prior_var + measured_var);
            ((weight * measured_var).sqrt(), weight)
        });
        let gb = gb.powi(2);
        set3(&mut cov, GYRO_BIAS, [gb, gb, gb]);
        let q_rest = self.levelled_at_rest(&q_nb);
        if let Some((q_rest, _)) = q_rest.filter(|_| alignment.gyrocompass) {
            // Choice: after a gyrocompass the horizontal bias keeps the class's turn-on σ
            // (resolved in the levelled frame): its part across north is the heading's
            // error (inseparable at rest, see [`super::super::gyrocompass`]), and its part along
            // north, which the mean rate's magnitude less Ω cos L measures, is left to the
            // filter, since over a few seconds that measurement (the rate noise's mean) is
            // coarser than a navigation-grade class's σ. The vertical one is as above.
            let horizontal = turn_on_sigma_rad_s.powi(2);
            let c_nb = q_rest.to_rotation_matrix().into_inner();
            let p_n = Matrix3::from_diagonal(&Vector3::new(horizontal, horizontal, gb));
            cov.fixed_view_mut::<3, 3>(GYRO_BIAS, GYRO_BIAS)
                .copy_from(&(c_nb.transpose() * p_n * c_nb));
        }
        let gm = config.imu.gyro_markov_sigma_rad_s.powi(2);
        set3(&mut cov, GYRO_GM, [gm, gm, gm]);
        let ab = config.imu.accel_bias_sigma_m_s2.powi(2);
        set3(&mut cov, ACC_BIAS, [ab, ab, ab]);
        let accel_bias_m_s2 = match self.attitude.as_ref().and_then(|a| a.at_rest) {
            Some(rest) => {
                let (bias, bias_cov) = accel_bias_along_gravity(&rest, t_s, &p, config);
                cov.fixed_view_mut::<3, 3>(ACC_BIAS, ACC_BIAS)
                    .copy_from(&bias_cov);
                bias
            }
            None => Vector3::zeros(),
        };
        // Loosely coupled the clock is inert (`super::super::process_noise`).
        if config.filter.coupling == Coupling::Tight {
            cov[(CLOCK_BIAS, CLOCK_BIAS)] = i.clock_bias_sigma_m.powi(2);
            cov[(CLOCK_DRIFT, CLOCK_DRIFT)] = i.clock_drift_sigma_mps.powi(2);
        }
        // The optional scale factors: inert (zero variance) when off.
        if config.wheel_odometry.scale_factor_state {
            cov[(WHEEL_SCALE, WHEEL_SCALE)] = config.wheel_odometry.scale_factor_sigma.powi(2);
        }
        if config.imu.scale_factor_states {
            let (g, a) = (
                config.imu.gyro_scale_factor_sigma.powi(2),
                config.imu.accel_scale_factor_sigma.powi(2),
            );
            set3(&mut cov, GYRO_SCALE, [g, g, g]);
            set3(&mut cov, ACC_SCALE, [a, a, a]);
        }
        // The bias at rest is the mean rate less the earth rate seen in the body frame,
        // which needs the heading: the levelled attitude turned by the yaw found since
        // (after a gyrocompass only its vertical part: the horizontal one is zero, above),
        // weighed against the prior as above. An alignment in motion has no bias (zero,
        // with the class's σ above).
        let gyro_bias_rad_s = match (&self.attitude, q_rest) {
            (None, _) => Vector3::zeros(),
            (Some(attitude), None) => attitude.gyro_bias_rad_s,
            (Some(_), Some((q_rest, w_rest))) => {
                let earth_n = earth::earth_rate_enu_rad_s(p.lat_rad);
                let measured = if alignment.gyrocompass {
                    let vertical = (q_rest * w_rest)[2] - earth_n[2];
                    q_rest.inverse() * Vector3::new(0.0, 0.0, vertical)
                } else {
                    w_rest - q_rest.inverse() * earth_n
                };
                measured * measured_weight
            }
        };
        InitialState {
            nav,
            gyro_bias_rad_s,
            accel_bias_m_s2,
            clock_bias_m: 0.0,
            clock_drift_mps: 0.0,
            p: cov,
            heading_from_motion: false,
            heading_sigma_rad: alignment.sigma_rad[2],
        }
    }
}
