//! The running filter: nominal state, sensor and clock error estimates, covariance; the
//! IMU propagation step and the closed-loop feedback of an error-state estimate.

use std::sync::Arc;

use nalgebra::{UnitQuaternion, Vector3};

use crate::filter::process_model::{self, LinearizationPoint, ProcessNoise};
use crate::ins::error_state::{
    StateMatrix, StateVector, ACC_BIAS, ACC_SCALE, CLOCK_BIAS, CLOCK_DRIFT, DP, DV, GYRO_BIAS,
    GYRO_GM, GYRO_SCALE, PHI, WHEEL_SCALE,
};
use crate::ins::mechanization::{self, ImuIncrement, MechanizationError};
use crate::ins::{ImuSample, NavState};

use super::output::Solution;
use super::phase_anchor::PhaseAnchor;

/// Filter state between IMU samples.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterState {
    pub nav: NavState,
    /// Gyro constant bias estimate ε_b (rad/s).
    pub gyro_bias_rad_s: Vector3<f64>,
    /// Gyro Gauss-Markov drift estimate ε_r (rad/s).
    pub gyro_markov_rad_s: Vector3<f64>,
    /// Accelerometer Gauss-Markov bias estimate ∇ (m/s²).
    pub accel_bias_m_s2: Vector3<f64>,
    pub clock_bias_m: f64,
    pub clock_drift_mps: f64,
    /// Wheel odometry scale factor: true forward speed per reported one (1 = exact).
    pub wheel_scale_factor: f64,
    /// Gyro scale-factor error s_g per axis (ω_meas = (1 + s_g) ω + bias).
    pub gyro_scale_error: Vector3<f64>,
    /// Accelerometer scale-factor error s_a per axis (f_meas = (1 + s_a) f + bias).
    pub accel_scale_error: Vector3<f64>,
    pub p: StateMatrix,
    /// The previous IMU increment (for the coning and sculling corrections).
    pub prev_increment: Option<ImuIncrement>,
    /// The last body-frame IMU sample the state was propagated to (raw, uncompensated).
    pub last_imu: ImuSample,
    /// The carrier phases of the last GNSS epoch (time-differenced carrier phase only).
    pub phase_anchor: Option<Arc<PhaseAnchor>>,
}

impl FilterState {
    /// Removes the estimated sensor errors from a raw body-frame sample:
    /// (raw − bias) / (1 + scale error), per axis.
    pub fn compensate(&self, raw: &ImuSample) -> ImuSample {
        let unscale = |x: Vector3<f64>, s: &Vector3<f64>| x.component_div(&s.add_scalar(1.0));
        ImuSample {
            t_s: raw.t_s,
            w_ib_b_rad_s: unscale(
                raw.w_ib_b_rad_s - self.gyro_bias_rad_s - self.gyro_markov_rad_s,
                &self.gyro_scale_error,
            ),
            f_ib_b_m_s2: unscale(
                raw.f_ib_b_m_s2 - self.accel_bias_m_s2,
                &self.accel_scale_error,
            ),
        }
    }

