//! IMU error model for the simulator: turns the true IMU output into what a real IMU of a
//! given grade reports. Per axis, for the gyro (and likewise the accelerometer):
//!
//! ω_meas = (1 + k) ω_true + b + ε_r + n,
//!
//! with k a constant scale-factor error, b a constant bias, ε_r a first-order Gauss-Markov
//! drift (the ERMAKF paper's eqs. 4–5) and n white noise from the angle (velocity) random
//! walk. Every random number comes from a `ChaCha8Rng` seeded by the caller, so the same
//! seed and the same inputs give identical outputs on every platform.

use nalgebra::Vector3;
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::ins::ImuSample;

/// Standard gravity g₀ (m/s²) defining the unit µg (ISO 80000-3).
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;
/// One micro-g in m/s².
const MICRO_G_M_S2: f64 = 1e-6 * STANDARD_GRAVITY_M_S2;
/// One degree per hour in rad/s.
const DEG_PER_H_RAD_S: f64 = std::f64::consts::PI / 180.0 / 3600.0;
/// One degree per √hour in rad/√s (√3600 s = 60 √s).
const DEG_PER_SQRT_H_RAD_PER_SQRT_S: f64 = std::f64::consts::PI / 180.0 / 60.0;

/// IMU error parameters in the units of data sheets. The default is the NovAtel
/// IMU-ISA-100C of the ERMAKF paper's field test (gyro bias 0.5 °/h, ARW 0.012 °/√h,
/// accelerometer bias 1250 µg, VRW 100 µg/√Hz).
///
/// Choices where the paper is silent: the constant biases alternate in sign between axes
/// (+, −, +) so that they do not all push one way; the Gauss-Markov drifts (0.05 °/h and
/// 50 µg, one hour) are a tenth or less of the biases, as for a navigation-grade unit; no
/// scale-factor error by default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImuErrorSpec {
    /// Constant gyro bias per body axis (°/h).
    pub gyro_bias_deg_per_h: [f64; 3],
    /// Constant accelerometer bias per body axis (µg).
    pub accel_bias_ug: [f64; 3],
    /// Steady-state σ of the gyro Gauss-Markov drift (°/h).
    pub gyro_gm_sigma_deg_per_h: f64,
    /// Correlation time of the gyro Gauss-Markov drift (s).
    pub gyro_gm_correlation_time_s: f64,
    /// Steady-state σ of the accelerometer Gauss-Markov drift (µg).
    pub accel_gm_sigma_ug: f64,
    /// Correlation time of the accelerometer Gauss-Markov drift (s).
    pub accel_gm_correlation_time_s: f64,
    /// Gyro angle random walk (°/√h).
    pub gyro_arw_deg_per_sqrt_h: f64,
    /// Accelerometer velocity random walk (µg/√Hz).
    pub accel_vrw_ug_per_sqrt_hz: f64,
    /// Gyro scale-factor error per axis (ppm).
    pub gyro_scale_factor_ppm: [f64; 3],
    /// Accelerometer scale-factor error per axis (ppm).
    pub accel_scale_factor_ppm: [f64; 3],
}

impl Default for ImuErrorSpec {
    fn default() -> Self {
        Self {
            gyro_bias_deg_per_h: [0.5, -0.5, 0.5],
            accel_bias_ug: [1250.0, -1250.0, 1250.0],
            gyro_gm_sigma_deg_per_h: 0.05,
            gyro_gm_correlation_time_s: 3600.0,
            accel_gm_sigma_ug: 50.0,
            accel_gm_correlation_time_s: 3600.0,
            gyro_arw_deg_per_sqrt_h: 0.012,
            accel_vrw_ug_per_sqrt_hz: 100.0,
            gyro_scale_factor_ppm: [0.0; 3],
            accel_scale_factor_ppm: [0.0; 3],
        }
    }
}

impl ImuErrorSpec {
    /// An error-free IMU (the correlation times keep a valid, unused value).
    pub fn perfect() -> Self {
        Self {
            gyro_bias_deg_per_h: [0.0; 3],
            accel_bias_ug: [0.0; 3],
            gyro_gm_sigma_deg_per_h: 0.0,
            gyro_gm_correlation_time_s: 3600.0,
            accel_gm_sigma_ug: 0.0,
            accel_gm_correlation_time_s: 3600.0,
            gyro_arw_deg_per_sqrt_h: 0.0,
            accel_vrw_ug_per_sqrt_hz: 0.0,
            gyro_scale_factor_ppm: [0.0; 3],
            accel_scale_factor_ppm: [0.0; 3],
        }
    }
}

