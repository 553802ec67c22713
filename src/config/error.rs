//! The one error type of the configuration layer. Every variant names the origin (the file
//! name, or the parameter override) and, where there is one, the dotted parameter key.

/// Why a configuration was refused. Nothing is applied when one of these is returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// The text is not valid YAML.
    #[error("{origin}: YAML syntax error{}: {message}", location_suffix(*.line, *.column))]
    Yaml {
        origin: String,
        /// 1-based line of the error, when the parser knows it.
        line: Option<usize>,
        /// 1-based column of the error, when the parser knows it.
        column: Option<usize>,
        message: String,
    },
    /// The document is YAML but not a ROS 2 parameter file.
    #[error(
        "{origin}: expected the ROS 2 parameter layout `<node_name>:` (or `/**:`), then \
         `ros__parameters:`, then the sections {sections}; found {found}"
    )]
    Layout {
        origin: String,
        /// The sections a parameter file may hold, for the message.
        sections: String,
        /// What was found instead.
        found: String,
    },
    /// A section or parameter name that this version does not know (often a typo or a unit
    /// missing from the name).
    #[error("{origin}: unknown parameter `{key}` (known here: {known})")]
    UnknownKey {
        origin: String,
        key: String,
        /// The names that are allowed at that place.
        known: String,
    },
    /// A value of the wrong YAML type (a string for a number, two elements for three, ...).
    #[error("{origin}: parameter `{key}`: {detail}")]
    WrongType {
        origin: String,
        key: String,
        detail: String,
    },
    /// A well-typed value outside its allowed range.
    #[error("{origin}: parameter `{key}` = {value}: {reason}")]
    Invalid {
        origin: String,
        key: String,
        value: String,
        reason: String,
    },
    /// The text is larger than a parameter file can be (checked before parsing).
    #[error("{origin}: larger than the limit of {limit} bytes for a parameter file")]
    TooLarge { origin: String, limit: usize },
    /// The text nests deeper than a parameter file can (checked before parsing).
    #[error("{origin}: nested deeper than {limit} levels at line {line}; a parameter file nests about 5")]
    TooDeep {
        origin: String,
        line: usize,
        limit: usize,
    },
    /// A node name that rcl refuses in a parameter file.
    #[error(
        "{origin}: node name `{name}` is not valid: rcl takes letters, digits and `_` \
         between the slashes, or the wildcards `*` (one token) and `**` (any tokens) as whole \
         tokens, e.g. `/**`, `/**/gnss_ins_node`"
    )]
    BadNodeName { origin: String, name: String },
}

impl ConfigError {
    /// The origin (file name or override) this error refers to.
    pub fn origin(&self) -> &str {
        match self {
            Self::Yaml { origin, .. }
            | Self::Layout { origin, .. }
            | Self::UnknownKey { origin, .. }
            | Self::WrongType { origin, .. }
            | Self::Invalid { origin, .. }
            | Self::TooLarge { origin, .. }
            | Self::TooDeep { origin, .. }
            | Self::BadNodeName { origin, .. } => origin,
        }
    }

    /// The dotted parameter key this error refers to, if it is about one key.
    pub fn key(&self) -> Option<&str> {
        match self {
            Self::UnknownKey { key, .. }
            | Self::WrongType { key, .. }
            | Self::Invalid { key, .. } => Some(key),
            Self::Yaml { .. }
            | Self::Layout { .. }
            | Self::TooLarge { .. }
            | Self::TooDeep { .. }
            | Self::BadNodeName { .. } => None,
        }
    }

    /// At most `QUOTED_CHARS` characters of a text from the input, for a message.
    ///
    /// Choice: an error quotes a short prefix of what it refers to and its length, so
    /// that a 100 MB value does not come back on stderr, `/rosout` or in a service reply.
    pub fn shortened(text: &str) -> String {
        match text.char_indices().nth(QUOTED_CHARS) {
            None => text.to_owned(),
            Some((end, _)) => format!("{}... ({} bytes)", &text[..end], text.len()),
        }
    }

    pub(super) fn layout(origin: &str, found: String) -> Self {
        Self::Layout {
            origin: origin.to_owned(),
            sections: super::section_names().join(", "),
            found,
        }
    }

    pub(super) fn yaml(e: &serde_yaml::Error, origin: &str) -> Self {
        let location = e.location();
        let line = location.as_ref().map(|l| l.line());
        let column = location.as_ref().map(|l| l.column());
        let mut message = e.to_string();
        if let (Some(line), Some(column)) = (line, column) {
            // The parser's own text repeats the location that the error's Display shows.
            message = message.replace(&format!(" at line {line} column {column}"), "");
        }
        Self::Yaml {
            origin: origin.to_owned(),
            line,
            column,
            message: Self::shortened(&message),
        }
    }
}

/// Longest quotation of input text in an error message (characters).
const QUOTED_CHARS: usize = 80;

fn location_suffix(line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(line), Some(column)) => format!(" at line {line}, column {column}"),
        (Some(line), None) => format!(" at line {line}"),
        _ => String::new(),
    }
}
