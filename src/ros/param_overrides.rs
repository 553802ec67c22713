//! A node's parameter files and `-p` rules as rcl collects them and rclcpp resolves them
//! (rcl 9 `rcl_arguments_get_param_overrides`, rclcpp 28 `resolve_parameter_overrides`).
//!
//! rcl reads the `--params-file`s and `-p` rules in command-line order into one table of
//! node-name entries: an entry per distinct node name as written (`gnss_ins_node`,
//! `/gnss_ins_node`, `/**` are three), in the order the names first appear; a later value
//! of a parameter in the same entry replaces the earlier one in place. A `-p` rule without
//! a `NODE:` prefix goes to the entry `/**`. rclcpp then walks the entries in that order,
//! takes those whose name matches the node's fully qualified name (`*` one name token,
//! `**` any number), and a later entry's value wins.
//!
//! So `--params-file ekf.yaml --params-file ermakf.yaml -p x:=1` applies ermakf.yaml over
//! ekf.yaml (same node name, later wins) and `-p` over both (its `/**` entry comes after
//! the node-named one). Choice, as rcl: when a `/**` entry appears *before* a node-named
//! one (a `/**` file or a `-p` rule first), the node-named entry wins even when it came
//! later on the command line.

use serde_yaml::Value;

use crate::config::{parse_parameter_file, parse_parameter_value, Assignment, ConfigError};

/// The node name a `-p` rule without prefix is filed under.
const EVERY_NODE: &str = "/**";

/// The parameter overrides of one command line.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParameterOverrides {
    entries: Vec<Entry>,
}

#[derive(Debug, Clone, PartialEq)]
struct Entry {
    node: String,
    values: Vec<Assignment>,
}

impl ParameterOverrides {
    /// Adds a parameter file's entries; returns the node names it holds. `origin` (the
    /// path) is quoted in errors.
    pub fn add_file(&mut self, text: &str, origin: &str) -> Result<Vec<String>, ConfigError> {
        let mut nodes = Vec::new();
        for entry in parse_parameter_file(text, origin)? {
            nodes.push(entry.node.clone());
            let values = entry.values.into_iter().map(|(name, value)| Assignment {
                name,
                value,
                origin: origin.to_owned(),
            });
            self.add(&entry.node, values);
        }
        Ok(nodes)
    }

    /// Adds `-p [node:]name:=value`; the value is parsed as YAML here (as rcl does).
    pub fn add_rule(
        &mut self,
        node: Option<&str>,
        name: &str,
        value: &str,
    ) -> Result<(), ConfigError> {
        let origin = format!("-p {name}:={}", ConfigError::shortened(value));
        let value: Value = parse_parameter_value(value, &origin)?;
        let assignment = Assignment {
            name: name.to_owned(),
            value,
            origin,
        };
        self.add(node.unwrap_or(EVERY_NODE), [assignment]);
        Ok(())
    }

    fn add(&mut self, node: &str, values: impl IntoIterator<Item = Assignment>) {
        let index = match self.entries.iter().position(|e| e.node == node) {
            Some(i) => i,
            None => {
                self.entries.push(Entry {
                    node: node.to_owned(),
                    values: Vec::new(),
                });
                self.entries.len() - 1
            }
        };
        for value in values {
            set(&mut self.entries[index].values, value);
        }
    }

    /// The values for the node `fully_qualified_name`, one per parameter, in the order
    /// they were first given.
    pub fn for_node(&self, fully_qualified_name: &str) -> Vec<Assignment> {
        let mut out = Vec::new();
        for entry in self
            .entries
            .iter()
            .filter(|e| node_matches(&e.node, fully_qualified_name))
        {
            for value in &entry.values {
                set(&mut out, value.clone());
            }
        }
        out
    }
}

fn set(values: &mut Vec<Assignment>, value: Assignment) {
    match values.iter_mut().find(|v| v.name == value.name) {
        Some(slot) => *slot = value,
        None => values.push(value),
    }
}

