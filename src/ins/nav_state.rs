use nalgebra::{UnitQuaternion, Vector3};

use crate::earth::Llh;

/// One IMU sample in REP-145 form: angular rate ω_ib (rad/s) and specific force f_ib
/// (m/s², gravity included). The engine receives samples in the IMU's own axes and rotates
/// them into the body frame (FLU) with the configured mounting; from there on the fields
/// hold body-frame vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// Sample time (s) on the engine's time axis.
    pub t_s: f64,
    pub w_ib_b_rad_s: Vector3<f64>,
    pub f_ib_b_m_s2: Vector3<f64>,
}

impl ImuSample {
    pub fn is_finite(&self) -> bool {
        self.t_s.is_finite()
            && self.w_ib_b_rad_s.iter().all(|x| x.is_finite())
            && self.f_ib_b_m_s2.iter().all(|x| x.is_finite())
    }
}

/// The nominal (whole-state) navigation solution the error-state filter corrects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavState {
    /// Time of validity (s) on the engine's time axis.
    pub t_s: f64,
    /// Geodetic position of the IMU.
    pub p: Llh,
    /// Velocity relative to the earth in ENU (m/s): (V_E, V_N, V_U).
    pub v_n: Vector3<f64>,
    /// Attitude: rotation from body (FLU) to navigation (ENU), i.e. C_b^n.
    pub q_nb: UnitQuaternion<f64>,
}

impl NavState {
    pub fn is_finite(&self) -> bool {
        self.t_s.is_finite()
            && self.p.is_finite()
            && self.v_n.iter().all(|x| x.is_finite())
            && self.q_nb.coords.iter().all(|x| x.is_finite())
    }
}
