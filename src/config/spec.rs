//! What the parameter table says about one parameter besides its value: its type as
//! written in the file, its valid range, and how both read in the manual.

use std::fmt::Write as _;

/// The type of a parameter as written in the file and served over the ROS parameter
/// services.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `true` / `false`.
    Bool,
    /// A whole number.
    Integer,
    /// A number (an integer is accepted too).
    Double,
    /// A name out of a fixed set (an enum).
    Text,
    /// A list of numbers of fixed length.
    DoubleArray(usize),
    /// A list of names.
    TextArray,
}

impl Kind {
    /// The type as the manual names it.
    pub fn name(self) -> String {
        match self {
            Self::Bool => "bool".to_owned(),
            Self::Integer => "integer".to_owned(),
            Self::Double => "double".to_owned(),
            Self::Text => "string".to_owned(),
            Self::DoubleArray(n) => format!("double[{n}]"),
            Self::TextArray => "string[]".to_owned(),
        }
    }
}

/// A range of finite numbers, each end open or closed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
    pub lo_open: bool,
    pub hi_open: bool,
}

impl Interval {
    /// `[lo, hi]`.
    pub const fn closed(lo: f64, hi: f64) -> Self {
        Self {
            lo,
            hi,
            lo_open: false,
            hi_open: false,
        }
    }

    /// `(lo, hi]`.
    pub const fn above(lo: f64, hi: f64) -> Self {
        Self {
            lo,
            hi,
            lo_open: true,
            hi_open: false,
        }
    }

    /// `[lo, hi)`.
    pub const fn below(lo: f64, hi: f64) -> Self {
        Self {
            lo,
            hi,
            lo_open: false,
            hi_open: true,
        }
    }

    /// True for a finite `x` inside.
    pub fn contains(&self, x: f64) -> bool {
        let above_lo = if self.lo_open {
            x > self.lo
        } else {
            x >= self.lo
        };
        let below_hi = if self.hi_open {
            x < self.hi
        } else {
            x <= self.hi
        };
        x.is_finite() && above_lo && below_hi
    }

    /// `[1e-9, 1e6]`, `(0, 1]`, ...
    pub fn text(&self) -> String {
        format!(
            "{}{}, {}{}",
            if self.lo_open { '(' } else { '[' },
            number_text(self.lo),
            number_text(self.hi),
            if self.hi_open { ')' } else { ']' },
        )
    }
}

/// The values a parameter accepts (beyond its type).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// Every value of its type (a bool, a name of the enum, a seed).
    Any,
    /// A finite number inside.
    Within(Interval),
    /// 0 (which switches the feature off) or a number inside.
    OffOrWithin(Interval),
    /// A whole number in `min..=max`.
    Count { min: u64, max: u64 },
    /// Three numbers, each inside its own interval: (name, interval, unit).
    Components([(&'static str, Interval, &'static str); 3]),
    /// A non-empty list naming each element at most once.
    EachOnce,
}

/// The reason given for a value outside its range.
pub type OutOfRange = String;

impl Range {
    /// Checks a number.
    pub fn check_number(&self, x: f64, unit: &str) -> Result<(), OutOfRange> {
        let inside = match self {
            Self::Any => x.is_finite(),
            Self::Within(i) => i.contains(x),
            Self::OffOrWithin(i) => x == 0.0 || i.contains(x),
            _ => return Err(self.misfit("a number")),
        };
        match (inside, self) {
            (true, _) => Ok(()),
            (false, Self::OffOrWithin(i)) => {
                Err(format!("must be 0 (off) or in {}{}", i.text(), space(unit)))
            }
            (false, _) => Err(format!("must be in {}", self.text(unit))),
        }
    }

    /// Checks a whole number.
    pub fn check_count(&self, n: u64) -> Result<(), OutOfRange> {
        match *self {
            Self::Any => Ok(()),
            Self::Count { min, max } if (min..=max).contains(&n) => Ok(()),
            Self::Count { .. } => Err(format!("must be {}", self.text(""))),
            _ => Err(self.misfit("a whole number")),
        }
    }

