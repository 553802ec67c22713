//! The validated configuration in SI units and radians: what the engine reads. Each field
//! names the parameter-file key it comes from and that key's default.
//!
//! The sections whose keys need no unit conversion (`filter`, `loose`, `adaptive`, `robust`,
//! `engine`) are also what the file is read into, before validation (see `raw`).

use nalgebra::{UnitQuaternion, Vector3};
use serde::Deserialize;

use crate::earth::Llh;
use crate::gnss::Constellation;

/// The validated configuration, in SI units and radians.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub filter: FilterConfig,
    pub imu: ImuConfig,
    pub mounting: MountingConfig,
    pub clock: ClockConfig,
    pub gnss: GnssConfig,
    pub loose: LooseConfig,
    pub adaptive: AdaptiveConfig,
    pub robust: RobustConfig,
    pub init: InitConfig,
    pub engine: EngineConfig,
    pub output: OutputConfig,
}

/// Which filter runs (`filter.variant`). Every variant shares the engine, the measurement
/// models and the diagnostics, so variants can be compared on the same data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FilterVariant {
    /// `ekf`: error-state extended Kalman filter with the fixed noise of this file; the
    /// baseline the adaptive variants are measured against.
    Ekf,
    /// `eiakf`: innovation-based adaptive R (windowed innovation covariance less H P⁻ Hᵀ),
    /// enhanced with a whiteness test and an AR(1) correction (the ERMAKF paper's
    /// reference [24]).
    Eiakf,
    /// `srmakf`: the simple redundant-measurement estimator, R = E[∇Z²]/2 over the window
    /// (ERMAKF paper, eqs. 12–18).
    Srmakf,
    /// `ermakf`: the enhanced redundant-measurement AKF: random weighting (eq. 19), KDE
    /// detection (eqs. 20–24) and the Burg/Akaike AR variance (eqs. 25–29).
    Ermakf,
    /// `ckf`: the cubature Kalman filter of the IARF paper (scheme 1 of its section 5),
    /// fixed noise, no adaptive factor, no robust step.
    Ckf,
    /// `akf_all`: the adaptive filter with the factor α of the predicted residual
    /// (section 2.2) at every epoch (IARF paper, scheme 2).
    AkfAll,
    /// `akf_partial`: the adaptive filter only at the epochs that pass the Mahalanobis test
    /// (section 3), α = 1 at the others (IARF paper, scheme 3).
    AkfPartial,
    /// `iarf`: the improved adaptively-robust filter (IARF paper, section 3, scheme 4): the
    /// robust equivalent covariance R̄ at every epoch, the adaptive factor only at the
    /// epochs that pass the Mahalanobis test.
    Iarf,
    /// `residual_akf`: online stochastic modelling of R from the post-update residuals
    /// (Ding, Wang and Rizos 2007, eqs. 14–15).
    ResidualAkf,
}

impl FilterVariant {
    /// Every variant, in the order of the documentation.
    pub const ALL: [FilterVariant; 9] = [
        Self::Ekf,
        Self::Eiakf,
        Self::Srmakf,
        Self::Ermakf,
        Self::Ckf,
        Self::AkfAll,
        Self::AkfPartial,
        Self::Iarf,
        Self::ResidualAkf,
    ];

    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Ekf => "ekf",
            Self::Eiakf => "eiakf",
            Self::Srmakf => "srmakf",
            Self::Ermakf => "ermakf",
            Self::Ckf => "ckf",
            Self::AkfAll => "akf_all",
            Self::AkfPartial => "akf_partial",
            Self::Iarf => "iarf",
            Self::ResidualAkf => "residual_akf",
        }
    }

    /// True for the variants of the IARF paper, whose experiments all run on the cubature
    /// filter (section 5): `ckf`, `akf_all`, `akf_partial`, `iarf`.
    pub fn is_iarf_family(self) -> bool {
        matches!(
            self,
            Self::Ckf | Self::AkfAll | Self::AkfPartial | Self::Iarf
        )
    }
}

