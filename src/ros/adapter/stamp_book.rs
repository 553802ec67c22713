//! The exact ROS stamps of recent inputs, so that an output computed at an input's time
//! carries that input's stamp to the nanosecond (issue 16, item 3).
//!
//! Choice: the engine keeps absolute `f64` seconds and the adapter remembers, for the
//! last few inputs, which ROS `Time` each `t_s` came from. The engine's math, and so the
//! golden replay, stay bit-identical, and the one place that turns seconds back into a
//! stamp looks the exact stamp up first. The alternative, `f64` seconds relative to an
//! epoch near the data, would change every `dt` in the last bits (the golden data
//! regenerated) and need an epoch carried through resets and time jumps, and it would
//! still round a stamp to nanoseconds on the way out. A `t_s` no input had (none today:
//! solutions are at IMU times, reports at their measurement's) falls back to the nearest
//! nanosecond ([`seconds_to_time`]).

use std::collections::VecDeque;

use crate::ros::convert::{seconds_to_time, ConvertError};
use crate::ros::msg::Time;

/// Choice: stamps remembered per stream. Outputs are stamped in the call that fed their
/// input (at most [`super::TIME_JUMP_CONFIRM_SAMPLES`] IMU samples at once); a report is
/// at a measurement held at most [`crate::engine::MAX_PENDING_MEASUREMENTS`] deep.
/// 128 covers both with room; a lookup walks back from the newest, where the hit is.
pub(super) const REMEMBERED_STAMPS: usize = 128;

/// The stamps of one input stream's last [`REMEMBERED_STAMPS`] messages, by their time in
/// seconds.
#[derive(Debug, Clone, Default)]
pub(super) struct StampBook {
    recent: VecDeque<(f64, Time)>,
}

impl StampBook {
    /// Remembers that the input at `t_s` was stamped `stamp`. A repeat of the newest `t_s`
    /// (two stamps within one `f64` step, or a duplicate) keeps the first, as the engine
    /// keeps the first of duplicate samples.
    pub(super) fn note(&mut self, t_s: f64, stamp: Time) {
        if self.recent.back().is_some_and(|&(newest, _)| newest == t_s) {
            return;
        }
        if self.recent.len() >= REMEMBERED_STAMPS {
            self.recent.pop_front();
        }
        self.recent.push_back((t_s, stamp));
    }

    /// The stamp of the input at exactly `t_s`, else the nearest nanosecond.
    pub(super) fn stamp(&self, t_s: f64) -> Result<Time, ConvertError> {
        match self.recent.iter().rev().find(|&&(t, _)| t == t_s) {
            Some(&(_, stamp)) => Ok(stamp),
            None => seconds_to_time(t_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::convert::time_to_seconds;

    #[test]
    fn a_remembered_stamp_comes_back_exactly_others_round() {
        let mut book = StampBook::default();
        let odd = Time {
            sec: 1_764_000_000,
            nanosec: 2_500_001,
        };
        let t_s = time_to_seconds(&odd).unwrap();
        assert_ne!(seconds_to_time(t_s).unwrap(), odd, "f64 seconds lose it");
        book.note(t_s, odd);
        assert_eq!(book.stamp(t_s).unwrap(), odd);
        // A second stamp of the same f64 keeps the first.
        book.note(
            t_s,
            Time {
                nanosec: 2_500_002,
                ..odd
            },
        );
        assert_eq!(book.stamp(t_s).unwrap(), odd);
        assert_eq!(book.stamp(1.5).unwrap(), seconds_to_time(1.5).unwrap());
        for k in 0..REMEMBERED_STAMPS {
            book.note(2.0 + k as f64, Time::default());
        }
        assert_eq!(book.recent.len(), REMEMBERED_STAMPS, "bounded");
        assert_eq!(book.stamp(t_s).unwrap(), seconds_to_time(t_s).unwrap());
    }
}
