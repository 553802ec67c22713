//! The ROS 2 parameter-file layout around the sections: finding `ros__parameters`, refusing
//! unknown names before serde sees them (so the message can list the known ones), editing
//! one dotted key, and writing the tree back out as a parameter file.

use serde_yaml::{Mapping, Value};

use super::raw::RawConfig;
use super::ConfigError;

/// The key under the node name that holds the parameters.
const ROS_PARAMETERS: &str = "ros__parameters";
/// The node name the echo is written under: ROS 2 applies it to every node.
const WILDCARD_NODE: &str = "/**";

/// The mapping below `<node>:` / `ros__parameters:` of a parsed parameter file.
/// An empty `ros__parameters:` is an empty mapping (every key at its default).
pub fn parameters_of(document: &Value, origin: &str) -> Result<Mapping, ConfigError> {
    let layout_error = |found: String| ConfigError::Layout {
        origin: origin.to_owned(),
        sections: section_names(),
        found,
    };
    let nodes = match document {
        Value::Mapping(nodes) => nodes,
        other => return Err(layout_error(describe(other))),
    };
    let mut entries = nodes.iter();
    let (node, node_value) = match (entries.next(), entries.next()) {
        (Some((node, value)), None) if node.is_string() => (node, value),
        _ => return Err(layout_error(format!("top-level {}", keys_phrase(nodes)))),
    };
    let node_name = node.as_str().unwrap_or_default();
    let inner = match node_value {
        Value::Mapping(inner) => inner,
        other => {
            return Err(layout_error(format!(
                "`{node_name}:` holding {}",
                describe(other)
            )))
        }
    };
    let mut inner_entries = inner.iter();
    match (inner_entries.next(), inner_entries.next()) {
        (Some((key, value)), None) if key.as_str() == Some(ROS_PARAMETERS) => match value {
            Value::Mapping(parameters) => Ok(parameters.clone()),
            Value::Null => Ok(Mapping::new()),
            other => Err(layout_error(format!(
                "`{ROS_PARAMETERS}:` holding {}",
                describe(other)
            ))),
        },
        _ => Err(layout_error(format!(
            "keys {} under `{node_name}:`",
            key_list(inner)
        ))),
    }
}

/// Refuses any section or key that the default tree does not have, and turns an empty
/// section (`imu:` with nothing below) into an empty mapping.
pub fn check_known_keys(parameters: &Mapping, origin: &str) -> Result<Mapping, ConfigError> {
    let known = RawConfig::default().to_tree();
    let mut checked = Mapping::new();
    for (section, keys) in parameters {
        let section_name = key_text(section);
        let known_keys = match known.get(section) {
            Some(Value::Mapping(known_keys)) => known_keys,
            _ => {
                return Err(ConfigError::UnknownKey {
                    origin: origin.to_owned(),
                    key: section_name,
                    known: key_list(&known),
                })
            }
        };
        let keys = match keys {
            Value::Mapping(keys) => keys.clone(),
            Value::Null => Mapping::new(),
            other => {
                return Err(ConfigError::WrongType {
                    origin: origin.to_owned(),
                    key: section_name,
                    detail: format!(
                        "expected a mapping of parameters, found {}",
                        describe(other)
                    ),
                })
            }
        };
        if let Some(unknown) = keys.keys().find(|key| !known_keys.contains_key(*key)) {
            return Err(ConfigError::UnknownKey {
                origin: origin.to_owned(),
                key: format!("{section_name}.{}", key_text(unknown)),
                known: key_list(known_keys),
            });
        }
        checked.insert(section.clone(), Value::Mapping(keys));
    }
    Ok(checked)
}

/// Replaces `section.key` in `tree` by `value`; the key must already be there.
pub fn set_dotted(
    tree: &mut Mapping,
    dotted_key: &str,
    value: Value,
    origin: &str,
) -> Result<(), ConfigError> {
    let unknown = |known: String| ConfigError::UnknownKey {
        origin: origin.to_owned(),
        key: dotted_key.to_owned(),
        known,
    };
    let Some((section, key)) = dotted_key.split_once('.') else {
        return Err(unknown(key_list(tree)));
    };
    let sections = key_list(tree);
    let Some(Value::Mapping(keys)) = tree.get_mut(section) else {
        return Err(unknown(sections));
    };
    match keys.get_mut(key) {
        Some(slot) => {
            *slot = value;
            Ok(())
        }
        None => Err(unknown(key_list(keys))),
    }
}

/// `(section.key, value)` for every parameter of the tree, in file order.
pub fn flatten(tree: &Mapping) -> Vec<(String, Value)> {
    tree.iter()
        .flat_map(|(section, keys)| {
            let section = key_text(section);
            let keys = keys.as_mapping().cloned().unwrap_or_default();
            keys.into_iter()
                .map(move |(key, value)| (format!("{section}.{}", key_text(&key)), value))
        })
        .collect()
}

/// The tree as a ROS 2 parameter file under the wildcard node name `/**`.
pub fn to_parameter_file(tree: &Mapping) -> String {
    let mut text = format!("{WILDCARD_NODE}:\n  {ROS_PARAMETERS}:\n");
    for (section, keys) in tree {
        text.push_str(&format!("    {}:\n", key_text(section)));
        for (key, value) in keys.as_mapping().into_iter().flatten() {
            text.push_str(&format!(
                "      {}: {}\n",
                key_text(key),
                scalar_or_list(value)
            ));
        }
    }
    text
}

/// Flow-style YAML for the values the tree holds: scalars and lists of scalars.
fn scalar_or_list(value: &Value) -> String {
    match value {
        Value::Null => "null".to_owned(),
        Value::Bool(b) => b.to_string(),
        // serde_yaml prints floats with the shortest text that reads back to the same bits.
        Value::Number(n) => n.to_string(),
        Value::String(s) => s.clone(),
        Value::Sequence(items) => {
            let items: Vec<String> = items.iter().map(scalar_or_list).collect();
            format!("[{}]", items.join(", "))
        }
        Value::Mapping(_) | Value::Tagged(_) => describe(value),
    }
}

fn section_names() -> String {
    key_list(&RawConfig::default().to_tree())
}

fn key_text(key: &Value) -> String {
    match key {
        Value::String(s) => s.clone(),
        other => scalar_or_list(other),
    }
}

fn key_list(mapping: &Mapping) -> String {
    let names: Vec<String> = mapping.keys().map(key_text).collect();
    names.join(", ")
}

fn keys_phrase(mapping: &Mapping) -> String {
    if mapping.is_empty() {
        "no keys".to_owned()
    } else {
        format!("keys {}", key_list(mapping))
    }
}

fn describe(value: &Value) -> String {
    match value {
        Value::Null => "nothing (null)".to_owned(),
        Value::Bool(_) => "a boolean".to_owned(),
        Value::Number(_) => "a number".to_owned(),
        Value::String(_) => "a string".to_owned(),
        Value::Sequence(_) => "a list".to_owned(),
        Value::Mapping(m) => format!("a mapping with {}", keys_phrase(m)),
        Value::Tagged(_) => "a tagged value".to_owned(),
    }
}