    /// Propagates the nominal state and the covariance to the raw sample `next`.
    pub fn propagate(
        &mut self,
        next: &ImuSample,
        noise: &ProcessNoise,
    ) -> Result<(), MechanizationError> {
        let prev = self.compensate(&self.last_imu);
        let cur = self.compensate(next);
        let increment = ImuIncrement::from_samples(&prev, &cur)?;
        let dt = increment.dt_s;
        let nav = mechanization::integrate(&self.nav, self.prev_increment.as_ref(), &increment)?;
        // Linearize at the start of the interval with the interval's mean specific force.
        let lin = LinearizationPoint {
            nav: self.nav,
            f_ib_b_m_s2: increment.dv_b_m_s / dt,
            w_ib_b_rad_s: increment.dtheta_b_rad / dt,
        };
        let f = process_model::system_matrix(&lin, noise);
        let q_c = process_model::noise_density(noise);
        self.p = process_model::propagate_covariance(&f, &q_c, &self.p, dt);
        self.nav = nav;
        // The nominal Gauss-Markov and clock states follow their expected dynamics.
        self.gyro_markov_rad_s *= (-dt / noise.gyro_markov_time_s).exp();
        self.accel_bias_m_s2 *= (-dt / noise.accel_markov_time_s).exp();
        if let Some(clock) = noise.clock {
            self.clock_bias_m += self.clock_drift_mps * dt;
            self.clock_drift_mps *= (-dt / clock.drift_time_s).exp();
        }
        if let Some(scale) = noise.imu_scale {
            let decay = (-dt / scale.time_s).exp();
            self.gyro_scale_error *= decay;
            self.accel_scale_error *= decay;
        }
        self.prev_increment = Some(increment);
        self.last_imu = *next;
        Ok(())
    }

    /// Closed-loop feedback of the error estimate δx̂ (see [`crate::ins::error_state`] for
    /// the sign conventions); afterwards the error state is zero again.
    ///
    /// Math note: the reset Jacobian of the attitude error, I − ½[δφ×], differs from the
    /// identity by the size of the correction (milliradians); it is neglected, as usual.
    pub fn apply_correction(&mut self, dx: &StateVector) {
        let phi = Vector3::new(dx[PHI], dx[PHI + 1], dx[PHI + 2]);
        self.nav.q_nb = UnitQuaternion::from_scaled_axis(phi) * self.nav.q_nb;
        self.nav.v_n -= dx.fixed_rows::<3>(DV);
        self.nav.p.lat_rad -= dx[DP];
        self.nav.p.lon_rad -= dx[DP + 1];
        self.nav.p.height_m -= dx[DP + 2];
        self.gyro_bias_rad_s += dx.fixed_rows::<3>(GYRO_BIAS);
        self.gyro_markov_rad_s += dx.fixed_rows::<3>(GYRO_GM);
        self.accel_bias_m_s2 += dx.fixed_rows::<3>(ACC_BIAS);
        self.clock_bias_m -= dx[CLOCK_BIAS];
        self.clock_drift_mps -= dx[CLOCK_DRIFT];
        self.wheel_scale_factor += dx[WHEEL_SCALE];
        self.gyro_scale_error += dx.fixed_rows::<3>(GYRO_SCALE);
        self.accel_scale_error += dx.fixed_rows::<3>(ACC_SCALE);
    }

    /// The error state δx that [`Self::apply_correction`] would take from `self` to
    /// `corrected` (its inverse): the difference of two nominal states in the error state's
    /// coordinates and sign conventions.
    pub fn error_towards(&self, corrected: &Self) -> StateVector {
        let mut dx = StateVector::zeros();
        let phi = (corrected.nav.q_nb * self.nav.q_nb.inverse()).scaled_axis();
        dx.fixed_rows_mut::<3>(PHI).copy_from(&phi);
        dx.fixed_rows_mut::<3>(DV)
            .copy_from(&(self.nav.v_n - corrected.nav.v_n));
        dx[DP] = self.nav.p.lat_rad - corrected.nav.p.lat_rad;
        dx[DP + 1] = self.nav.p.lon_rad - corrected.nav.p.lon_rad;
        dx[DP + 2] = self.nav.p.height_m - corrected.nav.p.height_m;
        dx.fixed_rows_mut::<3>(GYRO_BIAS)
            .copy_from(&(corrected.gyro_bias_rad_s - self.gyro_bias_rad_s));
        dx.fixed_rows_mut::<3>(GYRO_GM)
            .copy_from(&(corrected.gyro_markov_rad_s - self.gyro_markov_rad_s));
        dx.fixed_rows_mut::<3>(ACC_BIAS)
            .copy_from(&(corrected.accel_bias_m_s2 - self.accel_bias_m_s2));
        dx[CLOCK_BIAS] = self.clock_bias_m - corrected.clock_bias_m;
        dx[CLOCK_DRIFT] = self.clock_drift_mps - corrected.clock_drift_mps;
        dx[WHEEL_SCALE] = corrected.wheel_scale_factor - self.wheel_scale_factor;
        dx.fixed_rows_mut::<3>(GYRO_SCALE)
            .copy_from(&(corrected.gyro_scale_error - self.gyro_scale_error));
        dx.fixed_rows_mut::<3>(ACC_SCALE)
            .copy_from(&(corrected.accel_scale_error - self.accel_scale_error));
        dx
    }