/// Whether the node name `pattern` of a parameter file addresses the node
/// `fully_qualified_name`, as rclcpp decides it: a leading `/` is implied, `*` stands for
/// one name token and `**` for any number of them (its regex `(/\w+)` and `(/\w+)*`).
pub fn node_matches(pattern: &str, fully_qualified_name: &str) -> bool {
    let tokens = |name: &str| -> Vec<String> {
        name.trim_start_matches('/')
            .split('/')
            .map(str::to_owned)
            .collect()
    };
    let pattern = tokens(pattern);
    let name = tokens(fully_qualified_name);
    // matched[j]: the pattern tokens so far match the first j name tokens. One pass per
    // pattern token: linear in both lengths, however many `**` the pattern holds.
    let mut matched = vec![false; name.len() + 1];
    matched[0] = true;
    for p in &pattern {
        let mut next = vec![false; name.len() + 1];
        for j in 0..=name.len() {
            next[j] = match p.as_str() {
                "**" => matched[j] || (j > 0 && next[j - 1]),
                "*" => j > 0 && matched[j - 1],
                literal => j > 0 && matched[j - 1] && name[j - 1] == literal,
            };
        }
        matched = next;
    }
    matched[name.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(a: &[Assignment]) -> Vec<(String, String)> {
        a.iter()
            .map(|a| (a.name.clone(), crate::config::yaml_text(&a.value)))
            .collect()
    }

    fn pair(n: &str, v: &str) -> (String, String) {
        (n.to_owned(), v.to_owned())
    }

    #[test]
    fn node_names_match_as_rclcpp_matches_them() {
        for (pattern, fqn) in [
            ("/**", "/gnss_ins_node"),
            ("/**", "/robot/arm/ins"),
            ("gnss_ins_node", "/gnss_ins_node"),
            ("/gnss_ins_node", "/gnss_ins_node"),
            ("/**/gnss_ins_node", "/gnss_ins_node"),
            ("/**/gnss_ins_node", "/robot/gnss_ins_node"),
            ("/*", "/gnss_ins_node"),
            ("*", "/gnss_ins_node"),
            ("/robot/*", "/robot/ins"),
            ("robot/ins", "/robot/ins"),
            ("/robot/**", "/robot/a/b"),
        ] {
            assert!(node_matches(pattern, fqn), "{pattern} {fqn}");
        }
        for (pattern, fqn) in [
            ("gnss_ins_node", "/robot/gnss_ins_node"),
            ("/*", "/robot/ins"),
            ("/robot/*", "/robot/a/b"),
            ("/**/ins", "/robot/ins2"),
            ("other", "/gnss_ins_node"),
        ] {
            assert!(!node_matches(pattern, fqn), "{pattern} {fqn}");
        }
        let many = "/**".repeat(500) + "/x";
        assert!(!node_matches(&many, "/a/b/c/d/e/f/g/h/y"));
    }

    #[test]
    fn later_files_win_and_rules_win_over_node_named_files() {
        let mut o = ParameterOverrides::default();
        let file = |v: &str| {
            format!("gnss_ins_node:\n  ros__parameters:\n    filter.variant: {v}\n    a: 1\n")
        };
        o.add_file(&file("ekf"), "ekf.yaml").unwrap();
        o.add_file(&file("ermakf"), "ermakf.yaml").unwrap();
        let got = o.for_node("/gnss_ins_node");
        assert_eq!(
            names(&got),
            vec![pair("filter.variant", "ermakf"), pair("a", "1")]
        );
        assert_eq!(got[0].origin, "ermakf.yaml");
        o.add_rule(None, "filter.variant", "iarf").unwrap();
        let got = o.for_node("/gnss_ins_node");
        assert_eq!(got[0].origin, "-p filter.variant:=iarf");
        assert_eq!(names(&got)[0], pair("filter.variant", "iarf"));
        // A rule for another node and a file entry for another node do not apply.
        o.add_rule(Some("other"), "a", "2").unwrap();
        assert_eq!(names(&o.for_node("/gnss_ins_node"))[1], pair("a", "1"));
    }

    #[test]
    fn an_early_wildcard_entry_loses_to_a_node_named_one_as_in_rcl() {
        let mut o = ParameterOverrides::default();
        o.add_rule(None, "a", "1").unwrap();
        o.add_file("gnss_ins_node:\n  ros__parameters:\n    a: 2\n", "f.yaml")
            .unwrap();
        o.add_rule(None, "a", "3").unwrap();
        // The `/**` entry (a = 3) came first, so the node-named entry (a = 2) is applied
        // after it.
        assert_eq!(names(&o.for_node("/gnss_ins_node")), vec![pair("a", "2")]);
    }

    #[test]
    fn bad_rule_values_are_errors_quoting_a_prefix() {
        let mut o = ParameterOverrides::default();
        let e = o.add_rule(None, "a", "[1,").unwrap_err().to_string();
        assert!(e.starts_with("-p a:=[1,"), "{e}");
        let deep = "[".repeat(100_000);
        let e = o.add_rule(None, "a", &deep).unwrap_err();
        assert!(matches!(e, ConfigError::TooDeep { .. }), "{e}");
        assert!(e.to_string().len() < 400, "{e}");
    }
}