    /// Checks three numbers.
    pub fn check_triple(&self, v: &[f64; 3], unit: &str) -> Result<(), OutOfRange> {
        match self {
            Self::Any if v.iter().all(|x| x.is_finite()) => Ok(()),
            Self::Any => Err("each component must be finite".to_owned()),
            Self::Within(i) => match v.iter().all(|&x| i.contains(x)) {
                true => Ok(()),
                false => Err(format!(
                    "each component must lie in {}{}",
                    i.text(),
                    space(unit)
                )),
            },
            Self::Components(parts) => {
                for ((name, i, unit), &x) in parts.iter().zip(v) {
                    if !i.contains(x) {
                        return Err(format!("{name} must lie in {}{}", i.text(), space(unit)));
                    }
                }
                Ok(())
            }
            _ => Err(self.misfit("three numbers")),
        }
    }

    /// Checks a list of names.
    pub fn check_list<T: PartialEq>(&self, items: &[T]) -> Result<(), OutOfRange> {
        match self {
            Self::Any => Ok(()),
            Self::EachOnce if items.is_empty() => Err("at least one is needed".to_owned()),
            Self::EachOnce => {
                let repeated = items
                    .iter()
                    .enumerate()
                    .any(|(i, item)| items[..i].contains(item));
                match repeated {
                    true => Err("each may be listed only once".to_owned()),
                    false => Ok(()),
                }
            }
            _ => Err(self.misfit("a list")),
        }
    }

    /// The range as the manual states it, e.g. `[1e-9, 1e6] m`.
    pub fn text(&self, unit: &str) -> String {
        let unit = space(unit);
        match self {
            Self::Any => "any".to_owned(),
            Self::Within(i) => format!("{}{unit}", i.text()),
            Self::OffOrWithin(i) => format!("0 (off) or {}{unit}", i.text()),
            Self::Count { min, max } => format!("an integer in [{min}, {max}]"),
            Self::Components(parts) => {
                let mut text = String::new();
                for (k, (name, i, unit)) in parts.iter().enumerate() {
                    let sep = if k == 0 { "" } else { ", " };
                    let _ = write!(text, "{sep}{name} in {}{}", i.text(), space(unit));
                }
                text
            }
            Self::EachOnce => "at least one, each at most once".to_owned(),
        }
    }

    /// The closed numeric bounds, for a ROS parameter descriptor (which only states
    /// inclusive ranges): None where the range is open, split or not numeric.
    pub fn closed_bounds(&self) -> Option<(f64, f64)> {
        match self {
            Self::Within(i) if !i.lo_open && !i.hi_open => Some((i.lo, i.hi)),
            Self::Count { min, max } => Some((*min as f64, *max as f64)),
            _ => None,
        }
    }

    /// A table error (a range that does not fit the parameter's type); the table's test
    /// checks every default against its range, so this never reaches a user.
    fn misfit(&self, what: &str) -> OutOfRange {
        format!("the table gives {what} the range {self:?}")
    }
}

fn space(unit: &str) -> String {
    if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// A number as the manual writes it: `0.5`, `3600`, `1e-9`, `1e6`.
pub fn number_text(x: f64) -> String {
    let plain = format!("{x}");
    let scientific = format!("{x:e}");
    if plain.len() <= scientific.len() {
        plain
    } else {
        scientific
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_written() {
        assert_eq!(number_text(1e-9), "1e-9");
        assert_eq!(number_text(1e6), "1e6");
        assert_eq!(number_text(0.5), "0.5");
        assert_eq!(number_text(3600.0), "3600");
        assert_eq!(number_text(-180.0), "-180");
        assert_eq!(Interval::above(0.0, 1.0).text(), "(0, 1]");
        assert_eq!(Interval::below(0.0, 90.0).text(), "[0, 90)");
    }

    #[test]
    fn ranges_accept_and_refuse_with_a_reason() {
        let sigma = Range::Within(Interval::closed(1e-9, 1e6));
        assert!(sigma.check_number(3.0, "m").is_ok());
        let e = sigma.check_number(1e300, "m").unwrap_err();
        assert_eq!(e, "must be in [1e-9, 1e6] m");
        assert!(sigma.check_number(f64::NAN, "m").is_err());
        let gate = Range::OffOrWithin(Interval::closed(1.0, 1e6));
        assert!(gate.check_number(0.0, "").is_ok() && gate.check_number(0.5, "").is_err());
        let count = Range::Count {
            min: 10,
            max: 10_000,
        };
        assert!(count.check_count(u64::MAX).is_err() && count.check_count(100).is_ok());
        assert!(Range::EachOnce.check_list(&[1, 2, 1]).is_err());
        assert!(Range::EachOnce.check_list::<u8>(&[]).is_err());
        assert!(count.check_number(1.0, "").is_err(), "a misfit is an error");
    }
}
