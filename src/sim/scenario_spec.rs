//! The scenario specification (YAML in human units, units in the key names), its defaults,
//! its validation, and the built-in scenarios embedded in the crate.

use serde::{Deserialize, Serialize};

use crate::gnss::Klobuchar;
use crate::sim::ar_process::ArModel;
use crate::sim::environment::{Environment, EnvironmentSegment};
use crate::sim::receiver_clock::ReceiverClockSpec;
use crate::sim::scenario_error::ScenarioError;
use crate::sim::{ImuErrorSpec, TrajectorySpec};

/// Highest IMU rate accepted (Hz).
pub const MAX_IMU_RATE_HZ: f64 = 1000.0;
/// Highest GNSS rate accepted (Hz). Choice: receivers give raw data at up to 20 Hz.
pub const MAX_GNSS_RATE_HZ: f64 = 20.0;
/// Highest truth-output rate accepted (Hz), the IMU's limit.
pub const MAX_TRUTH_RATE_HZ: f64 = 1000.0;
/// Largest |antenna lever-arm component| accepted (m), as the engine's configuration.
pub const MAX_LEVER_ARM_M: f64 = 100.0;

/// The built-in scenarios: (name, YAML).
const BUILTINS: [(&str, &str); 3] = [
    ("default", include_str!("scenarios/default.yaml")),
    ("open_sky", include_str!("scenarios/open_sky.yaml")),
    ("static", include_str!("scenarios/static.yaml")),
];

fn default_imu_rate_hz() -> f64 {
    100.0
}

fn default_gnss_rate_hz() -> f64 {
    1.0
}

fn default_truth_rate_hz() -> f64 {
    10.0
}

/// Choice: GPS week 2386, so that a scenario starts on 2025-10-01 23:59:51 UTC plus its
/// `start_gps_s` (a recent date: stamps of this decade, which `f64` seconds resolve only to
/// 238 ns, as a real recording's are).
pub const DEFAULT_CONSTELLATION_GPS_WEEK: u16 = 2386;
/// The GPS weeks accepted for the constellation: from 2017-01-01 (week 1930), since when
/// GPS − UTC has been the 18 s the stamps assume, to week 3000 (2037-07), inside the
/// range of a ROS stamp's seconds.
pub const CONSTELLATION_GPS_WEEKS: std::ops::RangeInclusive<u16> = 1930..=3000;

fn default_constellation_gps_week() -> u16 {
    DEFAULT_CONSTELLATION_GPS_WEEK
}

fn default_extra_satellites_per_plane() -> usize {
    1
}

fn default_elevation_mask_deg() -> f64 {
    10.0
}

/// The IMU: rate and error model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuSpec {
    /// Sample rate (Hz), in (0, 1000]. Default 100.
    #[serde(default = "default_imu_rate_hz")]
    pub rate_hz: f64,
    /// Error model (the default is the ERMAKF paper's IMU-ISA-100C).
    #[serde(default)]
    pub errors: ImuErrorSpec,
}

impl Default for ImuSpec {
    fn default() -> Self {
        Self {
            rate_hz: default_imu_rate_hz(),
            errors: ImuErrorSpec::default(),
        }
    }
}

/// Open-sky thermal noise and the C/N0 model.
///
/// C/N0(el) = cn0_horizon + (cn0_zenith − cn0_horizon) sin(el) − loss (dB-Hz), with the
/// environment's loss; σ(el) = σ_zenith · 10^(−(C/N0(el) − cn0_zenith)/20).
///
/// Math note: a delay-lock (and frequency-lock) loop's thermal jitter is proportional to
/// 1/√(C/N0) (Kaplan & Hegarty, code tracking jitter, above the squaring-loss knee), hence
/// the 20 in the exponent. With the defaults 35 + 15 sin(el) dB-Hz, σ at 15° elevation is
/// 3.6 σ_zenith — close to the common 1/sin(el) rule (3.9).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ThermalNoiseSpec {
    /// Pseudo-range σ at the zenith in open sky, i.e. at C/N0 = cn0_zenith (m), ≥ 0.
    pub pseudorange_sigma_zenith_m: f64,
    /// Pseudo-range-rate σ at the zenith in open sky (m/s), ≥ 0.
    pub pseudorange_rate_sigma_zenith_mps: f64,
    /// C/N0 at the zenith in open sky (dB-Hz), the reference of the σ.
    pub cn0_zenith_dbhz: f64,
    /// C/N0 at the horizon in open sky (dB-Hz), ≤ cn0_zenith.
    pub cn0_horizon_dbhz: f64,
    /// Carrier-phase σ at the zenith in open sky (m), ≥ 0; it follows the C/N0 like the
    /// code's (a phase-lock loop's jitter is also ∝ 1/√(C/N0)).
    pub carrier_phase_sigma_zenith_m: f64,
}

