//! The order of receiver epochs: each RAWX's receiver time (GPS week and time of week,
//! so a week rollover is just the next second) must follow the last accepted one, within
//! [`TIMELINE_STEP_S`]. An epoch before it, or further after it, is a jump: dropped until
//! [`TIMELINE_CONFIRM_EPOCHS`] epochs in a row follow the new time, which is then taken
//! (a receiver clock reset, a restart after an outage); a stray epoch alone is never
//! used, so one forged or corrupt time cannot move the satellites to another instant.

use crate::gnss::ephemeris::GpsTime;

/// Two receiver times closer than this (s) are the same epoch.
/// Choice: epochs are 40 ms apart at the least (25 Hz, the fastest u-blox rate); 1 µs is
/// far below that and far above the f64 resolution of a time of week (0.1 ns).
const SAME_EPOCH_S: f64 = 1e-6;

/// Choice: after a jump, the new timeline is taken once this many epochs in a row have
/// followed it; one outlying epoch alone never moves the timeline, a sustained jump does
/// within a fraction of a second at 10 Hz (the price: two epochs after an outage).
pub const TIMELINE_CONFIRM_EPOCHS: u32 = 3;

/// Choice: consecutive epochs are at most this far apart (s), which covers measurement
/// rates down to 0.1 Hz; beyond it the receiver time jumped (or the receiver was silent).
pub const TIMELINE_STEP_S: f64 = 10.0;

/// What to do with an epoch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// After the last accepted epoch: use it.
    Next,
    /// The epochs since a jump back have confirmed the new timeline: use it.
    NewTimeline,
    /// The same receiver time as the last accepted epoch: drop it.
    Duplicate,
    /// Before the last accepted epoch, not (yet) a confirmed new timeline: drop it.
    Backwards,
    /// More than [`TIMELINE_STEP_S`] after the last accepted epoch, not (yet) a confirmed
    /// new timeline: drop it.
    Ahead,
}

/// The timeline of accepted epochs.
#[derive(Debug, Clone, Default)]
pub struct EpochSequence {
    last: Option<GpsTime>,
    /// Epochs in a row after a jump: the latest one's time, and how many.
    jump: Option<(GpsTime, u32)>,
}

impl EpochSequence {
    /// The verdict on an epoch at receiver time `t` (finite), and the timeline moved on
    /// when it is used.
    pub fn judge(&mut self, t: GpsTime) -> Verdict {
        let Some(last) = self.last else {
            self.last = Some(t);
            return Verdict::Next;
        };
        let dt_s = t.seconds_since(&last);
        if dt_s.abs() < SAME_EPOCH_S {
            return Verdict::Duplicate;
        }
        if dt_s > 0.0 && dt_s <= TIMELINE_STEP_S {
            self.last = Some(t);
            self.jump = None;
            return Verdict::Next;
        }
        let run = match self.jump {
            Some((previous, n))
                if (SAME_EPOCH_S..=TIMELINE_STEP_S).contains(&t.seconds_since(&previous)) =>
            {
                n + 1
            }
            _ => 1,
        };
        if run >= TIMELINE_CONFIRM_EPOCHS {
            self.last = Some(t);
            self.jump = None;
            Verdict::NewTimeline
        } else {
            self.jump = Some((t, run));
            if dt_s < 0.0 {
                Verdict::Backwards
            } else {
                Verdict::Ahead
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rollover_duplicates_and_a_sustained_jump_back() {
        let mut s = EpochSequence::default();
        let at = |week, tow| GpsTime::new(week, tow);
        assert_eq!(s.judge(at(2047, 604_799.9)), Verdict::Next);
        assert_eq!(s.judge(at(2048, 0.0)), Verdict::Next, "week rollover");
        assert_eq!(s.judge(at(2048, 0.0)), Verdict::Duplicate);
        assert_eq!(s.judge(at(2048, 0.1)), Verdict::Next);
        // Stray epochs in the past are dropped, the timeline stays.
        assert_eq!(s.judge(at(2047, 100.0)), Verdict::Backwards);
        assert_eq!(s.judge(at(2047, 200.0)), Verdict::Backwards);
        assert_eq!(s.judge(at(2047, 300.0)), Verdict::Backwards);
        assert_eq!(s.judge(at(2048, 0.2)), Verdict::Next);
        // A receiver clock reset 5 s back: taken on its third epoch.
        assert_eq!(s.judge(at(2047, 604_795.3)), Verdict::Backwards);
        assert_eq!(s.judge(at(2047, 604_795.4)), Verdict::Backwards);
        assert_eq!(s.judge(at(2047, 604_795.5)), Verdict::NewTimeline);
        assert_eq!(s.judge(at(2047, 604_795.6)), Verdict::Next);
        // A stray epoch an hour ahead is dropped; a receiver back after a 60 s outage is
        // followed from its third epoch.
        assert_eq!(s.judge(at(2048, 3_000.0)), Verdict::Ahead);
        assert_eq!(s.judge(at(2047, 604_795.7)), Verdict::Next);
        assert_eq!(s.judge(at(2048, 55.0)), Verdict::Ahead);
        assert_eq!(s.judge(at(2048, 55.1)), Verdict::Ahead);
        assert_eq!(s.judge(at(2048, 55.2)), Verdict::NewTimeline);
    }
}
