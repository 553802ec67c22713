//! The signal environments of a scenario: open sky, foliage, urban canyon and outage, as
//! time segments with their error statistics (YAML in human units).
//!
//! What each environment does to a satellite's observation (see [`crate::sim::sat_errors`]
//! for the draws):
//! - every environment except outage: white thermal noise whose σ follows the C/N0;
//! - foliage: a C/N0 loss (canopy attenuation), time-correlated multipath as an AR(p)
//!   process per satellite on the pseudo-range and an independent one on the rate, and a
//!   heavy-tailed (contaminated Gaussian) white part;
//! - urban canyon: satellites behind the buildings are blocked (an azimuth-dependent mask
//!   from the street geometry), a fraction of the remaining ones carry a positive NLOS
//!   bias, and pseudo-range outliers occur;
//! - outage: no GNSS at all.

use serde::{Deserialize, Serialize};

/// Time-correlated multipath: an AR(p) process per satellite, stepped once per GNSS epoch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultipathSpec {
    /// φ_1 … φ_p of x_k = Σ φ_i x_{k−i} + w_k, per GNSS epoch (must be stationary).
    pub ar_coefficients: Vec<f64>,
    /// Steady-state σ of the pseudo-range multipath (m).
    pub pseudorange_sigma_m: f64,
    /// Steady-state σ of the pseudo-range-rate multipath (m/s).
    ///
    /// Choice: the rate error is its own AR process with the same coefficients, independent
    /// of the range one, not the derivative of the range multipath: a receiver's rate comes
    /// from the carrier (Doppler), whose multipath error is centimetres to decimetres per
    /// second, while differencing metre-level code multipath would give metres per second.
    pub pseudorange_rate_sigma_mps: f64,
}

/// A heavy-tailed white component (Tukey's contaminated Gaussian): with `probability`
/// the epoch's white noise of a satellite (range and rate together) is drawn with its σ
/// multiplied by `scale`, so its variance is σ² (1 − p + p s²).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeavyTailSpec {
    /// Probability of the wide component per satellite and epoch, in [0, 1].
    pub probability: f64,
    /// σ ratio of the wide component to the thermal noise, ≥ 1.
    pub scale: f64,
}

/// Foliage: attenuation, correlated multipath and heavy tails.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoliageSpec {
    /// C/N0 loss through the canopy (dB), ≥ 0.
    pub cn0_loss_db: f64,
    /// Time-correlated multipath.
    pub multipath: MultipathSpec,
    /// Heavy-tailed part of the white noise.
    pub heavy_tail: HeavyTailSpec,
}

/// Urban canyon: blocking, NLOS biases and outliers.
///
/// The blocking mask at relative azimuth α (satellite azimuth minus the vehicle's course)
/// is max(min_mask, atan(2 H |sin α| / W)): the edge of a wall of height H (above the
/// antenna) at W/2 to the side of a straight street of width W, seen across the street
/// (α = ±90°) at atan(2H/W) and not at all along it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UrbanCanyonSpec {
    /// C/N0 loss of the satellites still received (diffraction near edges) (dB), ≥ 0.
    pub cn0_loss_db: f64,
    /// Satellites below this elevation are blocked in every direction (deg), in [0, 90).
    pub min_mask_elevation_deg: f64,
    /// Height of the buildings above the antenna (m), ≥ 0 (0: only the uniform mask).
    pub building_height_m: f64,
    /// Width of the street between the building fronts (m), > 0.
    pub street_width_m: f64,
    /// Probability that a satellite still received is a non-line-of-sight reflection, in
    /// [0, 1]; decided once per satellite and segment.
    pub nlos_fraction: f64,
    /// Smallest NLOS excess path (m), ≥ 0.
    pub nlos_bias_min_m: f64,
    /// Largest NLOS excess path (m), ≥ the smallest; each NLOS satellite draws its bias
    /// uniformly in [min, max] once per segment.
    pub nlos_bias_max_m: f64,
    /// Probability of a pseudo-range outlier per satellite and epoch, in [0, 1].
    pub outlier_probability: f64,
    /// Smallest outlier magnitude (m), ≥ 0.
    pub outlier_min_m: f64,
    /// Largest outlier magnitude (m); an outlier is ± U[min, max], sign equally likely.
    pub outlier_max_m: f64,
}

impl UrbanCanyonSpec {
    /// Blocking elevation (rad) in the direction `relative_azimuth_rad` from the course.
    pub fn mask_elevation_rad(&self, relative_azimuth_rad: f64) -> f64 {
        let walls = (2.0 * self.building_height_m * relative_azimuth_rad.sin().abs())
            .atan2(self.street_width_m);
        walls.max(self.min_mask_elevation_deg.to_radians())
    }
}

/// One signal environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Environment {
    /// Thermal noise only (the default outside the listed segments).
    OpenSky,
    /// Canopy attenuation, correlated multipath, heavy tails.
    Foliage(FoliageSpec),
    /// Blocking, NLOS biases, outliers.
    UrbanCanyon(UrbanCanyonSpec),
    /// No GNSS at all.
    Outage,
}

impl Environment {
    /// Short name for reports ("open_sky", "foliage", "urban_canyon", "outage").
    pub fn name(&self) -> &'static str {
        match self {
            Environment::OpenSky => "open_sky",
            Environment::Foliage(_) => "foliage",
            Environment::UrbanCanyon(_) => "urban_canyon",
            Environment::Outage => "outage",
        }
    }

    /// C/N0 loss (dB) the environment applies to every received satellite.
    pub fn cn0_loss_db(&self) -> f64 {
        match self {
            Environment::Foliage(f) => f.cn0_loss_db,
            Environment::UrbanCanyon(u) => u.cn0_loss_db,
            Environment::OpenSky | Environment::Outage => 0.0,
        }
    }
}

/// An environment in force over [start_s, end_s) of scenario time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSegment {
    /// Start (s, scenario time), inclusive.
    pub start_s: f64,
    /// End (s, scenario time), exclusive.
    pub end_s: f64,
    /// The environment.
    pub environment: Environment,
}
