//! The ROS 2 parameter-file layout as rcl's YAML parser (rcl_yaml_param_parser) reads it:
//! node names above `ros__parameters:` (nested mappings are namespaces joined by `/`;
//! `*` and `**` are wildcard tokens), parameters below it as nested mappings or dotted
//! keys (`filter: {variant: x}` and `filter.variant: x` are the same parameter), a later
//! value of a parameter replacing an earlier one.
//!
//! Size and nesting depth are checked before the YAML parser sees the text: its scanner
//! is quadratic in the nesting of flow collections (100,000 nested `[` take 20 s) and a
//! large file costs several times its size in memory.

use serde_yaml::{Mapping, Value};

use super::ConfigError;

/// Largest parameter file (and `-p` value) accepted, in bytes.
///
/// Choice: 1 MiB. The full manual (`params/defaults.yaml`) is about 20 kB; a file a hundred
/// times larger is not a parameter file.
pub const MAX_FILE_BYTES: usize = 1 << 20;
/// Deepest nesting accepted (block levels plus flow brackets).
///
/// Choice: 64. A parameter file nests five levels (node, `ros__parameters`, section,
/// key, list); a few namespace levels more are plausible, sixty are not.
pub const MAX_NESTING_DEPTH: usize = 64;
/// The key that holds a node's parameters. rcl takes every key that starts with it.
const ROS_PARAMETERS: &str = "ros__parameters";
/// Separator of nested node names.
const NODE_SEPARATOR: char = '/';

/// The parameters a file gives one node name (or wildcard pattern), in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeParameters {
    /// The node name as the file writes it (`gnss_ins_node`, `/**`, `/robot/ins`, ...).
    pub node: String,
    /// Dotted parameter names and their values.
    pub values: Vec<(String, Value)>,
}

impl NodeParameters {
    /// Sets `name` (replacing an earlier value in place, as rcl does).
    fn set(&mut self, name: String, value: Value) {
        match self.values.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = value,
            None => self.values.push((name, value)),
        }
    }
}

/// Adds `values` for `node` to `entries`: into the entry of the same node name when there
/// is one (rcl keeps one entry per name, in the order names first appear).
fn merge(entries: &mut Vec<NodeParameters>, node: &str, values: Vec<(String, Value)>) {
    let index = match entries.iter().position(|e| e.node == node) {
        Some(i) => i,
        None => {
            entries.push(NodeParameters {
                node: node.to_owned(),
                values: Vec::new(),
            });
            entries.len() - 1
        }
    };
    for (name, value) in values {
        entries[index].set(name, value);
    }
}

/// The node entries of a parameter file. `origin` is quoted in errors.
pub fn parse(text: &str, origin: &str) -> Result<Vec<NodeParameters>, ConfigError> {
    let document = parse_yaml(text, origin)?;
    let layout = |found: String| ConfigError::layout(origin, found);
    let top = match &document {
        Value::Mapping(top) if !top.is_empty() => top,
        Value::Mapping(_) | Value::Null => return Err(layout("nothing".to_owned())),
        other => return Err(layout(describe(other))),
    };
    let mut entries = Vec::new();
    walk_nodes(top, "", &mut entries, origin)?;
    if entries.is_empty() {
        return Err(layout(format!(
            "no `{ROS_PARAMETERS}:` under {}",
            key_list(top)
        )));
    }
    Ok(entries)
}

/// A YAML value of a `-p name:=value` rule (checked like a file).
pub fn parse_value(text: &str, origin: &str) -> Result<Value, ConfigError> {
    parse_yaml(text, origin)
}

fn parse_yaml(text: &str, origin: &str) -> Result<Value, ConfigError> {
    if text.len() > MAX_FILE_BYTES {
        return Err(ConfigError::TooLarge {
            origin: origin.to_owned(),
            limit: MAX_FILE_BYTES,
        });
    }
    if let Some(line) = line_nested_deeper_than(text, MAX_NESTING_DEPTH) {
        return Err(ConfigError::TooDeep {
            origin: origin.to_owned(),
            line,
            limit: MAX_NESTING_DEPTH,
        });
    }
    serde_yaml::from_str(text).map_err(|e| ConfigError::yaml(&e, origin))
}