    /// True when every number of the state is finite.
    pub fn is_finite(&self) -> bool {
        self.nav.is_finite()
            && self.gyro_bias_rad_s.iter().all(|v| v.is_finite())
            && self.gyro_markov_rad_s.iter().all(|v| v.is_finite())
            && self.accel_bias_m_s2.iter().all(|v| v.is_finite())
            && self.clock_bias_m.is_finite()
            && self.clock_drift_mps.is_finite()
            && self.wheel_scale_factor.is_finite()
            && self.gyro_scale_error.iter().all(|v| v.is_finite())
            && self.accel_scale_error.iter().all(|v| v.is_finite())
            && self.p.iter().all(|v| v.is_finite())
    }

    /// The solution at the current time.
    pub fn solution(&self) -> Solution {
        let compensated = self.compensate(&self.last_imu);
        Solution {
            nav: self.nav,
            covariance: self.p,
            gyro_bias_rad_s: self.gyro_bias_rad_s + self.gyro_markov_rad_s,
            accel_bias_m_s2: self.accel_bias_m_s2,
            clock_bias_m: self.clock_bias_m,
            clock_drift_mps: self.clock_drift_mps,
            angular_rate_b_rad_s: compensated.w_ib_b_rad_s,
        }
    }
}

/// Linear interpolation of two IMU samples at `t_s` (within [a.t_s, b.t_s]).
pub fn interpolate(a: &ImuSample, b: &ImuSample, t_s: f64) -> ImuSample {
    let span = b.t_s - a.t_s;
    let w = if span > 0.0 {
        ((t_s - a.t_s) / span).clamp(0.0, 1.0)
    } else {
        1.0
    };
    ImuSample {
        t_s,
        w_ib_b_rad_s: a.w_ib_b_rad_s.lerp(&b.w_ib_b_rad_s, w),
        f_ib_b_m_s2: a.f_ib_b_m_s2.lerp(&b.f_ib_b_m_s2, w),
    }
}

#[cfg(test)]
impl FilterState {
    /// A level state at 39.1° N moving slowly, with the covariance `p_diagonal` × I (for
    /// tests).
    pub(crate) fn moving(p_diagonal: f64) -> Self {
        let imu = ImuSample {
            t_s: 0.0,
            w_ib_b_rad_s: Vector3::zeros(),
            f_ib_b_m_s2: Vector3::new(0.0, 0.0, 9.8),
        };
        Self {
            nav: NavState {
                t_s: 0.0,
                p: crate::earth::Llh::from_degrees(39.1, 117.2, 20.0),
                v_n: Vector3::new(0.5, -0.2, 0.1),
                q_nb: UnitQuaternion::identity(),
            },
            gyro_bias_rad_s: Vector3::zeros(),
            gyro_markov_rad_s: Vector3::zeros(),
            accel_bias_m_s2: Vector3::zeros(),
            clock_bias_m: 0.0,
            clock_drift_mps: 0.0,
            wheel_scale_factor: 1.0,
            gyro_scale_error: Vector3::zeros(),
            accel_scale_error: Vector3::zeros(),
            p: StateMatrix::identity() * p_diagonal,
            prev_increment: None,
            last_imu: imu,
            phase_anchor: None,
        }
    }
}