/// The base filter of the measurement update (`filter.base`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FilterBase {
    /// `auto`: cubature for the IARF-paper variants (`ckf`, `akf_all`, `akf_partial`,
    /// `iarf`), the EKF for every other variant.
    Auto,
    /// `ekf`: the linearized (extended) update.
    Ekf,
    /// `cubature`: the cubature Kalman filter update (2n points).
    Cubature,
}

impl FilterBase {
    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Ekf => "ekf",
            Self::Cubature => "cubature",
        }
    }
}

/// The adaptive-factor function of the IARF paper, section 2.2 (`robust.adaptive_factor_function`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AdaptiveFactorKind {
    /// `two_segment`: eq. (9), threshold c.
    TwoSegment,
    /// `three_segment`: eq. (10), thresholds c0 < c1.
    ThreeSegment,
}

impl AdaptiveFactorKind {
    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::TwoSegment => "two_segment",
            Self::ThreeSegment => "three_segment",
        }
    }
}

/// The equivalent-weight function of the robust step (`robust.equivalent_weight_function`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EquivalentWeightKind {
    /// `double_factor`: the IARF paper's double factor, section 3 (threshold c).
    DoubleFactor,
    /// `igg3`: Yang's IGG-III (thresholds k0 < k1).
    Igg3,
}

impl EquivalentWeightKind {
    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::DoubleFactor => "double_factor",
            Self::Igg3 => "igg3",
        }
    }
}

/// What the filter takes from the receiver (`filter.coupling`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coupling {
    /// `tight`: per-satellite pseudo-ranges and pseudo-range rates.
    Tight,
    /// `loose`: the receiver's position (and velocity) fix.
    Loose,
}

impl Coupling {
    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Tight => "tight",
            Self::Loose => "loose",
        }
    }
}

/// `filter.*`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterConfig {
    /// `filter.variant` (default `ekf`).
    pub variant: FilterVariant,
    /// `filter.coupling` (default `tight`).
    pub coupling: Coupling,
    /// `filter.joseph_form` (default `true`): covariance update P = (I−KH)P(I−KH)ᵀ + KRKᵀ.
    pub joseph_form: bool,
    /// `filter.base` (default `auto`): the base filter of the measurement update.
    pub base: FilterBase,
    /// `filter.q_scaling` (default `false`): Ding's process-noise scaling, eqs. (19), (22),
    /// combinable with every variant.
    pub q_scaling: bool,
}

impl FilterConfig {
    /// True when the measurement update is the cubature one (`filter.base` resolved).
    pub fn uses_cubature(&self) -> bool {
        match self.base {
            FilterBase::Auto => self.variant.is_iarf_family(),
            FilterBase::Ekf => false,
            FilterBase::Cubature => true,
        }
    }
}

/// `imu.*`, in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuConfig {
    /// Gyro angle random walk (rad/√s) from `imu.gyro_arw_deg_per_sqrt_h` (default `0.012`).
    pub gyro_arw_rad_per_sqrt_s: f64,
    /// Initial 1σ of the constant gyro bias (rad/s) from `imu.gyro_bias_deg_per_h` (default `0.5`).
    pub gyro_bias_sigma_rad_s: f64,
    /// Steady-state 1σ of the Gauss-Markov gyro drift (rad/s) from
    /// `imu.gyro_markov_sigma_deg_per_h` (default `0.5`).
    pub gyro_markov_sigma_rad_s: f64,
    /// Gyro drift correlation time (s), `imu.gyro_markov_correlation_time_s` (default `3600`).
    pub gyro_markov_time_s: f64,
    /// Accelerometer velocity random walk (m/s/√s) from `imu.accel_vrw_ug_per_sqrt_hz` (default
    /// `100`).
    pub accel_vrw_m_s_per_sqrt_s: f64,
    /// Steady-state 1σ of the Gauss-Markov accelerometer bias (m/s²) from
    /// `imu.accel_bias_ug` (default `1250`).
    pub accel_bias_sigma_m_s2: f64,
    /// Accelerometer bias correlation time (s), `imu.accel_bias_correlation_time_s` (default
    /// `3600`).
    pub accel_markov_time_s: f64,
}

