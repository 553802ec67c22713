//! A dispute of the divergence monitor ([`super::divergence`]): the GNSS leapt from
//! agreeing with the filter to beyond 5σ of it without the IMU (or the GNSS velocity)
//! seeing a motion, so one of the two is wrong and the monitor cannot tell which.
//!
//! Loosely coupled, the receiver's fixes are then held back by the leap
//! ([`Dispute::hold`], `loose.leap_hold_s`): the update takes each fix moved back by the
//! offset of the leap, so that the filter follows the fixes' motion but not their leap.
//! A street canyon's NLOS reception moves every fix by tens of metres at once, for as
//! long as the street lasts, at a claimed σ below a metre; followed, the filter was 30 m
//! off at a σ of 1 m for 100 s once it agreed with the fixes again (the consumer-MEMS
//! hour, seed 2, docs/results.md).
//!
//! Choices:
//! - A hold begins only with a leap out of fixes that moved little from epoch to epoch
//!   ([`RecentOffsets::newest_stands_out`]) and beyond 5σ of the fixes' covariance as the update
//!   weighs it (`loose.fix_consistency`): a degraded stretch whose fixes wander (simulated
//!   foliage) is no bias to hold.
//! - A leap, the first one and any later one, is confirmed by [`CONFIRM_EPOCHS`] epochs
//!   that stay where it leapt to; until then the fixes are left out, so that neither the
//!   leap nor a lone outlier (one of 261 m began a hold on seed 3 of the hour) pulls the
//!   filter, nor a fix that came back is pulled back by the held offset (akf_all ran
//!   150 m off vertically on tests/data/consumer_mems_drive.yaml).
//! - The confirmed leap's offset is taken as a bias of the fixes, constant while the hold
//!   lasts. A later leap is not taken as a new bias: while held, a filter that runs off
//!   moves the offset in steps that look like the GNSS's, and a hold that followed them
//!   kept a filter running off 240 m vertically (akf_all, that drive). A later change of
//!   the bias is an innovation like any other, bounded by `loose.fix_outlier_sigma`.
//! - The held fix's covariance is its own grown by the combined covariance at the leap
//!   (the offset is known to that) and by the scatter of the offsets since, which holds
//!   what the bias does after the leap (the canyon's vertical bias wanders by tens of
//!   metres): held without it, akf_all ran 70 m off on that drive.
//! - The hold ends when the fixes agree again (which ends the dispute), when a confirmed
//!   leap brings them back to within [`RETURN_SHARE`] of the held offset, or when the
//!   offsets' scatter reaches that share of it (noise, not a bias).
//!
//! Limit: a filter that leapt itself, with fixes that carry no velocity (the monitor
//! cannot tell), stays off by the leap, inside its published covariance (widened by the
//! offset while the dispute lasts), until the hold ends.

use std::collections::VecDeque;

use nalgebra::{Matrix3, Vector3};

use super::divergence::Disagreement;

/// Share of the held offset's length within which the fixes must come back to end the
/// hold.
///
/// Choice: one half. While held, the filter follows the motion of the fixes and so what
/// their bias does between leaps (the vertical bias of tests/data/consumer_mems_drive.yaml
/// crept by 50 m in 30 s), so the offset the fixes' return leaves may be a good part of
/// the bias; a change of the NLOS bias (seed 2 of the hour: from (−26, −30, +28) m to
/// (−38, −37, −40) m) leaves an offset as long as the bias was.
pub const RETURN_SHARE: f64 = 0.5;
/// Epochs, the leap's included, that confirm a leap of the fixes during a dispute.
/// Choice: 3; an outlier of the street canyon lasts one or two epochs (the consumer-MEMS
/// hour, seed 2), and a hold that ended on one made the filter follow the canyon's bias.
pub const CONFIRM_EPOCHS: u32 = 3;
/// Judged epochs whose offsets tell how far the fixes wander about the filter before a
/// leap. Choice: 10, the consistency judge's window (`engine::fix_consistency`).
pub const RECENT_EPOCHS: usize = 10;
/// Share of a leap's length below which the fixes' typical step from epoch to epoch
/// must lie for the leap to hold them ([`RecentOffsets::newest_stands_out`]). Choice: one half.
pub const WANDER_SHARE: f64 = 0.5;
/// Fewest steps of the recent offsets that tell how they wander.
pub const MIN_STEPS: usize = 3;
/// Fewest degrees of freedom of the offsets' scatter that is used.
pub const MIN_SCATTER_DOF: f64 = 2.0;

