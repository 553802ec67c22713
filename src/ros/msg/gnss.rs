//! The package's own messages (`msg/*.msg`): raw GNSS measurements in, noise diagnostics
//! out. The `.msg` files are the contract; the field comments there are the full story.

use serde::{Deserialize, Serialize};

use super::{ros_message, Header, Point, Vector3};

/// Text of `msg/SatelliteMeasurement.msg` (for MCAP / rosbag2 schemas).
pub const SATELLITE_MEASUREMENT_MSG: &str = include_str!("../../../msg/SatelliteMeasurement.msg");
/// Text of `msg/GnssMeasurements.msg` (for MCAP / rosbag2 schemas).
pub const GNSS_MEASUREMENTS_MSG: &str = include_str!("../../../msg/GnssMeasurements.msg");
/// Text of `msg/SatelliteNoise.msg` (for MCAP / rosbag2 schemas).
pub const SATELLITE_NOISE_MSG: &str = include_str!("../../../msg/SatelliteNoise.msg");
/// Text of `msg/NoiseEstimates.msg` (for MCAP / rosbag2 schemas).
pub const NOISE_ESTIMATES_MSG: &str = include_str!("../../../msg/NoiseEstimates.msg");

/// `adaptive_gnss_ins/msg/SatelliteMeasurement`: one satellite's raw measurements and
/// broadcast state at one receiver epoch. Absent or unknown values are NaN.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct SatelliteMeasurement {
    /// Constellation code (`GPS`, `GLONASS`, ... constants).
    pub constellation: u8,
    /// PRN (slot) number within the constellation.
    pub prn: u16,
    /// Pseudo-range as measured (m).
    pub pseudorange_m: f64,
    /// Pseudo-range rate (m/s), positive when the range grows; NaN when absent.
    pub pseudorange_rate_mps: f64,
    /// Receiver-reported 1σ of the pseudo-range (m); NaN when unknown.
    pub pseudorange_sigma_m: f64,
    /// Receiver-reported 1σ of the pseudo-range rate (m/s); NaN when unknown.
    pub pseudorange_rate_sigma_mps: f64,
    /// Carrier-to-noise density ratio (dB-Hz); NaN when unknown.
    pub cn0_dbhz: f32,
    /// Satellite position at transmission time, in the ECEF frame of that time (m).
    pub satellite_position_ecef_m: Point,
    /// Satellite velocity in ECEF (m/s).
    pub satellite_velocity_ecef_mps: Vector3,
    /// Satellite clock offset, relativistic term included (s).
    pub satellite_clock_bias_s: f64,
    /// Satellite clock drift (s/s).
    pub satellite_clock_drift_s_s: f64,
    /// Ionospheric delay on the pseudo-range (m); NaN: the node models it.
    pub ionosphere_delay_m: f64,
    /// Tropospheric delay on the pseudo-range (m); NaN: the node models it.
    pub troposphere_delay_m: f64,
    /// Carrier phase (cycles), with the sign of the pseudo-range; NaN when not tracked.
    pub carrier_phase_cycles: f64,
    /// Wavelength of the carrier (m); NaN when unknown.
    pub carrier_wavelength_m: f64,
    /// Receiver-reported 1σ of the carrier phase (cycles); NaN when unknown.
    pub carrier_phase_sigma_cycles: f64,
    /// Time lock has been kept on the carrier (s); NaN when unknown.
    pub carrier_lock_time_s: f64,
    /// `CARRIER_*` bits.
    pub carrier_phase_flags: u8,
}
ros_message!(
    SatelliteMeasurement,
    "adaptive_gnss_ins",
    "SatelliteMeasurement"
);

impl SatelliteMeasurement {
    /// GPS (USA).
    pub const GPS: u8 = 1;
    /// GLONASS (Russia).
    pub const GLONASS: u8 = 2;
    /// Galileo (EU).
    pub const GALILEO: u8 = 3;
    /// BeiDou (China).
    pub const BEIDOU: u8 = 4;
    /// QZSS (Japan).
    pub const QZSS: u8 = 5;
    /// SBAS geostationary satellites.
    pub const SBAS: u8 = 6;
    /// `carrier_phase_flags`: lock lost since the previous epoch (a cycle slip is possible).
    pub const CARRIER_LOSS_OF_LOCK: u8 = 1;
    /// `carrier_phase_flags`: the half-cycle ambiguity is not resolved.
    pub const CARRIER_HALF_CYCLE_UNRESOLVED: u8 = 2;
}