/// Why an IMU error model could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ImuErrorModelError {
    /// A parameter is not finite, or a σ is negative, or a correlation time not positive.
    #[error("invalid IMU error parameter {field}: {value}")]
    InvalidParameter { field: &'static str, value: f64 },
    /// The sample rate is not positive and finite.
    #[error("invalid IMU sample rate {rate_hz} Hz")]
    InvalidRate { rate_hz: f64 },
}

/// One sensor triad's error processes, in SI units.
#[derive(Debug, Clone, PartialEq)]
struct TriadErrors {
    bias: Vector3<f64>,
    scale_factor: Vector3<f64>,
    /// Current Gauss-Markov state.
    gm: Vector3<f64>,
    /// exp(−Δt/T).
    gm_phi: f64,
    /// σ √(1 − φ²), the driving noise per sample.
    gm_drive_sigma: f64,
    /// White noise σ per sample.
    white_sigma: f64,
}

impl TriadErrors {
    fn new(
        bias: Vector3<f64>,
        scale_factor: Vector3<f64>,
        gm_sigma: f64,
        gm_tau_s: f64,
        white_sigma: f64,
        dt_s: f64,
        rng: &mut ChaCha8Rng,
    ) -> Self {
        // Math note: the exact discretisation of ε̇ = −ε/T + w over Δt is
        // ε_{k+1} = e^{−Δt/T} ε_k + σ √(1 − e^{−2Δt/T}) ξ_k, ξ ~ N(0, 1), which keeps the
        // steady-state σ for any Δt; starting from N(0, σ²) makes the process stationary.
        let gm_phi = (-dt_s / gm_tau_s).exp();
        let gm = gm_sigma * standard_normal_vector(rng);
        Self {
            bias,
            scale_factor,
            gm,
            gm_phi,
            gm_drive_sigma: gm_sigma * (1.0 - gm_phi * gm_phi).max(0.0).sqrt(),
            white_sigma,
        }
    }

    /// The measured value for the true `x`, then the Gauss-Markov state moves one sample on.
    fn corrupt(&mut self, x: &Vector3<f64>, rng: &mut ChaCha8Rng) -> Vector3<f64> {
        let white = self.white_sigma * standard_normal_vector(rng);
        let out = x + self.scale_factor.component_mul(x) + self.bias + self.gm + white;
        self.gm = self.gm_phi * self.gm + self.gm_drive_sigma * standard_normal_vector(rng);
        out
    }
}

/// A seeded IMU error generator for one fixed sample rate.
#[derive(Debug, Clone)]
pub struct ImuErrorModel {
    rng: ChaCha8Rng,
    gyro: TriadErrors,
    accel: TriadErrors,
}

