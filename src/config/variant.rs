//! The variant table: what each `filter.variant` is made of — its measurement-noise
//! strategy, the IARF paper's scheme on top of the base filter, its default base filter —
//! and where it comes from. Everything else asks this table: the engine maps each column to
//! its strategy object in one match, validation checks `filter.base` against it, and the
//! tools list the variants from it.
//!
//! Adding a variant: a value of [`FilterVariant`] and its row of [`VARIANTS`] (in the same
//! place of both; a compile-time check keeps them in step), and its preset
//! `params/<name>.yaml`. A variant made of existing columns needs no code elsewhere; a new
//! strategy is a new column value, its implementation (`engine::adaptive_noise` for a noise
//! strategy, `filter::robust_update` for a scheme) and its arm in the one match that maps
//! the column (`NoiseModel::new`, `engine::adaptation`).

use std::fmt;

use serde::de::{self, EnumAccess, VariantAccess, Visitor};
use serde::{Deserialize, Deserializer};

use super::FilterConfig;

/// Which filter runs (`filter.variant`). Every variant shares the engine, the measurement
/// models and the diagnostics, so variants can be compared on the same data; what each one
/// is, is its row of [`VARIANTS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FilterVariant {
    Ekf,
    Eiakf,
    Srmakf,
    Ermakf,
    Ckf,
    AkfAll,
    AkfPartial,
    Iarf,
    ResidualAkf,
}

/// How the measurement-noise covariance R is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NoiseStrategy {
    /// The fixed σ of `gnss.*` (tight) and `loose.*` (loose).
    Fixed,
    /// Per satellite and observable, the windowed innovation covariance less h P⁻ hᵀ, with a
    /// whiteness test and an AR(1) correction (the ERMAKF paper's reference \[24\]).
    Innovation,
    /// Per satellite and observable, the simple redundant-measurement estimate
    /// R = E[∇Z²]/2 over the window (ERMAKF paper, eqs. 12–18).
    RedundantSimple,
    /// The redundant-measurement estimate with random weighting (eq. 19), KDE detection
    /// (eqs. 20–24) and the Burg/Akaike AR variance (eqs. 25–29) (ERMAKF paper).
    RedundantEnhanced,
    /// From the post-update residuals, ε εᵀ + H P̂ Hᵀ over a window (Ding, Wang and Rizos
    /// 2007, eqs. 14–15).
    Residual,
}

/// The IARF paper's scheme run on the base filter (Jiang & Zhang 2018, section 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RobustScheme {
    /// No adaptive factor, no robust step (scheme 1 on the cubature base).
    Plain,
    /// The adaptive factor α of the predicted residual (section 2.2) at every epoch
    /// (scheme 2).
    AdaptiveAll,
    /// The adaptive factor at the epochs that pass the Mahalanobis test (section 3), α = 1
    /// at the others (scheme 3).
    AdaptivePartial,
    /// The robust equivalent covariance R̄ at every epoch, the adaptive factor at the epochs
    /// that pass the Mahalanobis test (section 3, scheme 4).
    AdaptivelyRobust,
}

/// The base filter of the measurement update, resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BaseFilter {
    /// The linearized (extended) update.
    Ekf,
    /// The cubature Kalman filter update (2n points).
    Cubature,
}

impl BaseFilter {
    /// What the filter is called in messages.
    fn noun(self) -> &'static str {
        match self {
            Self::Ekf => "EKF",
            Self::Cubature => "cubature filter",
        }
    }
}

/// Which base filters a variant runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BaseRule {
    /// Either base; `filter.base: auto` picks this one.
    Default(BaseFilter),
    /// The variant is this base filter (`ckf`): `filter.base` may only confirm it.
    Only(BaseFilter),
}

impl BaseRule {
    /// The base of `filter.base: auto`.
    pub fn default_base(self) -> BaseFilter {
        match self {
            Self::Default(base) | Self::Only(base) => base,
        }
    }
}

/// One row of the variant table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VariantSpec {
    pub variant: FilterVariant,
    /// The name used in the parameter file.
    pub name: &'static str,
    pub noise: NoiseStrategy,
    pub scheme: RobustScheme,
    pub base: BaseRule,
    /// One line for the manual.
    pub description: &'static str,
    /// Where the method is described.
    pub reference: &'static str,
}