/// `mounting.*`.
#[derive(Debug, Clone, PartialEq)]
pub struct MountingConfig {
    /// Rotation taking IMU-frame vectors into the body frame (FLU): v_b = q · v_imu, from
    /// `mounting.imu_rotation_rpy_deg` (default `[0, 0, 0]`) = `[roll, pitch, yaw]` about x, y, z
    /// applied as R = Rz(yaw) · Ry(pitch) · Rx(roll).
    pub imu_to_body: UnitQuaternion<f64>,
    /// Antenna phase centre relative to the IMU, body FLU (m), `mounting.antenna_lever_arm_m`
    /// (default `[0, 0, 0]`).
    pub lever_arm_b_m: Vector3<f64>,
}

/// `clock.*`: receiver clock bias c·δt_u (m) and drift c·δt_ru (m/s).
#[derive(Debug, Clone, PartialEq)]
pub struct ClockConfig {
    /// White noise driving the bias (m/√s), `clock.bias_noise_m_per_sqrt_s` (default `0.1`).
    pub bias_noise_m_per_sqrt_s: f64,
    /// White noise driving the drift (m/s/√s), `clock.drift_noise_mps_per_sqrt_s` (default `0.2`).
    pub drift_noise_m_s_per_sqrt_s: f64,
    /// Drift correlation time (s), `clock.drift_correlation_time_s` (default `1800`).
    pub drift_time_s: f64,
}

/// `gnss.*`, in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssConfig {
    /// Satellites below this elevation are not used (rad), `gnss.elevation_mask_deg` (default
    /// `10`).
    pub elevation_mask_rad: f64,
    /// Satellites below this C/N0 are not used (dB-Hz; 0 = off), `gnss.cn0_mask_dbhz` (default
    /// `0`).
    pub cn0_mask_dbhz: f64,
    /// Zenith 1σ of a pseudo-range (m), `gnss.pseudorange_sigma_m` (default `3.0`).
    pub pseudorange_sigma_m: f64,
    /// Zenith 1σ of a pseudo-range rate (m/s), `gnss.pseudorange_rate_sigma_mps` (default `0.1`).
    pub pseudorange_rate_sigma_mps: f64,
    /// Scale the zenith σ by 1 / sin(elevation), `gnss.elevation_weighting` (default `true`).
    pub elevation_weighting: bool,
    /// Use the receiver's own σ when it reports one, `gnss.use_receiver_sigmas` (default `false`).
    pub use_receiver_sigmas: bool,
    /// Fuse pseudo-range rates as well as ranges, `gnss.use_pseudorange_rate` (default `true`).
    pub use_pseudorange_rate: bool,
    /// Reject a measurement whose |innovation| > gate · √S (0 = off),
    /// `gnss.innovation_gate_sigma` (default `5.0`).
    pub innovation_gate_sigma: f64,
    /// Constellations used, `gnss.constellations` (default `[gps, galileo, beidou]`); non-empty,
    /// unique.
    pub constellations: Vec<Constellation>,
    /// A common pseudo-range step larger than this (m) is absorbed as a receiver clock jump,
    /// `gnss.clock_jump_threshold_m` (default `100000`).
    pub max_clock_jump_m: f64,
}

/// `loose.*`: weighting of the receiver fix in loose coupling.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LooseConfig {
    /// true = weight the fix by the covariance the receiver publishes with it; false = by
    /// the σ below. `loose.use_fix_covariance` (default `true`).
    pub use_fix_covariance: bool,
    /// Horizontal 1σ of a fix (m), `loose.fix_sigma_horizontal_m` (default `1.5`).
    pub fix_sigma_horizontal_m: f64,
    /// Vertical 1σ of a fix (m), `loose.fix_sigma_vertical_m` (default `3.0`).
    pub fix_sigma_vertical_m: f64,
    /// 1σ of each receiver velocity component (m/s), `loose.velocity_sigma_mps` (default `0.1`).
    pub velocity_sigma_mps: f64,
}

