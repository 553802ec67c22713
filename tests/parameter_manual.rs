//! The parameter table against what is generated from it: `params/defaults.yaml` (the
//! commented manual, and the base every other preset is loaded over) and
//! `docs/parameters.md` (the reference). A stale file fails here with the command that
//! regenerates it; `GNSS_INS_REGENERATE=1 cargo test --test parameter_manual` rewrites
//! both.

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::{self, manual, Assignment, Config, ConfigError};
use adaptive_gnss_ins::ros::node::params;
use adaptive_gnss_ins::ros::ubx_node;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Compares `path` with `expected`, or writes it when regenerating.
fn check_generated(path: PathBuf, expected: &str) {
    if std::env::var_os("GNSS_INS_REGENERATE").is_some() {
        std::fs::write(&path, expected).unwrap();
        return;
    }
    let found = std::fs::read_to_string(&path).unwrap_or_default();
    if found != expected {
        let line = found
            .lines()
            .zip(expected.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| found.lines().count().min(expected.lines().count()));
        panic!(
            "{} is not what the parameter table gives (first difference at line {}); \
             regenerate it with `{}` and commit it",
            path.display(),
            line + 1,
            manual::REGENERATE
        );
    }
}

#[test]
fn the_manual_is_generated_from_the_table() {
    check_generated(root().join("params/defaults.yaml"), &manual::manual_file());
}

#[test]
fn the_reference_is_generated_from_the_table() {
    let reference = params::reference() + &ubx_node::params::reference_section();
    check_generated(root().join("docs/parameters.md"), &reference);
}

/// The manual lists every parameter with its unit and its default, and loading it gives
/// the built-in defaults.
#[test]
fn the_manual_states_every_default_and_loads_to_them() {
    let text = manual::manual_file();
    assert_eq!(
        Config::from_yaml_str(&text, "defaults.yaml").unwrap(),
        Config::default()
    );
    for p in config::parameter_table() {
        let section = text
            .find(&format!("\n    {}:\n", p.section()))
            .unwrap_or_else(|| panic!("section of {} not in the manual", p.name));
        let line = format!("\n      {}: ", p.key());
        let at = section
            + text[section..]
                .find(&line)
                .unwrap_or_else(|| panic!("{} not in the manual", p.name));
        let comment = &text[..at];
        let facts = comment.rsplit("Unit:").next().unwrap();
        let default = config::yaml_text(&p.default_value());
        assert!(
            facts.contains(&format!("Default: {default}")),
            "{}: {facts}",
            p.name
        );
        let first_words: String = p
            .doc()
            .split_whitespace()
            .take(4)
            .collect::<Vec<_>>()
            .join(" ");
        let comment_words: String = comment
            .lines()
            .map(|l| l.trim_start().trim_start_matches('#').trim())
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            comment_words.contains(&first_words),
            "{}: text missing",
            p.name
        );
    }
}

/// Every row of the table is sound: a unique dotted name, a manual text, a default inside
/// its own range (written back through the row's checks), a unit where the kind has one.
#[test]
fn every_row_is_sound() {
    let table = config::parameter_table();
    let mut names: Vec<&str> = table.iter().map(|p| p.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), table.len(), "duplicate names");
    let defaults = table.iter().map(|p| Assignment {
        name: p.name.to_owned(),
        value: p.default_value(),
        origin: "defaults".to_owned(),
    });
    let written: Result<Config, ConfigError> = Config::default().with(defaults);
    assert_eq!(written.unwrap(), Config::default());
    for p in table {
        assert!(p.doc().len() > 10, "{}: no manual text", p.name);
        assert!(p.name.split('.').count() == 2, "{}", p.name);
        assert!(!p.description().is_empty());
    }
    // The node's own parameters do not collide with the table.
    for node in params::NODE_PARAMETERS {
        assert!(config::parameter(node.name).is_none(), "{}", node.name);
    }
}
