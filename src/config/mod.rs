//! Configuration: one YAML file in the ROS 2 parameter layout, in human units, converted to
//! SI once and validated.
//!
//! ```yaml
//! gnss_ins_node:          # any single node name, or /** for every node
//!   ros__parameters:
//!     imu:
//!       gyro_bias_deg_per_h: 0.5
//! ```
//!
//! Every key is optional and takes its documented default (see `params/ekf.yaml`, the
//! manual). An unknown key, a wrong type or an out-of-range value is an error naming the key
//! and the origin, and nothing is applied. The core reads no files: the caller hands over
//! the text and the name to quote in messages.

mod convert;
mod error;
mod layout;
mod raw;
mod sections;
mod tree;
mod validate;

use serde_yaml::{Mapping, Value};

pub use convert::{
    si_to_human, M_S2_PER_UG, RAD_PER_DEG, RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H, RAD_S_PER_DEG_H,
    STANDARD_GRAVITY_M_S2,
};
pub use error::ConfigError;
pub use raw::{
    ConstellationName, RawClock, RawConfig, RawGnss, RawImu, RawInit, RawMounting, RawOutput,
};
pub use sections::{
    AdaptiveConfig, AdaptiveFactorKind, ClockConfig, Config, Coupling, EngineConfig,
    EquivalentWeightKind, FilterBase, FilterConfig, FilterVariant, GnssConfig, ImuConfig,
    InitConfig, LooseConfig, MountingConfig, OutputConfig, RobustConfig,
};

/// The origin quoted in errors from [`Config::set_parameter`].
pub const PARAMETER_OVERRIDE_ORIGIN: &str = "parameter override";

impl Default for Config {
    /// The documented defaults (those of `params/ekf.yaml`).
    fn default() -> Self {
        Config::from(&RawConfig::default())
    }
}

impl Config {
    /// Parses, converts and validates a parameter file. `origin` is the name quoted in
    /// errors (normally the file path); the caller reads the file.
    pub fn from_yaml_str(text: &str, origin: &str) -> Result<Config, ConfigError> {
        let document: Value = serde_yaml::from_str(text).map_err(|e| yaml_error(&e, origin))?;
        let parameters = layout::parameters_of(&document, origin)?;
        Self::from_parameters(&parameters, origin)
    }

    /// The effective configuration as a ROS 2 parameter file in human units (under the
    /// node name `/**`), for echoing at start. Loading it gives back this configuration;
    /// the mounting rotation is echoed as Euler angles rounded to 1e-12 deg, so it comes
    /// back exactly when it was loaded from angles with at most 12 decimals.
    pub fn to_human_yaml(&self) -> String {
        let header = "# adaptive_gnss_ins effective configuration (human units)\n";
        header.to_owned() + &layout::to_parameter_file(&self.human_tree())
    }

    /// Every parameter of this configuration as (`section.key`, current value in human
    /// units), in file order: the names and values the ROS parameter services list.
    pub fn parameters(&self) -> Vec<(String, Value)> {
        layout::flatten(&self.human_tree())
    }

    /// Sets one parameter, e.g. `("imu.gyro_bias_deg_per_h", "0.3")`, with the validation of
    /// the file. On error `self` is unchanged; errors name [`PARAMETER_OVERRIDE_ORIGIN`].
    pub fn set_parameter(&mut self, dotted_key: &str, yaml_value: &str) -> Result<(), ConfigError> {
        let origin = PARAMETER_OVERRIDE_ORIGIN;
        let value: Value = serde_yaml::from_str(yaml_value).map_err(|e| yaml_error(&e, origin))?;
        let mut tree = self.human_tree();
        layout::set_dotted(&mut tree, dotted_key, value, origin)?;
        *self = Self::from_parameters(&tree, origin)?;
        Ok(())
    }

    fn human_tree(&self) -> Mapping {
        RawConfig::from(self).to_tree()
    }

    fn from_parameters(parameters: &Mapping, origin: &str) -> Result<Config, ConfigError> {
        let checked = layout::check_known_keys(parameters, origin)?;
        let raw: RawConfig =
            serde_path_to_error::deserialize(Value::Mapping(checked)).map_err(|e| {
                ConfigError::WrongType {
                    origin: origin.to_owned(),
                    key: e.path().to_string(),
                    detail: e.inner().to_string(),
                }
            })?;
        validate::validate(&raw, origin)?;
        Ok(Config::from(&raw))
    }
}

fn yaml_error(e: &serde_yaml::Error, origin: &str) -> ConfigError {
    let location = e.location();
    let line = location.as_ref().map(|l| l.line());
    let column = location.as_ref().map(|l| l.column());
    let mut message = e.to_string();
    if let (Some(line), Some(column)) = (line, column) {
        // The parser's own text repeats the location that the error's Display shows.
        message = message.replace(&format!(" at line {line} column {column}"), "");
    }
    ConfigError::Yaml {
        origin: origin.to_owned(),
        line,
        column,
        message,
    }
}