/// `adaptive.*`: the online measurement-noise estimators of the ERMAKF family (used by the
/// `eiakf`, `srmakf` and `ermakf` variants; ignored by `ekf`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AdaptiveConfig {
    /// Window M of the redundant-measurement estimator (epochs), `adaptive.window_size_m`
    /// (default `100`).
    pub window_size_m: usize,
    /// Samples needed before an estimate is trusted (epochs), `adaptive.min_samples`
    /// (default `30`).
    pub min_samples: usize,
    /// Random weighting of the window, eq. (19) (ermakf), `adaptive.random_weighting`
    /// (default `true`).
    pub random_weighting: bool,
    /// Seed of the random weights, `adaptive.random_seed` (default `0`).
    pub random_seed: u64,
    /// KDE credibility threshold in standard deviations, `adaptive.kde_threshold`
    /// (default `3.0`).
    pub kde_threshold: f64,
    /// Consecutive epochs that switch the Gaussian verdict, `adaptive.kde_consecutive_epochs`
    /// (default `3`).
    pub kde_consecutive_epochs: usize,
    /// Highest AR order tried, `adaptive.ar_max_order` (default `5`).
    pub ar_max_order: usize,
    /// AR order criterion, `adaptive.ar_order_criterion` (default `aic`).
    pub ar_order_criterion: crate::adaptive::burg::OrderCriterion,
    /// Floor of the eq. (29) denominator, `adaptive.ar_denominator_floor` (default `0.1`).
    pub ar_denominator_floor: f64,
    /// Innovation window of the eiakf (epochs), `adaptive.innovation_window` (default `50`).
    pub innovation_window: usize,
    /// Significance of the eiakf whiteness test, `adaptive.innovation_significance`
    /// (default `0.05`).
    pub innovation_significance: f64,
    /// Bounds on the estimated pseudo-range σ (m), `adaptive.pseudorange_sigma_min_m`
    /// (default `0.3`) and `adaptive.pseudorange_sigma_max_m` (default `150.0`).
    pub pseudorange_sigma_min_m: f64,
    pub pseudorange_sigma_max_m: f64,
    /// Bounds on the estimated rate σ (m/s), `adaptive.pseudorange_rate_sigma_min_mps`
    /// (default `0.02`) and `adaptive.pseudorange_rate_sigma_max_mps` (default `10.0`).
    pub pseudorange_rate_sigma_min_mps: f64,
    pub pseudorange_rate_sigma_max_mps: f64,
    /// Longest gap between two epochs of a satellite over which ∇Z is still formed (s),
    /// `adaptive.max_epoch_gap_s` (default `2.0`).
    pub max_epoch_gap_s: f64,
}