/// Collects the entries below the node-name path `path` (rcl's node level).
fn walk_nodes(
    level: &Mapping,
    path: &str,
    entries: &mut Vec<NodeParameters>,
    origin: &str,
) -> Result<(), ConfigError> {
    let layout = |found: String| ConfigError::layout(origin, found);
    for (key, value) in level {
        let key = key_text(key);
        if key.starts_with(ROS_PARAMETERS) {
            if path.is_empty() {
                return Err(layout(format!(
                    "`{ROS_PARAMETERS}:` without a node name above it"
                )));
            }
            check_node_name(path, origin)?;
            let values = match value {
                Value::Mapping(parameters) => flatten(parameters),
                Value::Null => Vec::new(),
                other => {
                    return Err(layout(format!(
                        "`{ROS_PARAMETERS}:` holding {}",
                        describe(other)
                    )))
                }
            };
            merge(entries, path, values);
            continue;
        }
        let node = join_node(path, &key);
        match value {
            Value::Mapping(inner) => walk_nodes(inner, &node, entries, origin)?,
            // A node name with nothing below it gives no parameters (as in rcl).
            Value::Null => {}
            other => {
                return Err(layout(format!(
                    "{} at `{}` before any `{ROS_PARAMETERS}:`",
                    describe(other),
                    ConfigError::shortened(&node)
                )))
            }
        }
    }
    Ok(())
}

/// rcl's join of nested node names: `/` between them unless the outer one ends with it.
fn join_node(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_owned()
    } else if path.ends_with(NODE_SEPARATOR) {
        format!("{path}{key}")
    } else {
        format!("{path}{NODE_SEPARATOR}{key}")
    }
}

/// rcl's check of a node name of a parameter file: namespace tokens and the base name are
/// ROS name tokens (letters, digits, `_`, not starting with a digit) or the wildcards `*`
/// (one token) and `**` (any number of tokens); `/**` and `/*` stand alone too.
fn check_node_name(name: &str, origin: &str) -> Result<(), ConfigError> {
    let token = |t: &str| {
        t == "*"
            || t == "**"
            || (!t.is_empty()
                && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                && !t.starts_with(|c: char| c.is_ascii_digit()))
    };
    let body = name.strip_prefix(NODE_SEPARATOR).unwrap_or(name);
    if body.split(NODE_SEPARATOR).all(token) {
        Ok(())
    } else {
        Err(ConfigError::BadNodeName {
            origin: origin.to_owned(),
            name: ConfigError::shortened(name),
        })
    }
}

/// `(dotted name, value)` of every parameter below `ros__parameters:`.
fn flatten(parameters: &Mapping) -> Vec<(String, Value)> {
    let mut out = Vec::new();
    flatten_into(parameters, "", &mut out);
    out
}

fn flatten_into(level: &Mapping, prefix: &str, out: &mut Vec<(String, Value)>) {
    for (key, value) in level {
        let key = key_text(key);
        let name = if prefix.is_empty() {
            key
        } else {
            format!("{prefix}.{key}")
        };
        match value {
            Value::Mapping(inner) if !inner.is_empty() => flatten_into(inner, &name, out),
            _ => match out.iter_mut().find(|(n, _)| *n == name) {
                Some(slot) => slot.1 = value.clone(),
                None => out.push((name, value.clone())),
            },
        }
    }
}

/// The line of the first place where `text` nests deeper than `limit`, counted without a
/// YAML parser and in one pass: block levels (strictly increasing indentation, and each
/// leading `- `), plus open flow collections (`[`, `{` that start a value, outside quotes
/// and comments). The count can only err high (a bracket inside a multi-line quoted
/// string), never low.
fn line_nested_deeper_than(text: &str, limit: usize) -> Option<usize> {
    let mut indents: Vec<usize> = Vec::new();
    let mut flow = 0usize;
    for (number, line) in text.lines().enumerate() {
        let body = line.trim_start_matches([' ', '\t']);
        let mut block = indents.len();
        let mut rest = body;
        if flow == 0 {
            if body.is_empty() || body.starts_with('#') {
                continue;
            }
            let indent = line.len() - body.len();
            while indents.last().is_some_and(|&i| i >= indent) {
                indents.pop();
            }
            indents.push(indent);
            block = indents.len();
            while let Some(after) = rest
                .strip_prefix('-')
                .filter(|a| a.is_empty() || a.starts_with(' '))
            {
                block += 1;
                rest = after.trim_start();
            }
        }
        let (deepest, open) = flow_depth(rest, flow);
        flow = open;
        if block + deepest > limit {
            return Some(number + 1);
        }
    }
    None
}

