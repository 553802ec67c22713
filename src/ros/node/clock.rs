//! The node's time: the wall clock, or the last `/clock` message when `use_sim_time` is
//! true. It stamps /diagnostics and /rosout and measures the time since the last input;
//! the filter itself runs on its inputs' stamps either way.

use std::time::{SystemTime, UNIX_EPOCH};

use crate::ros::convert::time_to_seconds;
use crate::ros::msg::{Clock, Time};

/// The latest simulated time seen on `/clock`.
#[derive(Debug, Clone, Default)]
pub struct NodeClock {
    sim: Option<Time>,
}

/// Wall-clock ROS time.
pub fn wall_time() -> Time {
    let d = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    Time {
        sec: i32::try_from(d.as_secs()).unwrap_or(i32::MAX),
        nanosec: d.subsec_nanos(),
    }
}

impl NodeClock {
    /// Takes one `/clock` message. Choice (as rclcpp): a clock that goes backwards (a bag
    /// played in a loop) is followed, not refused.
    pub fn on_clock(&mut self, msg: &Clock) {
        self.sim = Some(msg.clock);
    }

    /// The node's time now. As in ROS, with `use_sim_time` and no `/clock` yet the time is
    /// zero.
    pub fn now(&self, use_sim_time: bool) -> Time {
        if use_sim_time {
            self.sim.unwrap_or_default()
        } else {
            wall_time()
        }
    }

    /// [`Self::now`] in seconds (0 for a stamp that does not convert).
    pub fn now_s(&self, use_sim_time: bool) -> f64 {
        time_to_seconds(&self.now(use_sim_time)).unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sim_time_follows_clock_and_is_zero_before_it() {
        let mut c = NodeClock::default();
        assert_eq!(c.now(true), Time::default());
        assert!(c.now(false).sec > 1_600_000_000, "wall clock");
        let at = |sec| Clock {
            clock: Time { sec, nanosec: 5 },
        };
        c.on_clock(&at(42));
        assert_eq!(c.now(true), at(42).clock);
        c.on_clock(&at(7));
        assert_eq!(c.now(true), at(7).clock, "backwards is followed");
        assert!(c.now(false).sec > 1_600_000_000, "wall clock unaffected");
    }
}
