//! Parameter descriptions for `describe_parameters`, taken from the manual: the comments
//! above each key of `params/ekf.yaml` (which a test keeps equal to the defaults).

use std::collections::HashMap;

const MANUAL: &str = include_str!("../../../params/ekf.yaml");
/// Indentation of a section (`gnss:`) and of its keys in the manual.
const SECTION_INDENT: usize = 4;
const KEY_INDENT: usize = 6;

/// (dotted name, description) of every parameter of the manual: its comment lines joined.
///
/// Choice: a comment block that opens a section is part of its first key's description
/// (the manual does not separate the two).
pub fn descriptions() -> HashMap<String, String> {
    let mut found = HashMap::new();
    let mut section = "";
    let mut comment: Vec<&str> = Vec::new();
    for line in MANUAL.lines() {
        let text = line.trim_start();
        let indent = line.len() - text.len();
        if let Some(c) = text.strip_prefix('#') {
            if indent >= KEY_INDENT {
                comment.push(c.trim());
            }
        } else if let Some((key, value)) = text.split_once(':') {
            if indent == SECTION_INDENT && value.trim().is_empty() {
                section = key;
            } else if indent == KEY_INDENT {
                found.insert(format!("{section}.{key}"), comment.join(" "));
            }
            comment.clear();
        } else {
            comment.clear();
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    #[test]
    fn every_parameter_has_a_description_with_its_unit() {
        let d = descriptions();
        for (name, _) in Config::default().parameters() {
            let text = d
                .get(&name)
                .unwrap_or_else(|| panic!("{name} undocumented"));
            assert!(text.contains("Unit:"), "{name}: {text}");
        }
        assert!(d["gnss.elevation_mask_deg"].starts_with("Satellites below this elevation"));
    }
}