/// The deepest flow nesting reached on `line` starting at depth `open`, and the depth at
/// its end.
fn flow_depth(line: &str, mut open: usize) -> (usize, usize) {
    let mut deepest = open;
    let mut quote: Option<char> = None;
    // The last non-blank character before the current one (' ' at the start).
    let mut previous = ' ';
    let mut after_blank = true;
    for c in line.chars() {
        if let Some(q) = quote {
            if c == q {
                quote = None;
            }
        } else {
            // Block context: a flow collection starts a value (line start, after `: `,
            // `- `, `? `); inside a plain scalar a bracket is text. Flow context: every
            // bracket nests (a plain scalar cannot hold one), and a quote opens a string
            // only where a value starts, so that a stray quote cannot hide brackets.
            let starts_value = matches!(previous, ' ' | ':' | '-' | '?')
                || (open > 0 && matches!(previous, ',' | '[' | '{'));
            match c {
                '#' if after_blank => break,
                '\'' | '"' if starts_value => quote = Some(c),
                '[' | '{' if open > 0 || starts_value => {
                    open += 1;
                    deepest = deepest.max(open);
                }
                ']' | '}' if open > 0 => open -= 1,
                _ => {}
            }
        }
        after_blank = c == ' ' || c == '\t';
        if !after_blank {
            previous = c;
        }
    }
    (deepest, open)
}

pub(super) fn key_text(key: &Value) -> String {
    match key {
        Value::String(s) => s.clone(),
        other => super::table::yaml_text(other),
    }
}

pub(super) fn key_list(mapping: &Mapping) -> String {
    let names: Vec<String> = mapping
        .keys()
        .map(|k| ConfigError::shortened(&key_text(k)))
        .collect();
    names.join(", ")
}

pub(super) fn describe(value: &Value) -> String {
    match value {
        Value::Null => "nothing (null)".to_owned(),
        Value::Bool(_) => "a boolean".to_owned(),
        Value::Number(_) => "a number".to_owned(),
        Value::String(_) => "a string".to_owned(),
        Value::Sequence(_) => "a list".to_owned(),
        Value::Mapping(m) => format!("a mapping with keys {}", key_list(m)),
        Value::Tagged(_) => "a tagged value".to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(text: &str) -> Vec<NodeParameters> {
        parse(text, "t.yaml").unwrap()
    }

    #[test]
    fn nested_and_dotted_keys_are_the_same_parameter() {
        let nested = values("/**:\n  ros__parameters:\n    filter:\n      variant: ermakf\n");
        let dotted = values("/**:\n  ros__parameters:\n    filter.variant: ermakf\n");
        assert_eq!(nested, dotted);
        assert_eq!(nested[0].values[0].0, "filter.variant");
        let both = values(
            "/**:\n  ros__parameters:\n    filter.variant: ekf\n    filter:\n      variant: iarf\n",
        );
        assert_eq!(
            both[0].values,
            vec![("filter.variant".into(), "iarf".into())]
        );
    }

    #[test]
    fn nested_node_names_are_namespaces() {
        let e = values(
            "robot:\n  ins:\n    ros__parameters:\n      a.b: 1\n  ros__parameters:\n    c: 2\n",
        );
        let nodes: Vec<&str> = e.iter().map(|e| e.node.as_str()).collect();
        assert_eq!(nodes, vec!["robot/ins", "robot"]);
        let e = values("/**:\n  gnss_ins_node:\n    ros__parameters:\n      a: 1\n");
        assert_eq!(e[0].node, "/**/gnss_ins_node");
    }

    #[test]
    fn node_names_follow_rcl() {
        for good in [
            "/**",
            "/*",
            "gnss_ins_node",
            "/r1/ins",
            "/**/ins",
            "*",
            "/robot/*",
        ] {
            let text = format!("\"{good}\":\n  ros__parameters: {{a: 1}}\n");
            assert!(parse(&text, "t").is_ok(), "{good}");
        }
        for bad in ["gnss_*", "/robot//ins", "9lives", "/a b"] {
            let text = format!("\"{bad}\":\n  ros__parameters: {{a: 1}}\n");
            let e = parse(&text, "t").unwrap_err();
            assert!(matches!(e, ConfigError::BadNodeName { .. }), "{bad}: {e}");
        }
    }

    #[test]
    fn depth_is_counted_without_a_parser() {
        assert_eq!(
            line_nested_deeper_than("a:\n  b:\n    c: [1, [2]]\n", 4),
            Some(3)
        );
        assert_eq!(
            line_nested_deeper_than("a:\n  b:\n    c: [1, [2]]\n", 5),
            None
        );
        assert_eq!(line_nested_deeper_than("- - - - x\n", 3), Some(1));
        // Brackets inside plain scalars, quotes and comments are not nesting.
        let text = "a: x[[[[\nb: '[[[[['\nc: 1 # [[[[[\n";
        assert_eq!(line_nested_deeper_than(text, 2), None);
        // Flow collections spanning lines keep their depth.
        assert_eq!(
            line_nested_deeper_than("a: [\n [\n  [\n 1]]]\n", 3),
            Some(3)
        );
        // A stray quote inside a flow collection does not hide the brackets after it.
        assert_eq!(line_nested_deeper_than("a: [x'[[[[\n", 3), Some(1));
    }
}
