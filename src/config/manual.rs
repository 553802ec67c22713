//! Text generated from the parameter table: the echo of a configuration, the commented
//! manual `params/defaults.yaml` and the reference `docs/parameters.md` (the last two are
//! checked against their files by `tests/parameter_manual.rs`).

use std::fmt::Write as _;

use super::table::yaml_text;
use super::{parameter_table, sections, Config, Parameter};

/// The node name the echo and the presets are written under: rcl applies it to every
/// node, whatever its name and namespace (a preset keyed `gnss_ins_node` would not reach
/// a node in a namespace: that key means `/gnss_ins_node`).
const WILDCARD_NODE: &str = "/**";
/// Width of the manual's comment lines.
const WIDTH: usize = 90;

/// The command that regenerates the manual and the reference.
pub const REGENERATE: &str = "GNSS_INS_REGENERATE=1 cargo test --test parameter_manual";

const MANUAL_HEADER: &str = "\
adaptive_gnss_ins: the manual (tightly-coupled error-state EKF with fixed noise, the \
built-in defaults).

Every parameter is listed with its meaning, unit, range and default, and the values below ARE \
the defaults. Any key may be left out and then takes its default. An unknown key, a value of \
the wrong type or out of range is an error naming the key and this file; nothing is processed.

The presets of params/ (ekf.yaml, ermakf.yaml, ekf_loose.yaml, imu_*.yaml, ...) hold only the \
keys that differ from this file (ekf.yaml only its variant) and are loaded after it (a later \
file wins):
  --ros-args --params-file params/defaults.yaml --params-file params/ermakf.yaml
  gnss_ins replay BAG --params params/defaults.yaml --params params/ermakf.yaml
Override one key:  --ros-args -p imu.gyro_bias_deg_per_h:=0.3

The parameters are keyed `/**`, so they reach the node under any name and namespace.
Units are in the key names and converted to SI once at load time. Frames: navigation ENU, \
body FLU (REP-103); IMU data is specific force (REP-145).
";

/// A parameter as the reference lists it.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub name: String,
    pub kind: String,
    /// Unit and its SI conversion.
    pub unit: String,
    pub default: String,
    pub range: String,
    /// Whether it can change while the node runs.
    pub runtime: bool,
    pub doc: String,
}

impl Row {
    /// The row of a parameter of the table.
    pub fn of(p: &Parameter) -> Self {
        let unit = match p.conversion_text() {
            c if c.is_empty() => p.unit.to_owned(),
            c => format!("{} ({c})", p.unit),
        };
        Self {
            name: p.name.to_owned(),
            kind: p.kind.name() + if p.nullable { " or null" } else { "" },
            unit,
            default: yaml_text(&p.default_value()),
            range: p.range_text(),
            runtime: p.runtime,
            doc: p.doc(),
        }
    }
}

/// `config` as a ROS 2 parameter file under `/**`, without comments.
pub fn values_file(config: &Config) -> String {
    let mut text = format!("{WILDCARD_NODE}:\n  ros__parameters:\n");
    for (section, _) in sections() {
        let _ = writeln!(text, "    {section}:");
        for p in parameter_table().iter().filter(|p| p.section() == section) {
            let _ = writeln!(text, "      {}: {}", p.key(), yaml_text(&p.value(config)));
        }
    }
    text
}

/// `params/defaults.yaml`: every parameter with its manual text, unit, range and default.
pub fn manual_file() -> String {
    let mut text = String::new();
    for paragraph in MANUAL_HEADER.lines() {
        comment(&mut text, "", paragraph);
    }
    comment(&mut text, "", "");
    comment(
        &mut text,
        "",
        "Generated from the parameter table (src/config/parameters.rs); edit the table, not \
         this file, and regenerate with:",
    );
    comment(&mut text, "", &format!("  {REGENERATE}"));
    let _ = write!(text, "\n{WILDCARD_NODE}:\n  ros__parameters:\n");
    for (k, (section, doc)) in sections().enumerate() {
        if k > 0 {
            text.push('\n');
        }
        comment(&mut text, "    ", &doc);
        let _ = writeln!(text, "    {section}:");
        for p in parameter_table().iter().filter(|p| p.section() == section) {
            let row = Row::of(p);
            comment(&mut text, "      ", &row.doc);
            let unit = if row.unit.is_empty() {
                "none"
            } else {
                &row.unit
            };
            let null = if p.nullable { ", or null" } else { "" };
            let facts = format!(
                "Unit: {unit}. Range: {}{null}. Run time: {}.",
                row.range,
                if row.runtime { "yes" } else { "no" },
            );
            comment(&mut text, "      ", &facts);
            comment(&mut text, "      ", &format!("Default: {}", row.default));
            let _ = writeln!(text, "      {}: {}", p.key(), row.default);
        }
    }
    text
}

/// `docs/parameters.md`: the table's parameters by section, then `node_rows` (the
/// node's own parameters).
pub fn reference(node_rows: &[Row]) -> String {
    let mut text = String::from("# Parameters\n\n");
    let _ = writeln!(
        text,
        "Generated from the parameter table (`src/config/parameters.rs`) and the node's own \
         parameters (`src/ros/node/params.rs`); edit those, not this file, and regenerate \
         with `{REGENERATE}`. `params/defaults.yaml` is the same manual as a parameter file.\n\n\
         Names are those of the parameter file (`section.key`, nested or dotted) and of the \
         ROS parameter services. \"Run time: yes\" means the running node takes a new value \
         (`ros2 param set`); the others are read-only while it runs and are set in a \
         parameter file or with `-p name:=value` at start."
    );
    for (section, doc) in sections() {
        let _ = write!(text, "\n## `{section}`\n\n{doc}\n\n");
        let rows: Vec<Row> = parameter_table()
            .iter()
            .filter(|p| p.section() == section)
            .map(Row::of)
            .collect();
        table(&mut text, &rows);
    }
    text.push_str(
        "\n## The node's own parameters\n\nRead by `gnss_ins_node` only (`gnss_ins replay` \
         and `compare` accept and ignore them).\n\n",
    );
    table(&mut text, node_rows);
    text
}

/// Appends `rows` to `text` as a Markdown table of the reference.
pub fn table(text: &mut String, rows: &[Row]) {
    text.push_str("| Parameter | Type | Unit | Default | Range | Run time | Meaning |\n");
    text.push_str("|---|---|---|---|---|---|---|\n");
    for r in rows {
        let _ = writeln!(
            text,
            "| `{}` | {} | {} | `{}` | {} | {} | {} |",
            r.name,
            r.kind,
            cell(&r.unit),
            r.default,
            cell(&r.range),
            if r.runtime { "yes" } else { "no" },
            cell(&r.doc)
        );
    }
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// Appends `paragraph` as `# ` comment lines indented by `indent`, wrapped at [`WIDTH`].
fn comment(text: &mut String, indent: &str, paragraph: &str) {
    let lead = format!("{indent}#");
    if paragraph.trim().is_empty() {
        let _ = writeln!(text, "{lead}");
        return;
    }
    // Lines that start with spaces (commands) are kept as they are.
    if paragraph.starts_with(' ') {
        let _ = writeln!(text, "{lead} {paragraph}");
        return;
    }
    let mut line = lead.clone();
    for word in paragraph.split_whitespace() {
        if line.len() > lead.len() && line.len() + 1 + word.len() > WIDTH {
            let _ = writeln!(text, "{line}");
            line = lead.clone();
        }
        line.push(' ');
        line.push_str(word);
    }
    let _ = writeln!(text, "{line}");
}
