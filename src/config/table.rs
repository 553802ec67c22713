//! The machinery of the parameter table (`parameters.rs`): one [`Parameter`] row per
//! parameter, and the macro that builds, from one declaration each, the section structs,
//! their defaults, the [`Config`] struct and the rows with their readers and writers.
//!
//! A declaration (doc comment lines = the manual text):
//!
//! ```text
//! /// Initial 1-sigma of the constant (turn-on) gyro bias, per axis.
//! gyro_bias_sigma_rad_s: f64 ["gyro_bias_deg_per_h": f64] = 0.5,
//!     unit "deg/h", range SIGMA, at_start, si Scale::to("rad/s", RAD_S_PER_DEG_H);
//! ```
//!
//! declares the SI field `imu.gyro_bias_sigma_rad_s` read from the file key
//! `imu.gyro_bias_deg_per_h` (an f64 there too) with default 0.5 deg/h, checked against
//! `SIGMA` in the file's unit, fixed once the filter runs (`at_start`; `at_run_time` may
//! change while it runs), converted by the factor. Without `[...]` the file key is the
//! field's name and its type the field's; without `si` the value is taken as it is.

use serde_yaml::Value;

use super::spec::{Kind, Range};
use super::Config;

/// One parameter of the table.
pub struct Parameter {
    /// Dotted name in the file and on the parameter services: `section.key`.
    pub name: &'static str,
    /// Type in the file.
    pub kind: Kind,
    /// Whether `null` is a value ("not set").
    pub nullable: bool,
    /// Unit of the file value ("" for none).
    pub unit: &'static str,
    /// Valid values, in the file's unit.
    pub range: Range,
    /// Whether a running engine takes a new value over (else it is read-only while the
    /// node runs).
    pub runtime: bool,
    pub(super) doc_lines: &'static [&'static str],
    pub(super) conversion: fn(&str) -> String,
    pub(super) read: fn(&Config) -> Value,
    pub(super) write: fn(&mut Config, Value) -> Result<(), WriteError>,
    pub(super) copy: fn(&mut Config, &Config),
}

/// Why a value was not written.
#[derive(Debug)]
pub(super) enum WriteError {
    /// Not of the parameter's type; `path` locates the element inside a list.
    Type { path: String, detail: String },
    /// Of the right type but outside the range.
    Range { value: String, reason: String },
}

impl Parameter {
    /// The section (`imu`).
    pub fn section(&self) -> &'static str {
        self.name.split_once('.').map_or(self.name, |(s, _)| s)
    }

    /// The key within the section (`gyro_bias_deg_per_h`).
    pub fn key(&self) -> &'static str {
        self.name.split_once('.').map_or(self.name, |(_, k)| k)
    }

    /// The manual text, one paragraph.
    pub fn doc(&self) -> String {
        join_doc(self.doc_lines)
    }

    /// What the SI conversion is, empty when the value is used as written.
    pub fn conversion_text(&self) -> String {
        (self.conversion)(self.unit)
    }

    /// The value in `config`, in the file's units.
    pub fn value(&self, config: &Config) -> Value {
        (self.read)(config)
    }

    /// Sets this parameter of `config` to its value in `from`.
    pub fn take_value(&self, config: &mut Config, from: &Config) {
        (self.copy)(config, from)
    }

    /// The documented default.
    pub fn default_value(&self) -> Value {
        self.value(&Config::default())
    }

    /// The range as the manual states it (`in [1e-9, 1e6] m`).
    pub fn range_text(&self) -> String {
        match (self.range, self.kind) {
            (Range::Any, Kind::Bool) => "true or false".to_owned(),
            (Range::Any, Kind::Text) => "a name the text lists".to_owned(),
            (range, _) => range.text(self.unit),
        }
    }

    /// The description the parameter services give: the manual text, the unit and its
    /// conversion, the range and the default.
    pub fn description(&self) -> String {
        let unit = if self.unit.is_empty() {
            "none"
        } else {
            self.unit
        };
        let conversion = match self.conversion_text() {
            c if c.is_empty() => String::new(),
            c => format!(" ({c})"),
        };
        format!(
            "{} Unit: {unit}{conversion}. Range: {}{}. Default: {}",
            self.doc(),
            self.range_text(),
            if self.nullable { ", or null" } else { "" },
            yaml_text(&self.default_value()),
        )
    }
}

/// Doc-comment lines as one paragraph.
pub(super) fn join_doc(lines: &[&str]) -> String {
    lines
        .iter()
        .flat_map(|l| l.split_whitespace())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Flow-style YAML of a value: `0.5`, `[gps, galileo]`, `null`.
pub fn yaml_text(value: &Value) -> String {
    match value {
        Value::Null => "null".to_owned(),
        Value::Bool(b) => b.to_string(),
        // serde_yaml prints floats with the shortest text that reads back to the same bits.
        Value::Number(n) => n.to_string(),
        Value::String(s) => s.clone(),
        Value::Sequence(items) => {
            let items: Vec<String> = items.iter().map(yaml_text).collect();
            format!("[{}]", items.join(", "))
        }
        Value::Mapping(_) => "a mapping".to_owned(),
        Value::Tagged(_) => "a tagged value".to_owned(),
    }
}

/// Reads a file value of type `T` from `value`, locating a wrong element of a list.
pub(super) fn read_value<T: serde::de::DeserializeOwned>(value: Value) -> Result<T, WriteError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        WriteError::Type {
            path: if path == "." { String::new() } else { path },
            detail: e.inner().to_string(),
        }
    })
}

