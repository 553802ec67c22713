//! Serde helper for `float64[N]` fields with N above serde's derive limit of 32
//! (the 6×6 covariances, `float64[36]`).
//!
//! A CDR fixed-size array carries no length: it is written as an N-tuple, exactly as
//! serde's own arrays up to 32 elements are.

use std::fmt;

use serde::de::{self, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserializer, Serializer};

/// Serializes `array` as an N-tuple (no length prefix). Use with `#[serde(with = ...)]`.
pub fn serialize<S: Serializer, const N: usize>(
    array: &[f64; N],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    let mut tuple = serializer.serialize_tuple(N)?;
    for element in array {
        tuple.serialize_element(element)?;
    }
    tuple.end()
}

/// Deserializes an N-tuple of `f64` into an array. Use with `#[serde(with = ...)]`.
pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(
    deserializer: D,
) -> Result<[f64; N], D::Error> {
    deserializer.deserialize_tuple(N, ArrayVisitor::<N>)
}

/// Fills a `[f64; N]` from exactly N sequence elements.
struct ArrayVisitor<const N: usize>;

impl<'de, const N: usize> Visitor<'de> for ArrayVisitor<N> {
    type Value = [f64; N];

    fn expecting(&self, formatter: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(formatter, "an array of {N} float64")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut array = [0.0; N];
        for (index, slot) in array.iter_mut().enumerate() {
            *slot = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(index, &self))?;
        }
        Ok(array)
    }
}
