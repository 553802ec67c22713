//! Configuration: parameters in the ROS 2 parameter-file layout, in human units, checked
//! and converted to SI once.
//!
//! ```yaml
//! gnss_ins_node:          # the node name, its fully qualified name, or /** for every node
//!   ros__parameters:
//!     imu:
//!       gyro_bias_deg_per_h: 0.5
//!     filter.variant: ermakf    # a dotted key is the same parameter as a nested one
//! ```
//!
//! Every parameter is declared once, in the table of `parameters.rs`, with its type,
//! unit, default, range, run-time flag, SI conversion and manual text; the section
//! structs, the loader, the echo and the manual (`params/defaults.yaml`, `docs/parameters.md`)
//! come from it. Every key is optional and takes its default. An unknown key, a wrong
//! type or an out-of-range value is an error naming the key and the origin, and nothing
//! is applied. The core reads no files: the caller hands over the text and the name to
//! quote in messages.

mod convert;
mod error;
mod file_value;
pub mod manual;
mod param_file;
mod parameters;
mod sections;
mod spec;
mod table;
mod validate;
mod variant;

use std::collections::HashMap;

use serde_yaml::Value;

pub use convert::{
    si_to_human, M_S2_PER_UG, RAD_PER_DEG, RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H, RAD_S_PER_DEG_H,
    STANDARD_GRAVITY_M_S2,
};
pub use error::ConfigError;
pub use param_file::{NodeParameters, MAX_FILE_BYTES};
pub use parameters::{
    AdaptiveConfig, ClockConfig, Config, ConstraintsConfig, DualAntennaConfig, EngineConfig,
    FilterConfig, GnssConfig, ImuConfig, InitConfig, LooseConfig, MountingConfig, OutputConfig,
    RobustConfig, WheelOdometryConfig,
};
pub use sections::{AdaptiveFactorKind, Coupling, EquivalentWeightKind, Platform};
pub use spec::{Interval, Kind, Range};
pub use table::{yaml_text, Parameter};
pub use variant::{
    BaseFilter, BaseRule, FilterBase, FilterVariant, NoiseStrategy, RobustScheme, VariantSpec,
    VARIANTS,
};

use table::WriteError;

/// The origin quoted in errors from [`Config::set_parameter`].
pub const PARAMETER_OVERRIDE_ORIGIN: &str = "parameter override";

/// Every parameter, in file order.
pub fn parameter_table() -> &'static [Parameter] {
    parameters::PARAMETERS
}

/// The parameter called `name` (`section.key`).
pub fn parameter(name: &str) -> Option<&'static Parameter> {
    parameters::PARAMETERS.iter().find(|p| p.name == name)
}

/// Every section name in file order with its manual text.
pub fn sections() -> impl Iterator<Item = (&'static str, String)> {
    parameters::SECTIONS
        .iter()
        .map(|(name, doc)| (*name, table::join_doc(doc)))
}

fn section_names() -> Vec<&'static str> {
    parameters::SECTIONS.iter().map(|(name, _)| *name).collect()
}

/// The node entries of a parameter file (any number, rcl's layout); `origin` is quoted in
/// errors. The text is size- and depth-checked before it is parsed.
pub fn parse_parameter_file(text: &str, origin: &str) -> Result<Vec<NodeParameters>, ConfigError> {
    param_file::parse(text, origin)
}

/// A parameter value written as YAML text (a `-p name:=value`), checked as a file is.
pub fn parse_parameter_value(text: &str, origin: &str) -> Result<Value, ConfigError> {
    param_file::parse_value(text, origin)
}

/// One parameter value and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    /// Dotted name.
    pub name: String,
    /// The value as written (human units).
    pub value: Value,
    /// The file or override it came from, quoted in errors.
    pub origin: String,
}

impl Config {
    /// Parses, converts and checks a parameter file that holds one node entry (any node
    /// name): one configuration. `origin` is the name quoted in errors (normally the file
    /// path); the caller reads the file.
    pub fn from_yaml_str(text: &str, origin: &str) -> Result<Config, ConfigError> {
        let entries = param_file::parse(text, origin)?;
        let [entry] = entries.as_slice() else {
            let nodes: Vec<&str> = entries.iter().map(|e| e.node.as_str()).collect();
            return Err(ConfigError::layout(
                origin,
                format!(
                    "{} node entries ({}); a configuration file holds one",
                    nodes.len(),
                    ConfigError::shortened(&nodes.join(", "))
                ),
            ));
        };
        Config::default().with(entry.values.iter().map(|(name, value)| Assignment {
            name: name.clone(),
            value: value.clone(),
            origin: origin.to_owned(),
        }))
    }