/// Every variant, in the order of the documentation and of [`FilterVariant`].
pub const VARIANTS: [VariantSpec; 9] = [
    VariantSpec {
        variant: FilterVariant::Ekf,
        name: "ekf",
        noise: NoiseStrategy::Fixed,
        scheme: RobustScheme::Plain,
        base: BaseRule::Default(BaseFilter::Ekf),
        description: "error-state EKF with fixed noise; the baseline of the adaptive variants",
        reference: "ERMAKF paper, eqs. (10)-(11)",
    },
    VariantSpec {
        variant: FilterVariant::Eiakf,
        name: "eiakf",
        noise: NoiseStrategy::Innovation,
        scheme: RobustScheme::Plain,
        base: BaseRule::Default(BaseFilter::Ekf),
        description: "innovation-based adaptive R with a whiteness test and AR(1) correction",
        reference: "ERMAKF paper, reference [24]",
    },
    VariantSpec {
        variant: FilterVariant::Srmakf,
        name: "srmakf",
        noise: NoiseStrategy::RedundantSimple,
        scheme: RobustScheme::Plain,
        base: BaseRule::Default(BaseFilter::Ekf),
        description: "simple redundant-measurement R, E[∇Z²]/2 over the window",
        reference: "ERMAKF paper, eqs. (12)-(18)",
    },
    VariantSpec {
        variant: FilterVariant::Ermakf,
        name: "ermakf",
        noise: NoiseStrategy::RedundantEnhanced,
        scheme: RobustScheme::Plain,
        base: BaseRule::Default(BaseFilter::Ekf),
        description: "enhanced redundant-measurement R: random weighting, KDE, Burg AR variance",
        reference: "ERMAKF paper, eqs. (19)-(29)",
    },
    VariantSpec {
        variant: FilterVariant::Ckf,
        name: "ckf",
        noise: NoiseStrategy::Fixed,
        scheme: RobustScheme::Plain,
        base: BaseRule::Only(BaseFilter::Cubature),
        description: "cubature Kalman filter with fixed noise",
        reference: "IARF paper, section 5, scheme 1",
    },
    VariantSpec {
        variant: FilterVariant::AkfAll,
        name: "akf_all",
        noise: NoiseStrategy::Fixed,
        scheme: RobustScheme::AdaptiveAll,
        base: BaseRule::Default(BaseFilter::Cubature),
        description: "adaptive factor of the predicted residual at every epoch",
        reference: "IARF paper, section 2.2; section 5, scheme 2",
    },
    VariantSpec {
        variant: FilterVariant::AkfPartial,
        name: "akf_partial",
        noise: NoiseStrategy::Fixed,
        scheme: RobustScheme::AdaptivePartial,
        base: BaseRule::Default(BaseFilter::Cubature),
        description: "adaptive factor at the epochs that pass the Mahalanobis test",
        reference: "IARF paper, section 3; section 5, scheme 3",
    },
    VariantSpec {
        variant: FilterVariant::Iarf,
        name: "iarf",
        noise: NoiseStrategy::Fixed,
        scheme: RobustScheme::AdaptivelyRobust,
        base: BaseRule::Default(BaseFilter::Cubature),
        description: "robust R̄ at every epoch, adaptive factor at the epochs passing the test",
        reference: "IARF paper, section 3; section 5, scheme 4",
    },
    VariantSpec {
        variant: FilterVariant::ResidualAkf,
        name: "residual_akf",
        noise: NoiseStrategy::Residual,
        scheme: RobustScheme::Plain,
        base: BaseRule::Default(BaseFilter::Ekf),
        description: "R from the post-update residuals (online stochastic modelling)",
        reference: "Ding, Wang and Rizos 2007, eqs. (14)-(15)",
    },
];

// Row i of the table describes the enum's value i: `FilterVariant::spec` relies on it.
const _: () = {
    let mut i = 0;
    while i < VARIANTS.len() {
        assert!(
            VARIANTS[i].variant as usize == i,
            "VARIANTS must list the variants in the order of FilterVariant"
        );
        i += 1;
    }
};

/// The names of the table, for the error of an unknown name.
const NAMES: [&str; VARIANTS.len()] = {
    let mut names = [""; VARIANTS.len()];
    let mut i = 0;
    while i < VARIANTS.len() {
        names[i] = VARIANTS[i].name;
        i += 1;
    }
    names
};

