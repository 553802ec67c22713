//! Changing parameters of a running engine (the node's `set_parameters` service).

use std::sync::LazyLock;

use crate::config::{parameter_table, Config};

use super::Engine;

/// The parameters (dotted names of the parameter file) a running engine takes over at
/// once, without a restart: those the parameter table marks `at_run_time`.
///
/// Choice (in the table): exactly those the engine reads from its configuration at every
/// use and from which it derives no state: the satellite masks, gate and fixed σ model of
/// `gnss.*`, the fix weighting of `loose.*`, the IMU gap limit and the output rate.
/// Everything else is built into the filter when the engine starts (the variant, the
/// process noise from `imu.*` and `clock.*`, the adaptive and robust estimators'
/// constants, the mounting, the start-up settings, the buffer length) and changing it
/// would need a new filter, which for a moving vehicle means a new levelling at rest.
pub static RUNTIME_PARAMETERS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    parameter_table()
        .iter()
        .filter(|p| p.runtime)
        .map(|p| p.name)
        .collect()
});

/// A new configuration differs from the running one in a parameter that is not one of
/// [`RUNTIME_PARAMETERS`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the change needs a new filter (only {} can change while running)", RUNTIME_PARAMETERS.join(", "))]
pub struct NotRuntimeTunable;

/// `base` with the values of every runtime parameter taken from `from`.
fn with_runtime_values(base: &Config, from: &Config) -> Config {
    let mut c = base.clone();
    for p in parameter_table().iter().filter(|p| p.runtime) {
        p.take_value(&mut c, from);
    }
    c
}

impl Engine {
    /// Replaces the configuration of the running engine by `config`, which must differ only
    /// in [`RUNTIME_PARAMETERS`]; the filter state and everything learned are kept. On
    /// error nothing changes.
    pub fn retune(&mut self, config: Config) -> Result<(), NotRuntimeTunable> {
        if with_runtime_values(&self.config, &config) != config {
            return Err(NotRuntimeTunable);
        }
        self.config = config;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid value for `key` different from its default.
    fn other_value(key: &str, config: &Config) -> String {
        let (_, current) = config
            .parameters()
            .into_iter()
            .find(|(k, _)| k == key)
            .unwrap_or_else(|| panic!("{key} is not a parameter"));
        match current {
            serde_yaml::Value::Bool(b) => (!b).to_string(),
            serde_yaml::Value::Number(n) => {
                let v = n.as_f64().unwrap();
                format!("{:?}", if v == 0.0 { 1.0 } else { v * 1.5 })
            }
            other => panic!("{key}: no test value for {other:?}"),
        }
    }

    #[test]
    fn every_runtime_parameter_is_taken_over_and_applied() {
        for key in RUNTIME_PARAMETERS.iter() {
            let mut engine = Engine::new(Config::default());
            let mut changed = engine.config().clone();
            changed
                .set_parameter(key, &other_value(key, &changed))
                .unwrap_or_else(|e| panic!("{key}: {e}"));
            assert_ne!(&changed, engine.config(), "{key}");
            engine
                .retune(changed.clone())
                .unwrap_or_else(|e| panic!("{key}: {e}"));
            assert_eq!(engine.config(), &changed, "{key}");
        }
    }

    #[test]
    fn other_parameters_are_refused_and_nothing_changes() {
        for (key, value) in [
            ("filter.variant", "ermakf"),
            ("imu.gyro_bias_deg_per_h", "0.3"),
            ("adaptive.window_size_m", "50"),
            ("gnss.constellations", "[gps]"),
            ("engine.imu_buffer_s", "3.0"),
            ("output.datum_llh_deg_m", "[39.0, 117.0, 10.0]"),
        ] {
            let mut engine = Engine::new(Config::default());
            let mut changed = engine.config().clone();
            changed
                .set_parameter(key, value)
                .unwrap_or_else(|e| panic!("{key}: {e}"));
            assert_eq!(engine.retune(changed), Err(NotRuntimeTunable), "{key}");
            assert_eq!(engine.config(), &Config::default(), "{key}");
        }
    }
}