    /// This configuration with `assignments` applied in order (a later value of a
    /// parameter replaces an earlier one) and checked. On error nothing is applied.
    pub fn with(
        &self,
        assignments: impl IntoIterator<Item = Assignment>,
    ) -> Result<Config, ConfigError> {
        let mut config = self.clone();
        let mut origins: HashMap<String, String> = HashMap::new();
        let mut last_origin = String::new();
        for a in assignments {
            apply(&mut config, &a.name, a.value, &a.origin)?;
            origins.insert(a.name, a.origin.clone());
            last_origin = a.origin;
        }
        validate::relations(&config).map_err(|c| {
            let origin = origins
                .get(c.key)
                .or_else(|| origins.get(c.other))
                .unwrap_or(&last_origin);
            ConfigError::Invalid {
                origin: origin.clone(),
                key: c.key.to_owned(),
                value: c.value,
                reason: c.reason,
            }
        })?;
        Ok(config)
    }

    /// The effective configuration as a ROS 2 parameter file in human units (under the
    /// node name `/**`), for echoing at start. Loading it gives back this configuration;
    /// the mounting rotation is echoed as Euler angles rounded to 1e-12 deg, so it comes
    /// back exactly when it was loaded from angles with at most 12 decimals.
    pub fn to_human_yaml(&self) -> String {
        let header = "# adaptive_gnss_ins effective configuration (human units)\n";
        header.to_owned() + &manual::values_file(self)
    }

    /// Every parameter of this configuration as (`section.key`, current value in human
    /// units), in file order: the names and values the ROS parameter services list.
    pub fn parameters(&self) -> Vec<(String, Value)> {
        parameter_table()
            .iter()
            .map(|p| (p.name.to_owned(), p.value(self)))
            .collect()
    }

    /// Sets one parameter, e.g. `("imu.gyro_bias_deg_per_h", "0.3")`, with the checks of
    /// the file. On error `self` is unchanged; errors name [`PARAMETER_OVERRIDE_ORIGIN`].
    pub fn set_parameter(&mut self, dotted_key: &str, yaml_value: &str) -> Result<(), ConfigError> {
        let origin = PARAMETER_OVERRIDE_ORIGIN;
        let value = param_file::parse_value(yaml_value, origin)?;
        *self = self.with([Assignment {
            name: dotted_key.to_owned(),
            value,
            origin: origin.to_owned(),
        }])?;
        Ok(())
    }
}

/// Writes one value into `config`, or says why not.
fn apply(config: &mut Config, name: &str, value: Value, origin: &str) -> Result<(), ConfigError> {
    if let Some(p) = parameter(name) {
        return (p.write)(config, value).map_err(|e| match e {
            WriteError::Type { path, detail } => ConfigError::WrongType {
                origin: origin.to_owned(),
                key: format!("{name}{path}"),
                detail: ConfigError::shortened(&detail),
            },
            WriteError::Range { value, reason } => ConfigError::Invalid {
                origin: origin.to_owned(),
                key: name.to_owned(),
                value: ConfigError::shortened(&value),
                reason,
            },
        });
    }
    let sections = section_names();
    let unknown = |key: &str, known: String| ConfigError::UnknownKey {
        origin: origin.to_owned(),
        key: ConfigError::shortened(key),
        known,
    };
    if sections.contains(&name) {
        // A section with nothing below it (`init:`) leaves every key at its value.
        return match value {
            Value::Null => Ok(()),
            Value::Mapping(m) if m.is_empty() => Ok(()),
            other => Err(ConfigError::WrongType {
                origin: origin.to_owned(),
                key: name.to_owned(),
                detail: format!(
                    "expected a mapping of parameters, found {}",
                    param_file::describe(&other)
                ),
            }),
        };
    }
    let section = name.split_once('.').map_or(name, |(s, _)| s);
    if sections.contains(&section) {
        let keys: Vec<&str> = parameter_table()
            .iter()
            .filter(|p| p.section() == section)
            .map(|p| p.key())
            .collect();
        Err(unknown(name, keys.join(", ")))
    } else {
        Err(unknown(name, sections.join(", ")))
    }
}
