//! The value types of the parameter file: how each is read from YAML (serde), written back
//! for the echo and the parameter services, and checked against its range.

use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_yaml::Value;

use super::spec::{Kind, OutOfRange, Range};
use super::{
    AdaptiveFactorKind, Coupling, EquivalentWeightKind, FilterBase, FilterVariant, Platform,
};
use crate::adaptive::burg::OrderCriterion;
use crate::gnss::Constellation;

/// A type a parameter has in the file (human units).
pub trait FileValue: DeserializeOwned {
    /// The type as served over ROS and named in the manual.
    const KIND: Kind;
    /// Whether `null` is a value (it means "not set", e.g. "from the first fix").
    const NULLABLE: bool = false;
    /// The value as YAML, for the echo and the parameter services.
    fn to_yaml(&self) -> Value;
    /// Whether the value lies in `range` (`unit` completes the message).
    fn check(&self, range: &Range, unit: &str) -> Result<(), OutOfRange>;
}

impl FileValue for f64 {
    const KIND: Kind = Kind::Double;
    fn to_yaml(&self) -> Value {
        Value::from(*self)
    }
    fn check(&self, range: &Range, unit: &str) -> Result<(), OutOfRange> {
        range.check_number(*self, unit)
    }
}

impl FileValue for bool {
    const KIND: Kind = Kind::Bool;
    fn to_yaml(&self) -> Value {
        Value::Bool(*self)
    }
    fn check(&self, _: &Range, _: &str) -> Result<(), OutOfRange> {
        Ok(())
    }
}

impl FileValue for u64 {
    const KIND: Kind = Kind::Integer;
    fn to_yaml(&self) -> Value {
        Value::from(*self)
    }
    fn check(&self, range: &Range, _: &str) -> Result<(), OutOfRange> {
        range.check_count(*self)
    }
}

impl FileValue for usize {
    const KIND: Kind = Kind::Integer;
    fn to_yaml(&self) -> Value {
        Value::from(*self)
    }
    fn check(&self, range: &Range, _: &str) -> Result<(), OutOfRange> {
        // usize is at most 64 bits on every supported target; saturate otherwise.
        range.check_count(u64::try_from(*self).unwrap_or(u64::MAX))
    }
}

impl FileValue for [f64; 3] {
    const KIND: Kind = Kind::DoubleArray(3);
    fn to_yaml(&self) -> Value {
        Value::Sequence(self.iter().map(|&x| Value::from(x)).collect())
    }
    fn check(&self, range: &Range, unit: &str) -> Result<(), OutOfRange> {
        range.check_triple(self, unit)
    }
}

impl<T: FileValue> FileValue for Option<T> {
    const KIND: Kind = T::KIND;
    const NULLABLE: bool = true;
    fn to_yaml(&self) -> Value {
        self.as_ref().map_or(Value::Null, T::to_yaml)
    }
    fn check(&self, range: &Range, unit: &str) -> Result<(), OutOfRange> {
        self.as_ref().map_or(Ok(()), |v| v.check(range, unit))
    }
}

impl FileValue for Vec<ConstellationName> {
    const KIND: Kind = Kind::TextArray;
    fn to_yaml(&self) -> Value {
        Value::Sequence(self.iter().map(|c| c.as_str().into()).collect())
    }
    fn check(&self, range: &Range, _: &str) -> Result<(), OutOfRange> {
        range.check_list(self)
    }
}

/// Enums written by name: any of their names is in range.
macro_rules! named_values {
    ($($t:ty),+) => {$(
        impl FileValue for $t {
            const KIND: Kind = Kind::Text;
            fn to_yaml(&self) -> Value {
                Value::String(self.as_str().to_owned())
            }
            fn check(&self, _: &Range, _: &str) -> Result<(), OutOfRange> {
                Ok(())
            }
        }
    )+};
}

named_values!(
    FilterVariant,
    FilterBase,
    Coupling,
    AdaptiveFactorKind,
    EquivalentWeightKind,
    OrderCriterion,
    ConstellationName,
    Platform
);

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
