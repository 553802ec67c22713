//! The configuration exactly as written in the parameter file: human units in the key names,
//! every key optional (a missing key takes its documented default), unknown keys refused.
//!
//! Sections whose keys carry no unit to convert (`filter`, `loose`, `adaptive`, `robust`,
//! `engine`) are read straight into their SI section types; the others have a raw type here.
//!
//! The defaults here are THE documented defaults: `params/ekf.yaml` is tested to equal them.

use serde::Deserialize;

use super::{
    AdaptiveConfig, AdaptiveFactorKind, Coupling, EngineConfig, EquivalentWeightKind, FilterBase,
    FilterConfig, FilterVariant, LooseConfig, RobustConfig,
};
use crate::adaptive::burg::OrderCriterion;
use crate::gnss::Constellation;

/// The whole parameter file below `ros__parameters:`, in human units.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawConfig {
    pub filter: FilterConfig,
    pub imu: RawImu,
    pub mounting: RawMounting,
    pub clock: RawClock,
    pub gnss: RawGnss,
    pub loose: LooseConfig,
    pub adaptive: AdaptiveConfig,
    pub robust: RobustConfig,
    pub init: RawInit,
    pub engine: EngineConfig,
    pub output: RawOutput,
}

/// The documented defaults of `filter.*`.
impl Default for FilterConfig {
    fn default() -> Self {
        Self {
            variant: FilterVariant::Ekf,
            coupling: Coupling::Tight,
            joseph_form: true,
            base: FilterBase::Auto,
            q_scaling: false,
        }
    }
}

/// `imu.*`: inertial sensor noise, in data-sheet units.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawImu {
    pub gyro_arw_deg_per_sqrt_h: f64,
    pub gyro_bias_deg_per_h: f64,
    pub gyro_markov_sigma_deg_per_h: f64,
    pub gyro_markov_correlation_time_s: f64,
    pub accel_vrw_ug_per_sqrt_hz: f64,
    pub accel_bias_ug: f64,
    pub accel_bias_correlation_time_s: f64,
}

impl Default for RawImu {
    fn default() -> Self {
        Self {
            gyro_arw_deg_per_sqrt_h: 0.012,
            gyro_bias_deg_per_h: 0.5,
            gyro_markov_sigma_deg_per_h: 0.5,
            gyro_markov_correlation_time_s: 3600.0,
            accel_vrw_ug_per_sqrt_hz: 100.0,
            accel_bias_ug: 1250.0,
            accel_bias_correlation_time_s: 3600.0,
        }
    }
}

/// `mounting.*`: IMU orientation and antenna lever arm.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawMounting {
    pub imu_rotation_rpy_deg: [f64; 3],
    pub antenna_lever_arm_m: [f64; 3],
}

/// `clock.*`: receiver clock model (bias and drift in metres).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawClock {
    pub bias_noise_m_per_sqrt_s: f64,
    pub drift_noise_mps_per_sqrt_s: f64,
    pub drift_correlation_time_s: f64,
}

impl Default for RawClock {
    fn default() -> Self {
        Self {
            bias_noise_m_per_sqrt_s: 0.1,
            drift_noise_mps_per_sqrt_s: 0.2,
            drift_correlation_time_s: 1800.0,
        }
    }
}

/// `gnss.*`: raw measurement selection and weighting (tight coupling).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawGnss {
    pub elevation_mask_deg: f64,
    pub cn0_mask_dbhz: f64,
    pub pseudorange_sigma_m: f64,
    pub pseudorange_rate_sigma_mps: f64,
    pub elevation_weighting: bool,
    pub use_receiver_sigmas: bool,
    pub use_pseudorange_rate: bool,
    pub innovation_gate_sigma: f64,
    pub constellations: Vec<ConstellationName>,
    pub clock_jump_threshold_m: f64,
}

impl Default for RawGnss {
    fn default() -> Self {
        Self {
            elevation_mask_deg: 10.0,
            cn0_mask_dbhz: 0.0,
            pseudorange_sigma_m: 3.0,
            pseudorange_rate_sigma_mps: 0.1,
            elevation_weighting: true,
            use_receiver_sigmas: false,
            use_pseudorange_rate: true,
            innovation_gate_sigma: 5.0,
            constellations: vec![
                ConstellationName::Gps,
                ConstellationName::Galileo,
                ConstellationName::Beidou,
            ],
            clock_jump_threshold_m: 100_000.0,
        }
    }
}

/// The documented defaults of `loose.*`.
impl Default for LooseConfig {
    fn default() -> Self {
        Self {
            use_fix_covariance: true,
            fix_sigma_horizontal_m: 1.5,
            fix_sigma_vertical_m: 3.0,
            velocity_sigma_mps: 0.1,
        }
    }
}