/// `adaptive_gnss_ins/msg/GnssMeasurements`: all raw measurements of one receiver epoch.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct GnssMeasurements {
    /// Receiver measurement time (ROS time) and the antenna's frame.
    pub header: Header,
    /// GPS week number (not modulo 1024).
    pub gps_week: u16,
    /// GPS time of week (s).
    pub gps_time_of_week_s: f64,
    /// One entry per tracked satellite.
    pub satellites: Vec<SatelliteMeasurement>,
    /// Klobuchar α coefficients (s, s/sc, s/sc², s/sc³); NaN when not broadcast.
    pub klobuchar_alpha: [f64; 4],
    /// Klobuchar β coefficients (s, s/sc, s/sc², s/sc³); NaN when not broadcast.
    pub klobuchar_beta: [f64; 4],
}
ros_message!(GnssMeasurements, "adaptive_gnss_ins", "GnssMeasurements");

/// `adaptive_gnss_ins/msg/SatelliteNoise`: per-satellite noise diagnostics of one
/// update. Values not computed are NaN.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct SatelliteNoise {
    /// Constellation code (`SatelliteMeasurement` constants).
    pub constellation: u8,
    /// PRN (slot) number within the constellation.
    pub prn: u16,
    /// Elevation above the local horizon (degrees).
    pub elevation_deg: f64,
    /// True when the satellite entered the update.
    pub used: bool,
    /// One of the `REJECTION_*` constants.
    pub rejection_reason: u8,
    /// Pseudo-range innovation, measured minus predicted (m).
    pub innovation_pseudorange_m: f64,
    /// Pseudo-range rate innovation, measured minus predicted (m/s).
    pub innovation_pseudorange_rate_mps: f64,
    /// Pseudo-range innovation over its predicted standard deviation.
    pub normalized_innovation_pseudorange: f64,
    /// Pseudo-range rate innovation over its predicted standard deviation.
    pub normalized_innovation_pseudorange_rate: f64,
    /// Measurement noise variance used for the pseudo-range (m²).
    pub r_pseudorange_m2: f64,
    /// Measurement noise variance used for the pseudo-range rate (m²/s²).
    pub r_pseudorange_rate_m2_s2: f64,
    /// Kernel density estimate at the current redundant-measurement difference.
    pub kde_credibility: f64,
    /// True when the noise is judged Gaussian.
    pub gaussian: bool,
    /// Order of the fitted autoregressive noise model (0: none).
    pub ar_order: u8,
    /// Robust weight applied to the measurements (1: full weight).
    pub robust_weight: f64,
}
ros_message!(SatelliteNoise, "adaptive_gnss_ins", "SatelliteNoise");

impl SatelliteNoise {
    /// Used in the update.
    pub const REJECTION_NONE: u8 = 0;
    /// Below the elevation mask.
    pub const REJECTION_ELEVATION_MASK: u8 = 1;
    /// C/N0 below the mask.
    pub const REJECTION_CN0_MASK: u8 = 2;
    /// Innovation outside the innovation gate.
    pub const REJECTION_INNOVATION_GATE: u8 = 3;
    /// A measurement or broadcast state was NaN or infinite.
    pub const REJECTION_NOT_A_NUMBER: u8 = 4;
    /// No usable satellite position, velocity or clock.
    pub const REJECTION_NO_EPHEMERIS_STATE: u8 = 5;
    /// Rejected by the Mahalanobis (χ²) test.
    pub const REJECTION_MAHALANOBIS: u8 = 6;
    /// Constellation disabled in the configuration.
    pub const REJECTION_CONSTELLATION_DISABLED: u8 = 7;
}

/// `adaptive_gnss_ins/msg/NoiseEstimates`: noise estimates and consistency statistics of
/// one GNSS update. Values not computed are NaN.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Default)]
pub struct NoiseEstimates {
    /// Time of the processed GNSS epoch and the antenna's frame.
    pub header: Header,
    /// Configured filter variant, as spelled in the parameter file.
    pub filter_variant: String,
    /// One entry per satellite of the epoch, used or not.
    pub satellites: Vec<SatelliteNoise>,
    /// Adaptive factor applied to the predicted covariance (1: no scaling).
    pub adaptive_factor: f64,
    /// Squared Mahalanobis distance of the innovation vector.
    pub mahalanobis_d2: f64,
    /// χ² threshold the Mahalanobis distance was tested against.
    pub chi2_threshold: f64,
    /// Scale factor applied to the process noise Q (1: nominal).
    pub q_scale: f64,
    /// Normalized innovation squared of the update.
    pub nis: f64,
}
ros_message!(NoiseEstimates, "adaptive_gnss_ins", "NoiseEstimates");