/// How the update takes the fixes of a dispute that holds them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hold {
    /// A leap of the fixes awaits confirmation: the fix is left out, so that the filter
    /// moves neither towards the fix nor towards the held position meanwhile.
    LeftOut { since_t_s: f64 },
    /// The fix is moved back by `offset_enu_m` (GNSS less filter at the leap, ENU, m),
    /// its covariance grown by `covariance_enu_m2` (m²).
    MovedBack {
        since_t_s: f64,
        offset_enu_m: Vector3<f64>,
        covariance_enu_m2: Matrix3<f64>,
    },
}

impl Hold {
    /// When the dispute that holds the fixes began (s).
    pub fn since_t_s(&self) -> f64 {
        match *self {
            Self::LeftOut { since_t_s } | Self::MovedBack { since_t_s, .. } => since_t_s,
        }
    }
}

/// See the module documentation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dispute {
    since_t_s: f64,
    /// The offset at the leap and its combined covariance, once confirmed. With
    /// `leap_epochs`, None: the fixes are not held (any more).
    held: Option<(Vector3<f64>, Matrix3<f64>)>,
    /// A leap of the fixes awaits confirmation: the epochs since it, its own included.
    leap_epochs: Option<u32>,
    scatter: Scatter,
}

impl Dispute {
    /// The dispute that the leap at epoch `d` begins; it holds the fixes when `hold`, once
    /// [`CONFIRM_EPOCHS`] epochs confirm the leap.
    pub fn begin(d: &Disagreement, hold: bool) -> Self {
        Self {
            since_t_s: d.t_s,
            held: None,
            leap_epochs: hold.then_some(1),
            scatter: Scatter::default(),
        }
    }

    /// Takes the dispute's next epoch `d`, which disagrees; `leapt`: its offset leapt from
    /// the epoch before's (beyond 5σ); `fixes_leapt`: as a leap of the fixes (beyond the
    /// covariance the update weighed them with, and not the filter's: its velocity error,
    /// if any, cannot have carried it there).
    pub fn next(&mut self, d: &Disagreement, leapt: bool, fixes_leapt: bool) {
        if !self.holding() {
            return;
        }
        self.leap_epochs = match self.leap_epochs {
            _ if fixes_leapt => Some(1),
            Some(epochs) if !leapt && epochs + 1 >= CONFIRM_EPOCHS => {
                self.confirmed(d);
                None
            }
            Some(epochs) if !leapt => Some(epochs + 1),
            // A lesser leap: the fixes wander; nothing is confirmed, and a hold that
            // was still to begin does not.
            Some(_) => {
                if self.held.is_none() {
                    self.stop_holding();
                }
                None
            }
            None => {
                if !leapt {
                    self.scatter.push(&d.offset_enu_m);
                }
                None
            }
        };
        if let Some((held_enu_m, _)) = self.held {
            // Offsets that wander by half the held one are noise, not a bias.
            let scatter_m = self.scatter.covariance_enu_m2().trace().sqrt();
            if scatter_m >= RETURN_SHARE * held_enu_m.norm() {
                self.stop_holding();
            }
        }
    }