impl Default for ThermalNoiseSpec {
    /// 0.5 m and 0.05 m/s at 50 dB-Hz: a geodetic-grade receiver's L1 C/A code noise with
    /// a narrow correlator is decimetres, plus residual unmodelled effects; a Doppler-
    /// derived rate a few cm/s (Groves, Principles of GNSS, Inertial and Multisensor
    /// Integrated Navigation, 2nd ed., ch. 9). C/N0 35–50 dB-Hz is a typical open-sky span
    /// from horizon to zenith. The carrier phase 2 mm at the zenith: an L1 phase-lock
    /// loop's thermal jitter is about a millimetre at 50 dB-Hz (ibid.), doubled for the
    /// oscillator and residual multipath.
    fn default() -> Self {
        Self {
            pseudorange_sigma_zenith_m: 0.5,
            pseudorange_rate_sigma_zenith_mps: 0.05,
            cn0_zenith_dbhz: 50.0,
            cn0_horizon_dbhz: 35.0,
            carrier_phase_sigma_zenith_m: 0.002,
        }
    }
}

impl ThermalNoiseSpec {
    /// C/N0 (dB-Hz) at `elevation_rad` after a loss of `loss_db`.
    pub fn cn0_dbhz(&self, elevation_rad: f64, loss_db: f64) -> f64 {
        self.cn0_horizon_dbhz
            + (self.cn0_zenith_dbhz - self.cn0_horizon_dbhz) * elevation_rad.max(0.0).sin()
            - loss_db
    }

    /// Ratio of the thermal σ at `cn0_dbhz` to the zenith σ.
    pub fn sigma_ratio(&self, cn0_dbhz: f64) -> f64 {
        10f64.powf(-(cn0_dbhz - self.cn0_zenith_dbhz) / 20.0)
    }
}

/// The atmosphere: broadcast Klobuchar coefficients, the truth as scaled models, and
/// whether the observations report the delays.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AtmosphereSpec {
    /// Klobuchar α (s, s/semicircle, s/semicircle², s/semicircle³).
    pub klobuchar_alpha: [f64; 4],
    /// Klobuchar β (s, s/semicircle, s/semicircle², s/semicircle³).
    pub klobuchar_beta: [f64; 4],
    /// True ionospheric delay / Klobuchar delay (1: the model is the truth), ≥ 0.
    pub iono_truth_scale: f64,
    /// True tropospheric delay / Saastamoinen delay, ≥ 0.
    pub tropo_truth_scale: f64,
    /// Report the true delays in each observation (false: NaN, the node models them).
    pub report_delays: bool,
}

impl Default for AtmosphereSpec {
    /// The Klobuchar example set of the GPS interface specification's test values (the
    /// one the constellation tests use, a moderate ionosphere), models equal to the truth,
    /// delays not reported.
    fn default() -> Self {
        Self {
            klobuchar_alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -1.1921e-7],
            klobuchar_beta: [1.1469e5, 0.0, -1.9661e5, -6.5536e4],
            iono_truth_scale: 1.0,
            tropo_truth_scale: 1.0,
            report_delays: false,
        }
    }
}

impl AtmosphereSpec {
    /// The broadcast coefficients.
    pub fn klobuchar(&self) -> Klobuchar {
        Klobuchar {
            alpha: self.klobuchar_alpha,
            beta: self.klobuchar_beta,
        }
    }
}

