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
}

impl ConfigError {
    /// The origin (file name or override) this error refers to.
    pub fn origin(&self) -> &str {
        match self {
            Self::Yaml { origin, .. }
            | Self::Layout { origin, .. }
            | Self::UnknownKey { origin, .. }
            | Self::WrongType { origin, .. }
            | Self::Invalid { origin, .. } => origin,
        }
    }

    /// The dotted parameter key this error refers to, if it is about one key.
    pub fn key(&self) -> Option<&str> {
        match self {
            Self::UnknownKey { key, .. }
            | Self::WrongType { key, .. }
            | Self::Invalid { key, .. } => Some(key),
            Self::Yaml { .. } | Self::Layout { .. } => None,
        }
    }
}

fn location_suffix(line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(line), Some(column)) => format!(" at line {line}, column {column}"),
        (Some(line), None) => format!(" at line {line}"),
        _ => String::new(),
    }
}