impl ImuErrorModel {
    /// Builds the model for samples at `sample_rate_hz`, with all randomness from `seed`.
    ///
    /// Math note: white noise of spectral density N (rad/√s for ARW, m/s/√s for VRW)
    /// sampled at f_s has a per-sample σ = N √f_s, so that the integrated angle (velocity)
    /// random walk grows as N √t whatever the rate.
    pub fn new(
        spec: &ImuErrorSpec,
        sample_rate_hz: f64,
        seed: u64,
    ) -> Result<Self, ImuErrorModelError> {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(ImuErrorModelError::InvalidRate {
                rate_hz: sample_rate_hz,
            });
        }
        validate(spec)?;
        let dt_s = 1.0 / sample_rate_hz;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let gyro = TriadErrors::new(
            Vector3::from(spec.gyro_bias_deg_per_h) * DEG_PER_H_RAD_S,
            Vector3::from(spec.gyro_scale_factor_ppm) * 1e-6,
            spec.gyro_gm_sigma_deg_per_h * DEG_PER_H_RAD_S,
            spec.gyro_gm_correlation_time_s,
            spec.gyro_arw_deg_per_sqrt_h * DEG_PER_SQRT_H_RAD_PER_SQRT_S * sample_rate_hz.sqrt(),
            dt_s,
            &mut rng,
        );
        let accel = TriadErrors::new(
            Vector3::from(spec.accel_bias_ug) * MICRO_G_M_S2,
            Vector3::from(spec.accel_scale_factor_ppm) * 1e-6,
            spec.accel_gm_sigma_ug * MICRO_G_M_S2,
            spec.accel_gm_correlation_time_s,
            spec.accel_vrw_ug_per_sqrt_hz * MICRO_G_M_S2 * sample_rate_hz.sqrt(),
            dt_s,
            &mut rng,
        );
        Ok(Self { rng, gyro, accel })
    }

    /// The measured sample for the true sample `truth` (same time stamp). Call once per
    /// sample, in time order, at the rate the model was built for.
    pub fn corrupt(&mut self, truth: &ImuSample) -> ImuSample {
        ImuSample {
            t_s: truth.t_s,
            w_ib_b_rad_s: self.gyro.corrupt(&truth.w_ib_b_rad_s, &mut self.rng),
            f_ib_b_m_s2: self.accel.corrupt(&truth.f_ib_b_m_s2, &mut self.rng),
        }
    }

    /// Current gyro bias plus Gauss-Markov drift (rad/s): the part a filter can estimate,
    /// as it applies to the next call of [`Self::corrupt`].
    pub fn gyro_error_rad_s(&self) -> Vector3<f64> {
        self.gyro.bias + self.gyro.gm
    }

    /// Current accelerometer bias plus Gauss-Markov drift (m/s²), as for the next sample.
    pub fn accel_error_m_s2(&self) -> Vector3<f64> {
        self.accel.bias + self.accel.gm
    }

    /// Per-sample white-noise σ of the gyro (rad/s) and the accelerometer (m/s²).
    pub fn white_noise_sigma(&self) -> (f64, f64) {
        (self.gyro.white_sigma, self.accel.white_sigma)
    }
}

fn validate(spec: &ImuErrorSpec) -> Result<(), ImuErrorModelError> {
    let triples = [
        ("gyro_bias_deg_per_h", spec.gyro_bias_deg_per_h),
        ("accel_bias_ug", spec.accel_bias_ug),
        ("gyro_scale_factor_ppm", spec.gyro_scale_factor_ppm),
        ("accel_scale_factor_ppm", spec.accel_scale_factor_ppm),
    ];
    for (field, values) in triples {
        if let Some(&value) = values.iter().find(|v| !v.is_finite()) {
            return Err(ImuErrorModelError::InvalidParameter { field, value });
        }
    }
    let sigmas = [
        ("gyro_gm_sigma_deg_per_h", spec.gyro_gm_sigma_deg_per_h),
        ("accel_gm_sigma_ug", spec.accel_gm_sigma_ug),
        ("gyro_arw_deg_per_sqrt_h", spec.gyro_arw_deg_per_sqrt_h),
        ("accel_vrw_ug_per_sqrt_hz", spec.accel_vrw_ug_per_sqrt_hz),
    ];
    for (field, value) in sigmas {
        if !(value.is_finite() && value >= 0.0) {
            return Err(ImuErrorModelError::InvalidParameter { field, value });
        }
    }
    let taus = [
        (
            "gyro_gm_correlation_time_s",
            spec.gyro_gm_correlation_time_s,
        ),
        (
            "accel_gm_correlation_time_s",
            spec.accel_gm_correlation_time_s,
        ),
    ];
    for (field, value) in taus {
        if !(value.is_finite() && value > 0.0) {
            return Err(ImuErrorModelError::InvalidParameter { field, value });
        }
    }
    Ok(())
}