/// `human` checked against `range`; the error quotes the value.
pub(super) fn checked<T: super::file_value::FileValue>(
    human: T,
    range: &Range,
    unit: &str,
) -> Result<T, WriteError> {
    match human.check(range, unit) {
        Ok(()) => Ok(human),
        Err(reason) => Err(WriteError::Range {
            value: yaml_text(&human.to_yaml()),
            reason,
        }),
    }
}

/// The file key of a field: the one given in `[...]`, else the field's name.
macro_rules! file_key {
    ($field:ident) => {
        stringify!($field)
    };
    ($field:ident, $key:literal) => {
        $key
    };
}

/// The file type of a field: the one given in `[...]`, else the field's type.
macro_rules! file_type {
    ($si:ty) => {
        $si
    };
    ($si:ty, $human:ty) => {
        $human
    };
}

/// The conversion of a field: the one given after `si`, else none.
macro_rules! conversion {
    () => {
        $crate::config::convert::Same
    };
    ($conversion:expr) => {
        $conversion
    };
}

/// Whether a running engine takes the parameter over.
macro_rules! runtime {
    (at_start) => {
        false
    };
    (at_run_time) => {
        true
    };
}

/// Builds the section structs, [`Config`], `SECTIONS` and `PARAMETERS` from the table.
macro_rules! parameter_table {
    ($(
        $(#[doc = $section_doc:literal])+
        section $section:ident: $Section:ident {$(
            $(#[doc = $doc:literal])+
            $field:ident: $Si:ty $([$key:literal: $Human:ty])? = $default:expr,
                unit $unit:literal, range $range:expr, $when:ident $(, si $conv:expr)?;
        )+}
    )+) => {
        $(
            $(#[doc = $section_doc])+
            #[derive(Debug, Clone, PartialEq)]
            pub struct $Section {$(
                $(#[doc = $doc])+
                #[doc = ""]
                #[doc = concat!(
                    "File: `", stringify!($section), ".", $crate::config::table::file_key!($field $(, $key)?),
                    "` (default `", stringify!($default), "`).",
                )]
                pub $field: $Si,
            )+}

            impl Default for $Section {
                /// The documented defaults.
                fn default() -> Self {
                    Self {$(
                        $field: {
                            let human: $crate::config::table::file_type!($Si $(, $Human)?) =
                                $default;
                            $crate::config::convert::Convert::to_si(
                                &$crate::config::table::conversion!($($conv)?),
                                &human,
                            )
                        },
                    )+}
                }
            }
        )+

        /// The validated configuration, in SI units and radians: what the engine reads.
        #[derive(Debug, Clone, PartialEq, Default)]
        pub struct Config {$(
            $(#[doc = $section_doc])+
            pub $section: $Section,
        )+}

        /// Every section in file order with its manual text.
        pub(super) static SECTIONS: &[(&str, &[&str])] =
            &[$((stringify!($section), &[$($section_doc),+]),)+];

        /// Every parameter in file order.
        pub(super) static PARAMETERS: &[$crate::config::table::Parameter] = &[$($(
            $crate::config::table::Parameter {
                name: concat!(
                    stringify!($section), ".", $crate::config::table::file_key!($field $(, $key)?)
                ),
                kind: <$crate::config::table::file_type!($Si $(, $Human)?)
                    as $crate::config::file_value::FileValue>::KIND,
                nullable: <$crate::config::table::file_type!($Si $(, $Human)?)
                    as $crate::config::file_value::FileValue>::NULLABLE,
                unit: $unit,
                range: $range,
                runtime: $crate::config::table::runtime!($when),
                doc_lines: &[$($doc),+],
                conversion: |unit| {
                    $crate::config::convert::ConversionText::text(
                        &$crate::config::table::conversion!($($conv)?),
                        unit,
                    )
                },
                read: |config| {
                    let human: $crate::config::table::file_type!($Si $(, $Human)?) =
                        $crate::config::convert::Convert::to_human(
                            &$crate::config::table::conversion!($($conv)?),
                            &config.$section.$field,
                        );
                    $crate::config::file_value::FileValue::to_yaml(&human)
                },
                write: |config, value| {
                    let human: $crate::config::table::file_type!($Si $(, $Human)?) =
                        $crate::config::table::read_value(value)?;
                    let human = $crate::config::table::checked(human, &$range, $unit)?;
                    config.$section.$field = $crate::config::convert::Convert::to_si(
                        &$crate::config::table::conversion!($($conv)?),
                        &human,
                    );
                    Ok(())
                },
                copy: |to, from| to.$section.$field = from.$section.$field.clone(),
            },
        )+)+];
    };
}

pub(crate) use {conversion, file_key, file_type, parameter_table, runtime};