/// The GNSS receiver and the constellation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSpec {
    /// Epoch rate (Hz), in (0, 20]. Default 1.
    #[serde(default = "default_gnss_rate_hz")]
    pub rate_hz: f64,
    /// GPS time at scenario time 0, seconds since the constellation's reference epoch
    /// (its slot table's 1993-07-01 00:00 UTC, placed in `constellation_gps_week`), in
    /// [0, 1e9); sets the satellite geometry and the local time. Default 0.
    #[serde(default)]
    pub start_gps_s: f64,
    /// GPS week in which the constellation's reference epoch is placed (its Thursday
    /// 00:00:09 GPS time; see [`crate::sim::scenario_clock`]): with `start_gps_s` it sets
    /// the real date of the scenario, its stamps (UTC) and the week of its GNSS epochs.
    /// In [1930, 3000]. Default [`DEFAULT_CONSTELLATION_GPS_WEEK`].
    #[serde(default = "default_constellation_gps_week")]
    pub constellation_gps_week: u16,
    /// Satellites added to each of the six orbit planes of the baseline 24 (default 1:
    /// 30 satellites, like today's GPS), at most 4.
    #[serde(default = "default_extra_satellites_per_plane")]
    pub extra_satellites_per_plane: usize,
    /// Satellites below this elevation are not tracked (deg), in [0, 90). Default 10.
    #[serde(default = "default_elevation_mask_deg")]
    pub elevation_mask_deg: f64,
    /// Antenna phase centre relative to the IMU, body FLU (m). Default zero.
    #[serde(default)]
    pub antenna_lever_arm_m: [f64; 3],
    /// Thermal noise and C/N0.
    #[serde(default)]
    pub thermal_noise: ThermalNoiseSpec,
    /// Atmosphere.
    #[serde(default)]
    pub atmosphere: AtmosphereSpec,
    /// Receiver clock.
    #[serde(default)]
    pub receiver_clock: ReceiverClockSpec,
}

impl Default for GnssSpec {
    fn default() -> Self {
        Self {
            rate_hz: default_gnss_rate_hz(),
            start_gps_s: 0.0,
            constellation_gps_week: DEFAULT_CONSTELLATION_GPS_WEEK,
            extra_satellites_per_plane: default_extra_satellites_per_plane(),
            elevation_mask_deg: default_elevation_mask_deg(),
            antenna_lever_arm_m: [0.0; 3],
            thermal_noise: ThermalNoiseSpec::default(),
            atmosphere: AtmosphereSpec::default(),
            receiver_clock: ReceiverClockSpec::default(),
        }
    }
}

/// A dual-antenna (moving-base) receiver pair on the vehicle: at each GNSS epoch with a
/// fix, the heading of its baseline with a Gaussian error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DualAntennaSpec {
    /// The baseline from the moving base's antenna to the rover's, body FLU (m); its
    /// horizontal part at least 0.1 m.
    pub baseline_m: [f64; 3],
    /// 1-sigma of the heading's error (deg), positive; also the reported accuracy.
    pub heading_sigma_deg: f64,
}

/// Shortest horizontal baseline of a dual-antenna pair (m).
const MIN_BASELINE_M: f64 = 0.1;

/// A whole scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Name, for reports.
    pub name: String,
    /// The vehicle's motion; `start_t_s` must be 0 (scenario time starts at 0).
    pub trajectory: TrajectorySpec,
    /// IMU.
    #[serde(default)]
    pub imu: ImuSpec,
    /// GNSS.
    #[serde(default)]
    pub gnss: GnssSpec,
    /// Rate of the truth output (Hz), in (0, 1000]. Default 10.
    #[serde(default = "default_truth_rate_hz")]
    pub truth_rate_hz: f64,
    /// Environment segments (non-overlapping); open sky elsewhere.
    #[serde(default)]
    pub environments: Vec<EnvironmentSegment>,
    /// A dual-antenna pair (none by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dual_antenna: Option<DualAntennaSpec>,
}