fn standard_normal_vector(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    Vector3::new(
        StandardNormal.sample(rng),
        StandardNormal.sample(rng),
        StandardNormal.sample(rng),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth(t_s: f64) -> ImuSample {
        ImuSample {
            t_s,
            w_ib_b_rad_s: Vector3::new(0.1, -0.2, 0.3),
            f_ib_b_m_s2: Vector3::new(0.5, 0.2, 9.8),
        }
    }

    #[test]
    fn unit_conversions_match_hand_values() {
        // 0.012 °/√h = 0.012 · π/180 / 60 rad/√s = 3.4907e-6 rad/√s; at 100 Hz ×10.
        let m = ImuErrorModel::new(&ImuErrorSpec::default(), 100.0, 1).unwrap();
        let (sg, sa) = m.white_noise_sigma();
        assert!((sg - 3.490_658_5e-5).abs() < 1e-12, "{sg}");
        // 100 µg/√Hz = 9.80665e-4 m/s/√s; at 100 Hz ×10.
        assert!((sa - 9.806_65e-3).abs() < 1e-12, "{sa}");
        // Bias: 0.5 °/h = 2.4241e-6 rad/s; 1250 µg = 0.012258 m/s².
        let spec = ImuErrorSpec {
            gyro_gm_sigma_deg_per_h: 0.0,
            accel_gm_sigma_ug: 0.0,
            ..ImuErrorSpec::default()
        };
        let m = ImuErrorModel::new(&spec, 100.0, 1).unwrap();
        let g = m.gyro_error_rad_s();
        assert!((g - Vector3::new(1.0, -1.0, 1.0) * 2.424_068_405_5e-6).norm() < 1e-15);
        let a = m.accel_error_m_s2();
        assert!((a - Vector3::new(1.0, -1.0, 1.0) * 0.012_258_312_5).norm() < 1e-12);
    }

    #[test]
    fn perfect_imu_is_the_identity() {
        let mut m = ImuErrorModel::new(&ImuErrorSpec::perfect(), 100.0, 9).unwrap();
        for k in 0..10 {
            let t = truth(k as f64 * 0.01);
            assert_eq!(m.corrupt(&t), t);
        }
    }

    #[test]
    fn bias_and_scale_factor_without_noise_are_exact() {
        let spec = ImuErrorSpec {
            gyro_bias_deg_per_h: [3600.0 * 180.0 / std::f64::consts::PI, 0.0, 0.0],
            accel_bias_ug: [0.0, 1e6 / STANDARD_GRAVITY_M_S2, 0.0],
            gyro_scale_factor_ppm: [0.0, 0.0, 1000.0],
            accel_scale_factor_ppm: [-2000.0, 0.0, 0.0],
            ..ImuErrorSpec::perfect()
        };
        let mut m = ImuErrorModel::new(&spec, 100.0, 3).unwrap();
        let out = m.corrupt(&truth(0.0));
        // 1 rad/s on gyro x; 1 m/s² on accel y; +0.1 % on gyro z; −0.2 % on accel x.
        let w = Vector3::new(1.1, -0.2, 0.3 * 1.001);
        let f = Vector3::new(0.5 * 0.998, 1.2, 9.8);
        assert!(
            (out.w_ib_b_rad_s - w).norm() < 1e-12,
            "{}",
            out.w_ib_b_rad_s
        );
        assert!((out.f_ib_b_m_s2 - f).norm() < 1e-12, "{}", out.f_ib_b_m_s2);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let spec = ImuErrorSpec {
            gyro_gm_correlation_time_s: 0.0,
            ..ImuErrorSpec::default()
        };
        assert!(matches!(
            ImuErrorModel::new(&spec, 100.0, 0),
            Err(ImuErrorModelError::InvalidParameter { .. })
        ));
        let spec = ImuErrorSpec {
            accel_vrw_ug_per_sqrt_hz: -1.0,
            ..ImuErrorSpec::default()
        };
        assert!(ImuErrorModel::new(&spec, 100.0, 0).is_err());
        let spec = ImuErrorSpec {
            accel_bias_ug: [0.0, f64::NAN, 0.0],
            ..ImuErrorSpec::default()
        };
        assert!(ImuErrorModel::new(&spec, 100.0, 0).is_err());
        assert!(matches!(
            ImuErrorModel::new(&ImuErrorSpec::default(), 0.0, 0),
            Err(ImuErrorModelError::InvalidRate { .. })
        ));
    }

    #[test]
    fn spec_reads_from_yaml_with_defaults() {
        let s: ImuErrorSpec = serde_yaml::from_str("gyro_arw_deg_per_sqrt_h: 0.1").unwrap();
        assert_eq!(s.gyro_arw_deg_per_sqrt_h, 0.1);
        assert_eq!(s.accel_bias_ug, [1250.0, -1250.0, 1250.0]);
        assert!(serde_yaml::from_str::<ImuErrorSpec>("gyro_arw: 0.1").is_err());
    }
}
