//! The enum-valued parameters' types (the section structs themselves come from the
//! parameter table, `parameters.rs`).

use serde::Deserialize;

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

/// The vehicle carrying the IMU (`constraints.platform`): whether the non-holonomic
/// constraint applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Platform {
    /// `car`: a wheeled road vehicle (NHC on).
    Car,
    /// `robot`: a wheeled ground robot (NHC on).
    Robot,
    /// `pedestrian`: carried by a walker (no NHC: a person steps sideways).
    Pedestrian,
    /// `none`: nothing known of the vehicle (no NHC).
    None,
}

impl Platform {
    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Car => "car",
            Self::Robot => "robot",
            Self::Pedestrian => "pedestrian",
            Self::None => "none",
        }
    }

    /// True for a wheeled vehicle, whose constraint point does not slip sideways.
    pub fn is_wheeled(self) -> bool {
        matches!(self, Self::Car | Self::Robot)
    }
}