/// `robust.*`: the constants of the IARF-paper schemes (adaptive factor, robust equivalent
/// covariance, Mahalanobis test) and of Ding's residual R and Q scaling. All are
/// dimensionless unless a unit is named.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobustConfig {
    /// `robust.adaptive_factor_function` (default `two_segment`).
    pub adaptive_factor_function: AdaptiveFactorKind,
    /// Threshold c of eq. (9), `robust.adaptive_factor_c` (default `1.0`).
    pub adaptive_factor_c: f64,
    /// Thresholds c0, c1 of eq. (10), `robust.adaptive_factor_c0` (default `1.0`) and
    /// `robust.adaptive_factor_c1` (default `3.0`).
    pub adaptive_factor_c0: f64,
    pub adaptive_factor_c1: f64,
    /// Floor of α, `robust.alpha_floor` (default `0.01`).
    pub alpha_floor: f64,
    /// `robust.equivalent_weight_function` (default `double_factor`).
    pub equivalent_weight_function: EquivalentWeightKind,
    /// Threshold c of the double factor, `robust.double_factor_c` (default `1.5`).
    pub double_factor_c: f64,
    /// IGG-III thresholds, `robust.igg3_k0` (default `1.5`), `robust.igg3_k1` (default `3.0`).
    pub igg3_k0: f64,
    pub igg3_k1: f64,
    /// Largest variance inflation λ_ii, `robust.max_variance_inflation` (default `1e6`).
    pub max_variance_inflation: f64,
    /// Confidence of the χ² test of M², `robust.chi2_confidence` (default `0.95`).
    pub chi2_confidence: f64,
    /// Window m of the residual-based R, eq. (15) (epochs), `robust.residual_window_epochs`
    /// (default `64`).
    pub residual_window_epochs: usize,
    /// Window m of the Q-scaling factor, eq. (19) (epochs), `robust.q_window_epochs`
    /// (default `64`).
    pub q_window_epochs: usize,
    /// Bounds on one α of eq. (19), `robust.q_alpha_min` (default `0.01`) and
    /// `robust.q_alpha_max` (default `100.0`).
    pub q_alpha_min: f64,
    pub q_alpha_max: f64,
    /// Bounds on the accumulated scale of Q, `robust.q_scale_min` (default `0.001`) and
    /// `robust.q_scale_max` (default `1000.0`).
    pub q_scale_min: f64,
    pub q_scale_max: f64,
}

/// `init.*`: start-up and initial 1σ of the state blocks, in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct InitConfig {
    /// Known initial heading (rad), compass convention: the body x axis measured clockwise
    /// from true north (ENU yaw = π/2 − heading). `init.heading_deg` (default `null` = from
    /// the GNSS velocity once moving).
    pub heading_rad: Option<f64>,
    /// Speed above which the GNSS velocity gives the heading (m/s),
    /// `init.heading_min_speed_mps` (default `1.0`).
    pub heading_min_speed_mps: f64,
    /// Accelerometer averaging for roll and pitch at rest (s), `init.leveling_duration_s` (default
    /// `1.0`).
    pub leveling_duration_s: f64,
    /// Satellites needed for the single-point start (≥ 4), `init.min_satellites` (default `5`).
    pub min_satellites: usize,
    /// Initial roll/pitch 1σ (rad), `init.attitude_sigma_deg` (default `1.0`).
    pub attitude_sigma_rad: f64,
    /// Initial heading 1σ (rad), `init.heading_sigma_deg` (default `5.0`).
    pub heading_sigma_rad: f64,
    /// Initial velocity 1σ per axis (m/s), `init.velocity_sigma_mps` (default `0.5`).
    pub velocity_sigma_mps: f64,
    /// Initial position 1σ per axis (m), `init.position_sigma_m` (default `5.0`).
    pub position_sigma_m: f64,
    /// Initial clock bias 1σ (m), `init.clock_bias_sigma_m` (default `30.0`).
    pub clock_bias_sigma_m: f64,
    /// Initial clock drift 1σ (m/s), `init.clock_drift_sigma_mps` (default `5.0`).
    pub clock_drift_sigma_mps: f64,
}

/// `engine.*`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EngineConfig {
    /// How far back a late GNSS epoch may reach into the IMU history (s),
    /// `engine.imu_buffer_s` (default `2.0`).
    pub imu_buffer_s: f64,
    /// A larger gap between IMU samples is rejected and the filter coasts or re-initialises
    /// (s), `engine.max_imu_gap_s` (default `1.0`).
    pub max_imu_gap_s: f64,
}

/// `output.*`.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputConfig {
    /// Origin of the local ENU frame of the odometry, `output.datum_llh_deg_m`
    /// (default `null` = the first fix), written as `[lat_deg, lon_deg, height_m]`.
    pub datum: Option<Llh>,
    /// Output rate (Hz; 0 = every IMU sample), `output.rate_hz` (default `0`).
    pub rate_hz: f64,
}