impl ScenarioSpec {
    /// Names accepted by [`Self::builtin`].
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTINS.iter().map(|(name, _)| *name).collect()
    }

    /// A built-in scenario by name.
    pub fn builtin(name: &str) -> Result<Self, ScenarioError> {
        let yaml = BUILTINS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, y)| *y)
            .ok_or_else(|| ScenarioError::UnknownBuiltin {
                name: name.to_string(),
                known: Self::builtin_names().join(", "),
            })?;
        Self::from_yaml(yaml)
    }

    /// Parses a YAML scenario (field paths in the error message) and validates it.
    pub fn from_yaml(yaml: &str) -> Result<Self, ScenarioError> {
        let de = serde_yaml::Deserializer::from_str(yaml);
        let spec: Self = serde_path_to_error::deserialize(de).map_err(|e| ScenarioError::Yaml {
            message: e.to_string(),
        })?;
        spec.validate()?;
        Ok(spec)
    }

    /// Checks every value this module owns (the trajectory and IMU errors are checked by
    /// their own constructors).
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let invalid = |field: &'static str, reason: &'static str| ScenarioError::InvalidSpec {
            field: field.to_string(),
            reason,
        };
        if self.trajectory.start_t_s != 0.0 {
            return Err(invalid(
                "trajectory.start_t_s",
                "must be 0 (scenario time starts at 0)",
            ));
        }
        let rate_ok = |r: f64, max: f64| r.is_finite() && r > 0.0 && r <= max;
        if !rate_ok(self.imu.rate_hz, MAX_IMU_RATE_HZ) {
            return Err(invalid("imu.rate_hz", "must be in (0, 1000]"));
        }
        if !rate_ok(self.gnss.rate_hz, MAX_GNSS_RATE_HZ) {
            return Err(invalid("gnss.rate_hz", "must be in (0, 20]"));
        }
        if !rate_ok(self.truth_rate_hz, MAX_TRUTH_RATE_HZ) {
            return Err(invalid("truth_rate_hz", "must be in (0, 1000]"));
        }
        let g = &self.gnss;
        if !(0.0..1e9).contains(&g.start_gps_s) {
            return Err(invalid("gnss.start_gps_s", "must be in [0, 1e9)"));
        }
        if !CONSTELLATION_GPS_WEEKS.contains(&g.constellation_gps_week) {
            return Err(invalid(
                "gnss.constellation_gps_week",
                "must be in [1930, 3000] (from 2017, GPS - UTC = 18 s)",
            ));
        }
        if g.extra_satellites_per_plane > 4 {
            return Err(invalid(
                "gnss.extra_satellites_per_plane",
                "must be at most 4",
            ));
        }
        if !(g.elevation_mask_deg >= 0.0 && g.elevation_mask_deg < 90.0) {
            return Err(invalid("gnss.elevation_mask_deg", "must be in [0, 90)"));
        }
        if !g
            .antenna_lever_arm_m
            .iter()
            .all(|x| x.is_finite() && x.abs() <= MAX_LEVER_ARM_M)
        {
            return Err(invalid(
                "gnss.antenna_lever_arm_m",
                "components must be finite and within ±100 m",
            ));
        }
        let t = &g.thermal_noise;
        let non_negative = |x: f64| x.is_finite() && x >= 0.0;
        if !(non_negative(t.pseudorange_sigma_zenith_m)
            && non_negative(t.pseudorange_rate_sigma_zenith_mps)
            && non_negative(t.carrier_phase_sigma_zenith_m))
        {
            return Err(invalid(
                "gnss.thermal_noise",
                "σ values must be finite and non-negative",
            ));
        }
        if !(t.cn0_zenith_dbhz.is_finite()
            && t.cn0_horizon_dbhz.is_finite()
            && t.cn0_horizon_dbhz <= t.cn0_zenith_dbhz)
        {
            return Err(invalid(
                "gnss.thermal_noise",
                "C/N0 values must be finite with cn0_horizon_dbhz ≤ cn0_zenith_dbhz",
            ));
        }
        let a = &g.atmosphere;
        if !(a.klobuchar_alpha.iter().all(|x| x.is_finite())
            && a.klobuchar_beta.iter().all(|x| x.is_finite()))
        {
            return Err(invalid(
                "gnss.atmosphere",
                "Klobuchar coefficients must be finite",
            ));
        }
        if !(non_negative(a.iono_truth_scale) && non_negative(a.tropo_truth_scale)) {
            return Err(invalid(
                "gnss.atmosphere",
                "truth scales must be finite and non-negative",
            ));
        }
        if let Some((field, _)) = g.receiver_clock.invalid_field() {
            return Err(ScenarioError::InvalidSpec {
                field: format!("gnss.receiver_clock.{field}"),
                reason: "must be finite (h-coefficients non-negative)",
            });
        }
        if let Some(d) = &self.dual_antenna {
            let [x, y, z] = d.baseline_m;
            if !([x, y, z]
                .iter()
                .all(|v| v.is_finite() && v.abs() <= MAX_LEVER_ARM_M)
                && x.hypot(y) >= MIN_BASELINE_M)
            {
                return Err(invalid(
                    "dual_antenna.baseline_m",
                    "components must be finite and within ±100 m, the horizontal part ≥ 0.1 m",
                ));
            }
            if !(d.heading_sigma_deg.is_finite() && d.heading_sigma_deg > 0.0) {
                return Err(invalid(
                    "dual_antenna.heading_sigma_deg",
                    "must be finite and positive",
                ));
            }
        }
        self.validate_environments()
    }

    fn validate_environments(&self) -> Result<(), ScenarioError> {
        let mut spans: Vec<(f64, f64)> = Vec::with_capacity(self.environments.len());
        for (index, seg) in self.environments.iter().enumerate() {
            let invalid = |reason: &'static str| ScenarioError::InvalidSpec {
                field: format!("environments[{index}]"),
                reason,
            };
            if !(seg.start_s.is_finite() && seg.end_s.is_finite() && seg.start_s < seg.end_s) {
                return Err(invalid("start_s < end_s, both finite, is required"));
            }
            if spans.iter().any(|&(s, e)| seg.start_s < e && s < seg.end_s) {
                return Err(invalid("overlaps an earlier segment"));
            }
            spans.push((seg.start_s, seg.end_s));
            let probability = |p: f64| (0.0..=1.0).contains(&p);
            let non_negative = |x: f64| x.is_finite() && x >= 0.0;
            match &seg.environment {
                Environment::OpenSky | Environment::Outage => {}
                Environment::Foliage(f) => {
                    if !non_negative(f.cn0_loss_db) {
                        return Err(invalid("cn0_loss_db must be finite and non-negative"));
                    }
                    let m = &f.multipath;
                    if !(non_negative(m.pseudorange_sigma_m)
                        && non_negative(m.pseudorange_rate_sigma_mps))
                    {
                        return Err(invalid(
                            "multipath σ values must be finite and non-negative",
                        ));
                    }
                    if ArModel::new(&m.ar_coefficients, 1.0).is_err() {
                        return Err(invalid(
                            "multipath.ar_coefficients must be 1 to 8 finite values of a stationary AR process",
                        ));
                    }
                    let h = &f.heavy_tail;
                    if !(probability(h.probability) && h.scale.is_finite() && h.scale >= 1.0) {
                        return Err(invalid(
                            "heavy_tail needs probability in [0, 1] and a finite scale ≥ 1",
                        ));
                    }
                }
                Environment::UrbanCanyon(u) => {
                    let ok = non_negative(u.cn0_loss_db)
                        && (0.0..90.0).contains(&u.min_mask_elevation_deg)
                        && non_negative(u.building_height_m)
                        && u.street_width_m.is_finite()
                        && u.street_width_m > 0.0
                        && probability(u.nlos_fraction)
                        && non_negative(u.nlos_bias_min_m)
                        && u.nlos_bias_max_m.is_finite()
                        && u.nlos_bias_max_m >= u.nlos_bias_min_m
                        && probability(u.outlier_probability)
                        && non_negative(u.outlier_min_m)
                        && u.outlier_max_m.is_finite()
                        && u.outlier_max_m >= u.outlier_min_m;
                    if !ok {
                        return Err(invalid(
                            "urban_canyon values out of range (losses, heights, biases ≥ 0, \
                             mask in [0, 90), width > 0, probabilities in [0, 1], max ≥ min)",
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The environment in force at scenario time `t_s` and its segment index (None: the
    /// open sky outside every segment).
    pub fn environment_at(&self, t_s: f64) -> (Option<usize>, &Environment) {
        const OPEN_SKY: &Environment = &Environment::OpenSky;
        self.environments
            .iter()
            .enumerate()
            .find(|(_, seg)| t_s >= seg.start_s && t_s < seg.end_s)
            .map_or((None, OPEN_SKY), |(i, seg)| (Some(i), &seg.environment))
    }
}
