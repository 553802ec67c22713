//! The IMU time line: a stamp far off it is an outlier, dropped and counted, unless
//! several consecutive stamps agree on the new time (a bag played in a loop, a sensor
//! whose clock was set), which then resets the filter.

use crate::ins::ImuSample;

/// Choice: an IMU stamp more than this much older than the last accepted one is off the
/// time line; smaller steps back are ordinary out-of-order samples the engine rejects.
/// 1 s is far beyond any transport reordering.
pub const TIME_JUMP_BACK_S: f64 = 1.0;

/// Choice: this many consecutive samples off the time line, each within
/// `engine.max_imu_gap_s` after the one before, make a time jump (the filter resets and
/// they are fed); fewer are outliers, dropped. One spoofed or corrupted stamp (1 s in the
/// past, 10⁶ s ahead) then costs one sample instead of a reset, and one such message a
/// second can no longer keep the filter from running. 10 samples (0.1 s of a 100 Hz IMU)
/// are held at most, and a genuine jump is followed without losing them.
pub const TIME_JUMP_CONFIRM_SAMPLES: usize = 10;

/// Where a sample stands against the time line.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Verdict {
    /// On the time line (or there is none yet): feed it.
    OnLine,
    /// Off the time line: held until its run confirms a jump or ends.
    Held,
    /// The time jumped: the samples of the run, in order, to feed after the reset.
    Jumped(Vec<ImuSample>),
}

/// The run of consecutive samples off the time line (at most
/// [`TIME_JUMP_CONFIRM_SAMPLES`]).
#[derive(Debug, Clone, Default)]
pub(super) struct TimeLine {
    held: Vec<ImuSample>,
}

impl TimeLine {
    /// Judges `sample` against the last accepted IMU time `last_t_s`; a run it ends or
    /// replaces is dropped and added to `outliers`.
    pub(super) fn judge(
        &mut self,
        sample: &ImuSample,
        last_t_s: Option<f64>,
        max_gap_s: f64,
        outliers: &mut u64,
    ) -> Verdict {
        let on_line = last_t_s.is_none_or(|last_t_s| {
            sample.t_s >= last_t_s - TIME_JUMP_BACK_S && sample.t_s <= last_t_s + max_gap_s
        });
        if on_line {
            *outliers += self.held.len() as u64;
            self.held.clear();
            return Verdict::OnLine;
        }
        let continues_run = self.held.last().is_some_and(|last| {
            let dt_s = sample.t_s - last.t_s;
            dt_s > 0.0 && dt_s <= max_gap_s
        });
        if !continues_run {
            *outliers += self.held.len() as u64;
            self.held.clear();
        }
        self.held.push(*sample);
        if self.held.len() >= TIME_JUMP_CONFIRM_SAMPLES {
            Verdict::Jumped(std::mem::take(&mut self.held))
        } else {
            Verdict::Held
        }
    }
}
