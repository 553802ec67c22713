//! The enum-valued parameters' types (the section structs themselves come from the
//! parameter table, `parameters.rs`).

use serde::Deserialize;

use super::FilterConfig;

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
