//! The progress of a long command on stderr, in one style for every command: on a
//! terminal one line redrawn in place, elsewhere (a log, CI, a pipe) a line every few
//! seconds, so that no run of minutes is silent (issue 16: `compare` on a 1-hour bag said
//! nothing for 45 s) and a run of a few seconds writes nothing to a log.

use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Choice: off a terminal, a line every 5 s: a run of 45 s says 8 times how far it is, a
/// run shorter than 5 s says nothing.
const LOG_EVERY: Duration = Duration::from_secs(5);
/// On a terminal, the line is redrawn at most ten times a second.
const REDRAW_EVERY: Duration = Duration::from_millis(100);

/// A command's progress line (shareable between worker threads).
pub struct Progress {
    live: bool,
    /// When the line was last shown (at first: when the command started).
    shown: Mutex<Instant>,
}

impl Default for Progress {
    fn default() -> Self {
        Self::new()
    }
}

impl Progress {
    /// Live on a terminal, a line every few seconds elsewhere.
    pub fn new() -> Self {
        Self {
            live: std::io::stderr().is_terminal(),
            shown: Mutex::new(Instant::now()),
        }
    }

    /// Whether the line is redrawn in place (stderr is a terminal).
    pub fn is_live(&self) -> bool {
        self.live
    }

    /// Shows `text()` when it is time (it is not built otherwise).
    pub fn show(&self, text: impl FnOnce() -> String) {
        let every = if self.live { REDRAW_EVERY } else { LOG_EVERY };
        let Ok(mut shown) = self.shown.lock() else {
            return;
        };
        if shown.elapsed() < every {
            return;
        }
        *shown = Instant::now();
        let text = text();
        let mut err = std::io::stderr().lock();
        let _ = if self.live {
            write!(err, "\r\x1b[K{text}")
        } else {
            writeln!(err, "{text}")
        };
        let _ = err.flush();
    }

    /// Shows `what` done to `fraction` (0 to 1) with a bar, when it is time.
    pub fn fraction(&self, what: &str, fraction: f64) {
        self.show(|| format!("{what}: {}", bar(fraction)));
    }

    /// Clears the live line, so that what follows starts on a clean line.
    pub fn end(&self) {
        if self.live {
            eprint!("\r\x1b[K");
        }
    }
}

/// `[#####               ]  25.0 %`.
fn bar(fraction: f64) -> String {
    let width = 40;
    let fraction = fraction.clamp(0.0, 1.0);
    let done = (fraction * width as f64).round() as usize;
    format!(
        "[{}{}] {:5.1} %",
        "#".repeat(done),
        " ".repeat(width - done),
        fraction * 100.0
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bar_is_clamped_and_aligned() {
        assert_eq!(bar(0.25).len(), bar(1.0).len());
        assert!(bar(0.25).starts_with(&format!("[{}{}]", "#".repeat(10), " ".repeat(30))));
        assert!(bar(2.0).ends_with("100.0 %"));
        assert!(bar(-1.0).ends_with("  0.0 %"));
    }

    #[test]
    fn nothing_is_shown_before_it_is_time() {
        let p = Progress {
            live: false,
            shown: Mutex::new(Instant::now()),
        };
        p.show(|| panic!("built before {LOG_EVERY:?}"));
    }
}