/// The documented defaults of `adaptive.*`.
impl Default for AdaptiveConfig {
    fn default() -> Self {
        Self {
            window_size_m: 100,
            min_samples: 30,
            random_weighting: true,
            random_seed: 0,
            kde_threshold: 3.0,
            kde_consecutive_epochs: 3,
            ar_max_order: 5,
            ar_order_criterion: OrderCriterion::Aic,
            ar_denominator_floor: 0.1,
            innovation_window: 50,
            innovation_significance: 0.05,
            pseudorange_sigma_min_m: 0.3,
            pseudorange_sigma_max_m: 150.0,
            pseudorange_rate_sigma_min_mps: 0.02,
            pseudorange_rate_sigma_max_mps: 10.0,
            max_epoch_gap_s: 2.0,
        }
    }
}

/// The documented defaults of `robust.*`.
impl Default for RobustConfig {
    fn default() -> Self {
        Self {
            adaptive_factor_function: AdaptiveFactorKind::TwoSegment,
            adaptive_factor_c: 1.0,
            adaptive_factor_c0: 1.0,
            adaptive_factor_c1: 3.0,
            alpha_floor: 0.01,
            equivalent_weight_function: EquivalentWeightKind::DoubleFactor,
            double_factor_c: 1.5,
            igg3_k0: 1.5,
            igg3_k1: 3.0,
            max_variance_inflation: 1e6,
            chi2_confidence: 0.95,
            residual_window_epochs: 64,
            q_window_epochs: 64,
            q_alpha_min: 0.01,
            q_alpha_max: 100.0,
            q_scale_min: 0.001,
            q_scale_max: 1000.0,
        }
    }
}

/// `init.*`: start-up (alignment) and the initial 1σ of every state block.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawInit {
    pub heading_deg: Option<f64>,
    pub heading_min_speed_mps: f64,
    pub leveling_duration_s: f64,
    pub min_satellites: usize,
    pub attitude_sigma_deg: f64,
    pub heading_sigma_deg: f64,
    pub velocity_sigma_mps: f64,
    pub position_sigma_m: f64,
    pub clock_bias_sigma_m: f64,
    pub clock_drift_sigma_mps: f64,
}

impl Default for RawInit {
    fn default() -> Self {
        Self {
            heading_deg: None,
            heading_min_speed_mps: 1.0,
            leveling_duration_s: 1.0,
            min_satellites: 5,
            attitude_sigma_deg: 1.0,
            heading_sigma_deg: 5.0,
            velocity_sigma_mps: 0.5,
            position_sigma_m: 5.0,
            clock_bias_sigma_m: 30.0,
            clock_drift_sigma_mps: 5.0,
        }
    }
}

/// The documented defaults of `engine.*`.
impl Default for EngineConfig {
    fn default() -> Self {
        Self {
            imu_buffer_s: 2.0,
            max_imu_gap_s: 1.0,
        }
    }
}

/// `output.*`: what is published and where the local frame sits.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawOutput {
    pub datum_llh_deg_m: Option<[f64; 3]>,
    pub rate_hz: f64,
}

/// Constellation names as written in the parameter file (a local mapping, so the GNSS
/// observation type stays free of serde).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ConstellationName {
    Gps,
    Glonass,
    Galileo,
    Beidou,
    Qzss,
    Sbas,
}

impl ConstellationName {
    /// The name as written in the file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Gps => "gps",
            Self::Glonass => "glonass",
            Self::Galileo => "galileo",
            Self::Beidou => "beidou",
            Self::Qzss => "qzss",
            Self::Sbas => "sbas",
        }
    }
}

impl From<ConstellationName> for Constellation {
    fn from(name: ConstellationName) -> Self {
        match name {
            ConstellationName::Gps => Self::Gps,
            ConstellationName::Glonass => Self::Glonass,
            ConstellationName::Galileo => Self::Galileo,
            ConstellationName::Beidou => Self::Beidou,
            ConstellationName::Qzss => Self::Qzss,
            ConstellationName::Sbas => Self::Sbas,
        }
    }
}

impl From<Constellation> for ConstellationName {
    fn from(constellation: Constellation) -> Self {
        match constellation {
            Constellation::Gps => Self::Gps,
            Constellation::Glonass => Self::Glonass,
            Constellation::Galileo => Self::Galileo,
            Constellation::Beidou => Self::Beidou,
            Constellation::Qzss => Self::Qzss,
            Constellation::Sbas => Self::Sbas,
        }
    }
}
