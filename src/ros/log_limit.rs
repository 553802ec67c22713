//! Rate-limited warnings for repeated bad input.

use std::collections::HashMap;

/// Logs the 1st, 10th, 100th, ... occurrence of each kind of warning, with its count.
///
/// Choice: limiting by count instead of by wall time keeps the handler free of clocks and
/// deterministic in tests, and still bounds a flood of N bad messages to log10(N) lines.
#[derive(Debug, Default)]
pub struct LogLimiter {
    counts: HashMap<String, u64>,
}

impl LogLimiter {
    /// Counts one `kind` warning; returns true when it was logged.
    pub fn warn(&mut self, kind: &str, message: &str) -> bool {
        let n = self.counts.entry(kind.to_owned()).or_insert(0);
        *n += 1;
        let log_it = is_power_of_ten(*n);
        if log_it {
            log::warn!("{message} (occurrence {n} of `{kind}`)");
        }
        log_it
    }
}

#[cfg(test)]
impl LogLimiter {
    /// How many `kind` warnings were counted.
    pub fn count(&self, kind: &str) -> u64 {
        self.counts.get(kind).copied().unwrap_or(0)
    }

    /// How many `kind` warnings were logged: one per power of ten up to the count.
    pub fn logged(&self, kind: &str) -> u64 {
        let mut n = self.count(kind);
        let mut powers = 0;
        while n > 0 {
            n /= 10;
            powers += 1;
        }
        powers
    }
}

fn is_power_of_ten(mut n: u64) -> bool {
    while n >= 10 && n % 10 == 0 {
        n /= 10;
    }
    n == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn logs_at_powers_of_ten_per_kind() {
        let mut l = LogLimiter::default();
        let logged: Vec<u64> = (1..=1000).filter(|_| l.warn("a", "x")).collect::<Vec<_>>();
        assert_eq!(logged.len(), 4);
        let mut l = LogLimiter::default();
        let which: Vec<u64> = (1..=1000u64).filter(|_| l.warn("a", "x")).collect();
        assert_eq!(which, vec![1, 10, 100, 1000]);
        assert!(l.warn("b", "y"), "another kind has its own count");
    }
}
