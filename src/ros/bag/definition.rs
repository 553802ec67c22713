//! The full message definition stored in an MCAP schema of encoding `ros2msg`: the type's
//! own `.msg` text, then, for every nested non-builtin type, a line of 80 `=`, a line
//! `MSG: pkg/Type` and that type's text (the layout rosbag2 and Foxglove use).
//!
//! Choice: nested types are appended depth-first, each once, the dependencies of one text
//! in sorted order, which is the order rosbag2's MCAP plugin produces; readers do not
//! depend on the order.

use std::collections::BTreeSet;

use super::schemas::definition_text;

/// Field types that are not messages.
const PRIMITIVE_TYPES: &[&str] = &[
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
    "uint32", "int64", "uint64", "string", "wstring",
];

/// Line separating two definitions.
const SEPARATOR: &str =
    "================================================================================";

/// Deepest nesting followed before giving up (guards against a cyclic table).
const MAX_DEPTH: usize = 32;

/// A type whose definition text is unknown.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MissingDefinition {
    /// The `pkg/Type` without a known text.
    pub type_name: String,
}

/// `pkg/msg/Type` or `pkg/Type` -> `pkg/Type`.
pub fn short_type_name(type_name: &str) -> String {
    match type_name.split('/').collect::<Vec<_>>().as_slice() {
        [package, "msg", name] => format!("{package}/{name}"),
        _ => type_name.to_string(),
    }
}

/// The full `ros2msg` definition of `type_name` (`pkg/msg/Type` or `pkg/Type`).
pub fn full_definition(type_name: &str) -> Result<String, MissingDefinition> {
    let root = short_type_name(type_name);
    let mut seen = BTreeSet::from([root.clone()]);
    let mut text = String::new();
    append_definition(&root, &mut seen, &mut text, 0)?;
    Ok(text)
}

/// Appends the text of `short_name` and, recursively, of the types it nests not yet in `seen`.
fn append_definition(
    short_name: &str,
    seen: &mut BTreeSet<String>,
    out: &mut String,
    depth: usize,
) -> Result<(), MissingDefinition> {
    let missing = || MissingDefinition {
        type_name: short_name.to_string(),
    };
    if depth > MAX_DEPTH {
        return Err(missing());
    }
    let text = definition_text(short_name).ok_or_else(missing)?;
    out.push_str(text);
    let package = short_name.split('/').next().unwrap_or_default();
    for dependency in nested_types(text, package) {
        if seen.insert(dependency.clone()) {
            out.push('\n');
            out.push_str(SEPARATOR);
            out.push_str("\nMSG: ");
            out.push_str(&dependency);
            out.push('\n');
            append_definition(&dependency, seen, out, depth + 1)?;
        }
    }
    Ok(())
}

/// The message types (`pkg/Type`) that the fields of `text` use, sorted; names without a
/// package belong to `package`.
fn nested_types(text: &str, package: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|line| {
            let code = line.split('#').next().unwrap_or_default().trim();
            let type_spec = code.split_whitespace().next()?;
            // `float64[9]`, `Type[]`, `int32[<=4]` -> element type; `string<=8` -> string.
            let element = type_spec.split('[').next().unwrap_or_default();
            let element = element.split("<=").next().unwrap_or_default();
            if element.is_empty() || PRIMITIVE_TYPES.contains(&element) {
                return None;
            }
            Some(if element.contains('/') {
                short_type_name(element)
            } else {
                format!("{package}/{element}")
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::msg::{
        Clock, DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry,
        RosMessage, TFMessage, TwistWithCovarianceStamped, UInt8MultiArray, UbxRxmRawx,
        UbxRxmSfrbx,
    };

    /// The `MSG:` names of a full definition, in order.
    fn sections(text: &str) -> Vec<&str> {
        text.lines()
            .filter_map(|line| line.strip_prefix("MSG: "))
            .collect()
    }

    #[test]
    fn imu_definition_lists_each_nested_type_once_in_dependency_order() {
        let text = full_definition(Imu::TYPE_NAME).unwrap();
        assert!(text.starts_with("std_msgs/Header header\n"));
        assert_eq!(
            sections(&text),
            [
                "geometry_msgs/Quaternion",
                "geometry_msgs/Vector3",
                "std_msgs/Header",
                "builtin_interfaces/Time",
            ]
        );
        let separators = text.lines().filter(|line| *line == SEPARATOR).count();
        assert_eq!(separators, 4);
        assert_eq!(SEPARATOR.len(), 80);
    }

    #[test]
    fn relative_names_resolve_to_the_package_of_the_text() {
        let text = full_definition("sensor_msgs/msg/NavSatFix").unwrap();
        assert!(sections(&text).contains(&"sensor_msgs/NavSatStatus"));
        let text = full_definition(GnssMeasurements::TYPE_NAME).unwrap();
        assert_eq!(
            sections(&text),
            [
                "adaptive_gnss_ins/SatelliteMeasurement",
                "geometry_msgs/Point",
                "geometry_msgs/Vector3",
                "std_msgs/Header",
                "builtin_interfaces/Time",
            ]
        );
    }

    #[test]
    fn every_message_type_of_the_crate_has_a_full_definition() {
        for type_name in [
            Imu::TYPE_NAME,
            NavSatFix::TYPE_NAME,
            Odometry::TYPE_NAME,
            TwistWithCovarianceStamped::TYPE_NAME,
            DiagnosticArray::TYPE_NAME,
            TFMessage::TYPE_NAME,
            Clock::TYPE_NAME,
            GnssMeasurements::TYPE_NAME,
            NoiseEstimates::TYPE_NAME,
            UbxRxmRawx::TYPE_NAME,
            UbxRxmSfrbx::TYPE_NAME,
            UInt8MultiArray::TYPE_NAME,
        ] {
            assert!(full_definition(type_name).is_ok(), "{type_name}");
        }
    }

    #[test]
    fn an_unknown_nested_type_is_reported_by_name() {
        assert_eq!(
            full_definition("unknown_msgs/msg/Thing"),
            Err(MissingDefinition {
                type_name: "unknown_msgs/Thing".to_string()
            })
        );
    }
}