    /// A leap of the fixes confirmed at epoch `d`: the first holds them from `d` on; a
    /// later one that brought them back towards the filter (to at most [`RETURN_SHARE`]
    /// of the held offset) ends the hold, and any other is an innovation.
    fn confirmed(&mut self, d: &Disagreement) {
        match self.held {
            None => self.held = Some((d.offset_enu_m, d.covariance_enu_m2)),
            Some((held_enu_m, _)) => {
                if d.offset_enu_m.norm() <= RETURN_SHARE * held_enu_m.norm() {
                    self.stop_holding();
                }
            }
        }
    }

    /// Whether the fixes are held: a leap awaits confirmation or holds them.
    fn holding(&self) -> bool {
        self.leap_epochs.is_some() || self.held.is_some()
    }

    fn stop_holding(&mut self) {
        self.held = None;
        self.leap_epochs = None;
    }

    /// How the update takes the fix now; None: as it is.
    pub fn hold(&self) -> Option<Hold> {
        if self.leap_epochs.is_some() {
            return Some(Hold::LeftOut {
                since_t_s: self.since_t_s,
            });
        }
        let (offset_enu_m, covariance_enu_m2) = self.held?;
        Some(Hold::MovedBack {
            since_t_s: self.since_t_s,
            offset_enu_m,
            covariance_enu_m2: covariance_enu_m2 + self.scatter.covariance_enu_m2(),
        })
    }
}

/// The scatter of the offsets about their mean (Welford's sums).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Scatter {
    count: f64,
    mean_enu_m: Vector3<f64>,
    sum_squares_m2: Matrix3<f64>,
}

impl Scatter {
    fn push(&mut self, offset_enu_m: &Vector3<f64>) {
        self.count += 1.0;
        let before = offset_enu_m - self.mean_enu_m;
        self.mean_enu_m += before / self.count;
        self.sum_squares_m2 += before * (offset_enu_m - self.mean_enu_m).transpose();
    }

    /// The sample covariance (m²); zero below [`MIN_SCATTER_DOF`] degrees of freedom.
    fn covariance_enu_m2(&self) -> Matrix3<f64> {
        let dof = self.count - 1.0;
        if dof < MIN_SCATTER_DOF {
            return Matrix3::zeros();
        }
        self.sum_squares_m2 / dof
    }
}

/// The offsets (GNSS less filter, ENU, m) of the newest judged epoch and the
/// [`RECENT_EPOCHS`] before it, less the held offset while a hold moves the fixes back:
/// how the fixes wander about where the filter takes them to be.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RecentOffsets {
    offsets_enu_m: VecDeque<Vector3<f64>>,
}

impl RecentOffsets {
    pub fn push(&mut self, offset_enu_m: &Vector3<f64>) {
        if self.offsets_enu_m.len() > RECENT_EPOCHS {
            self.offsets_enu_m.pop_front();
        }
        self.offsets_enu_m.push_back(*offset_enu_m);
    }