impl FilterVariant {
    /// Every variant, in the order of the table.
    pub const ALL: [FilterVariant; VARIANTS.len()] = {
        let mut all = [FilterVariant::Ekf; VARIANTS.len()];
        let mut i = 0;
        while i < VARIANTS.len() {
            all[i] = VARIANTS[i].variant;
            i += 1;
        }
        all
    };

    /// The variant's row of the table.
    pub fn spec(self) -> &'static VariantSpec {
        &VARIANTS[self as usize]
    }

    /// The name used in the parameter file.
    pub fn as_str(self) -> &'static str {
        self.spec().name
    }

    /// The variant of a parameter-file name.
    pub fn from_name(name: &str) -> Option<Self> {
        VARIANTS.iter().find(|s| s.name == name).map(|s| s.variant)
    }

    /// Why `filter.base` may not be `base` for this variant (None: it may).
    pub fn base_conflict(self, base: FilterBase) -> Option<String> {
        let spec = self.spec();
        let (BaseRule::Only(only), Some(requested)) = (spec.base, base.explicit()) else {
            return None;
        };
        if requested == only {
            return None;
        }
        let alternative = VARIANTS.iter().find(|s| {
            s.noise == spec.noise
                && s.scheme == spec.scheme
                && s.base == BaseRule::Default(requested)
        });
        Some(match alternative {
            Some(alt) => format!(
                "variant {} is the {}; use variant {} for the {}",
                spec.name,
                only.noun(),
                alt.name,
                requested.noun()
            ),
            None => format!("variant {} runs only on the {}", spec.name, only.noun()),
        })
    }
}

/// Read by name through the table; the errors are those of a derived enum.
impl<'de> Deserialize<'de> for FilterVariant {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ByName;
        impl<'de> Visitor<'de> for ByName {
            type Value = FilterVariant;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a filter variant")
            }

            fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Self::Value, A::Error> {
                let (name, value): (String, _) = data.variant()?;
                value.unit_variant()?;
                FilterVariant::from_name(&name)
                    .ok_or_else(|| de::Error::unknown_variant(&name, &NAMES))
            }
        }
        deserializer.deserialize_enum("FilterVariant", &NAMES, ByName)
    }
}

/// The base filter of the measurement update (`filter.base`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FilterBase {
    /// `auto`: the variant's default base of [`VARIANTS`] (cubature for `ckf`, `akf_all`,
    /// `akf_partial` and `iarf`, whose paper runs all its schemes on the CKF; the EKF for
    /// the others).
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

    /// The base asked for, None for `auto`.
    fn explicit(self) -> Option<BaseFilter> {
        match self {
            Self::Auto => None,
            Self::Ekf => Some(BaseFilter::Ekf),
            Self::Cubature => Some(BaseFilter::Cubature),
        }
    }
}

impl FilterConfig {
    /// The base filter of the measurement update: `filter.base`, or the variant's default
    /// for `auto`.
    pub fn base_filter(&self) -> BaseFilter {
        self.base
            .explicit()
            .unwrap_or_else(|| self.variant.spec().base.default_base())
    }

    /// True when the measurement update is the cubature one (`filter.base` resolved).
    pub fn uses_cubature(&self) -> bool {
        self.base_filter() == BaseFilter::Cubature
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_read_back() {
        for v in FilterVariant::ALL {
            assert_eq!(FilterVariant::from_name(v.as_str()), Some(v));
            let yaml: FilterVariant = serde_yaml::from_str(v.as_str()).unwrap();
            assert_eq!(yaml, v);
        }
        let e = serde_yaml::from_str::<FilterVariant>("nope").unwrap_err();
        assert!(e
            .to_string()
            .contains("unknown variant `nope`, expected one of `ekf`"));
    }

    #[test]
    fn a_base_is_refused_only_where_the_row_fixes_another() {
        for spec in VARIANTS {
            for base in [FilterBase::Auto, FilterBase::Ekf, FilterBase::Cubature] {
                let refused = match (spec.base, base.explicit()) {
                    (BaseRule::Only(only), Some(asked)) => asked != only,
                    _ => false,
                };
                let conflict = spec.variant.base_conflict(base);
                assert_eq!(conflict.is_some(), refused, "{} {base:?}", spec.name);
            }
        }
        assert_eq!(
            FilterVariant::Ckf.base_conflict(FilterBase::Ekf).unwrap(),
            "variant ckf is the cubature filter; use variant ekf for the EKF"
        );
    }
}