    /// Whether the newest offset, a leap, stands out of how the offsets before it wander:
    /// the median of their steps from epoch to epoch is below [`WANDER_SHARE`] of its
    /// length, or there are too few steps to tell.
    ///
    /// Choice: a degraded stretch (simulated foliage) moves the fixes by 5-15 m from epoch
    /// to epoch, and a hold there anchored the filter to one of them; a street canyon's
    /// leap of 30-130 m comes out of fixes that moved by a metre. The median, so that one
    /// outlier in the window (a step there and one back) does not hide the next leap.
    pub fn newest_stands_out(&self) -> bool {
        let Some(newest) = self.offsets_enu_m.back() else {
            return true;
        };
        let before = self.offsets_enu_m.iter().take(self.offsets_enu_m.len() - 1);
        let mut steps_m: Vec<f64> = before
            .clone()
            .zip(before.skip(1))
            .map(|(a, b)| (b - a).norm())
            .collect();
        if steps_m.len() < MIN_STEPS {
            return true;
        }
        steps_m.sort_by(f64::total_cmp);
        steps_m[steps_m.len() / 2] < WANDER_SHARE * newest.norm()
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::Hold;
    use crate::engine::divergence::{Disagreement, DivergenceMonitor};

    /// Checks the offsets `east_m` at 1 s epochs from `from_t_s`; after each, how the
    /// update takes the next fix: "-" as it is, "out" left out, "back N" moved back by N m.
    fn holds(monitor: &mut DivergenceMonitor, from_t_s: f64, east_m: &[f64]) -> Vec<String> {
        east_m
            .iter()
            .enumerate()
            .map(|(k, &e)| {
                let t_s = from_t_s + k as f64;
                assert!(
                    !monitor.check(t_s, Some(&Disagreement::east_of_filter(t_s, e))),
                    "divergence at {t_s} s"
                );
                match monitor.hold() {
                    None => "-".to_owned(),
                    Some(Hold::LeftOut { .. }) => "out".to_owned(),
                    Some(Hold::MovedBack { offset_enu_m, .. }) => {
                        format!("back {:.0}", offset_enu_m.x)
                    }
                }
            })
            .collect()
    }

    /// Ten epochs of fixes within half a metre of the filter.
    const STEADY_M: [f64; 10] = [0.3, -0.2, 0.1, 0.4, -0.3, 0.0, 0.2, -0.4, 0.3, -0.1];

    #[test]
    fn a_leap_out_of_steady_fixes_holds_them_once_confirmed_until_they_agree() {
        let mut monitor = DivergenceMonitor::default();
        assert!(holds(&mut monitor, 0.0, &STEADY_M).iter().all(|h| h == "-"));
        let after = holds(&mut monitor, 10.0, &[40.0, 41.0, 40.0, 39.0, 40.0, 0.2]);
        assert_eq!(after, ["out", "out", "back 40", "back 40", "back 40", "-"]);
        assert_eq!(monitor.dispute_offset_enu_m(), None);
    }

    #[test]
    fn fixes_that_leap_back_towards_the_filter_end_the_hold_not_the_dispute() {
        let mut monitor = DivergenceMonitor::default();
        holds(&mut monitor, 0.0, &STEADY_M);
        holds(&mut monitor, 10.0, &[40.0, 40.0, 40.0, 40.0]);
        // Back to 8 m: the filter drifted while held; the fixes correct it from now on.
        let after = holds(&mut monitor, 14.0, &[8.0, 8.0, 8.0, 8.0]);
        assert_eq!(after, ["out", "out", "-", "-"]);
        assert_eq!(
            monitor.dispute_offset_enu_m(),
            Some(Vector3::new(8.0, 0.0, 0.0)),
            "still a dispute, published as one"
        );
    }

    #[test]
    fn a_lone_outlier_during_a_hold_neither_ends_nor_moves_it() {
        let mut monitor = DivergenceMonitor::default();
        holds(&mut monitor, 0.0, &STEADY_M);
        holds(&mut monitor, 10.0, &[40.0, 40.0, 40.0]);
        let after = holds(&mut monitor, 13.0, &[200.0, 41.0, 40.0, 39.0, 40.0]);
        assert_eq!(after, ["out", "out", "out", "back 40", "back 40"]);
    }

    #[test]
    fn a_leap_out_of_wandering_fixes_holds_nothing() {
        let mut monitor = DivergenceMonitor::default();
        // Fixes that move by 8 m from epoch to epoch, each within 5σ of the filter.
        let wandering = [4.0, -4.0, 4.0, -4.0, 4.0, -4.0, 4.0, -4.0];
        holds(&mut monitor, 0.0, &wandering);
        let after = holds(&mut monitor, 8.0, &[9.0, 9.0, 9.0, 9.0]);
        assert!(after.iter().all(|h| h == "-"), "{after:?}");
        assert_eq!(
            monitor.dispute_offset_enu_m(),
            Some(Vector3::new(9.0, 0.0, 0.0))
        );
    }
}
