//! Pairs `gnss/fix` with `gnss/velocity` of the same stamp before the loose update, so the
//! engine gets one fix with its velocity (it refuses a second measurement at one stamp).
//!
//! Choice (deterministic, driven by message order and stamps only, never by a clock):
//! - until the first velocity arrives, fixes pass through at once (no velocity stream);
//! - afterwards a fix is held until its velocity arrives, the next fix arrives, a later
//!   velocity arrives, or the IMU time passes its stamp by [`PAIRING_WAIT_S`]; it then
//!   goes on without a velocity;
//! - a velocity arriving first waits for its fix likewise; it is dropped and counted as
//!   unpaired when a later fix or velocity arrives or after [`PAIRING_WAIT_S`] of IMU time,
//!   and a velocity older than the held fix (its fix went on already) is dropped at once.
//!
//! The engine applies a fix released late by rolling back, so holding costs only latency.

use crate::engine::GnssFix;
use crate::ros::convert::GnssVelocity;

/// A fix and a velocity belong together when their stamps differ by at most this (s).
pub const PAIRING_TOLERANCE_S: f64 = 1e-3;
/// How long (IMU time, s) a fix or a velocity waits for its partner. Choice: receivers
/// send both within milliseconds; 0.2 s covers a loaded transport and stays far within
/// the engine's IMU buffer, so the late update rolls back.
pub const PAIRING_WAIT_S: f64 = 0.2;

/// A fix with the `frame_id` of its NavSatFix.
#[derive(Debug, Clone, PartialEq)]
pub struct FramedFix {
    /// The fix, without velocity.
    pub fix: GnssFix,
    /// `header.frame_id` of the NavSatFix.
    pub frame_id: String,
}

/// A fix leaving the pairing, with the velocity of its stamp when one arrived.
#[derive(Debug, Clone, PartialEq)]
pub struct Released {
    /// The fix.
    pub fix: FramedFix,
    /// Its velocity, if paired.
    pub velocity: Option<GnssVelocity>,
}

/// The pairing state: at most one held fix and one waiting velocity.
#[derive(Debug, Clone, Default)]
pub struct FixPairing {
    fix: Option<FramedFix>,
    velocity: Option<GnssVelocity>,
    velocities_seen: bool,
    unpaired_velocities: u64,
}

fn same_stamp(a_s: f64, b_s: f64) -> bool {
    (a_s - b_s).abs() <= PAIRING_TOLERANCE_S
}

fn alone(fix: FramedFix) -> Released {
    Released {
        fix,
        velocity: None,
    }
}

impl FixPairing {
    /// Velocities dropped without a fix so far.
    pub fn unpaired_velocities(&self) -> u64 {
        self.unpaired_velocities
    }

    /// A fix arrives: what goes to the engine now.
    pub fn on_fix(&mut self, fix: FramedFix) -> Vec<Released> {
        let mut out = Vec::new();
        if let Some(v) = self.velocity.take() {
            if same_stamp(v.t_s, fix.fix.t_s) {
                out.extend(self.fix.take().map(alone));
                out.push(Released {
                    fix,
                    velocity: Some(v),
                });
                return out;
            }
            if v.t_s < fix.fix.t_s {
                self.unpaired_velocities += 1;
            } else {
                // A later fix's velocity (out of order): it keeps waiting.
                self.velocity = Some(v);
            }
        }
        out.extend(self.fix.take().map(alone));
        if self.velocities_seen {
            self.fix = Some(fix);
        } else {
            out.push(alone(fix));
        }
        out
    }

    /// A velocity arrives: what goes to the engine now.
    pub fn on_velocity(&mut self, velocity: GnssVelocity) -> Vec<Released> {
        self.velocities_seen = true;
        let mut out = Vec::new();
        if let Some(held) = self.fix.take() {
            if same_stamp(held.fix.t_s, velocity.t_s) {
                out.push(Released {
                    fix: held,
                    velocity: Some(velocity),
                });
                return out;
            }
            if velocity.t_s < held.fix.t_s {
                // Its fix went on already (or never came).
                self.unpaired_velocities += 1;
                self.fix = Some(held);
                return out;
            }
            // A later velocity: the held fix's own will not come.
            out.push(alone(held));
        }
        if self.velocity.replace(velocity).is_some() {
            self.unpaired_velocities += 1;
        }
        out
    }

    /// The IMU time reached `t_s`: a fix or velocity that waited [`PAIRING_WAIT_S`] leaves.
    pub fn on_time(&mut self, t_s: f64) -> Vec<Released> {
        if self
            .velocity
            .as_ref()
            .is_some_and(|v| t_s > v.t_s + PAIRING_WAIT_S)
        {
            self.velocity = None;
            self.unpaired_velocities += 1;
        }
        match &self.fix {
            Some(held) if t_s > held.fix.t_s + PAIRING_WAIT_S => {
                self.fix.take().map(alone).into_iter().collect()
            }
            _ => Vec::new(),
        }
    }

    /// Drops what waits (the filter was reset); a waiting velocity counts as unpaired.
    pub fn clear(&mut self) {
        self.fix = None;
        if self.velocity.take().is_some() {
            self.unpaired_velocities += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Llh;

    fn fix(t_s: f64) -> FramedFix {
        FramedFix {
            fix: GnssFix {
                t_s,
                position: Llh::from_degrees(40.0, -105.0, 1600.0),
                position_covariance_enu_m2: None,
                velocity_enu_mps: None,
                velocity_covariance_enu_m2_s2: None,
            },
            frame_id: "gnss".to_owned(),
        }
    }

    fn velocity(t_s: f64) -> GnssVelocity {
        GnssVelocity {
            t_s,
            frame_id: "map".to_owned(),
            velocity_enu_mps: nalgebra::Vector3::new(1.0, 2.0, t_s),
            covariance_enu_m2_s2: None,
        }
    }

    /// (fix stamp, velocity stamp) of what was released.
    fn stamps(r: &[Released]) -> Vec<(f64, Option<f64>)> {
        r.iter()
            .map(|r| (r.fix.fix.t_s, r.velocity.as_ref().map(|v| v.t_s)))
            .collect()
    }

    #[test]
    fn without_velocities_fixes_pass_at_once() {
        let mut p = FixPairing::default();
        assert_eq!(stamps(&p.on_fix(fix(1.0))), vec![(1.0, None)]);
        assert_eq!(stamps(&p.on_fix(fix(2.0))), vec![(2.0, None)]);
        assert!(p.on_time(10.0).is_empty());
        assert_eq!(p.unpaired_velocities(), 0);
    }

    #[test]
    fn velocity_after_or_before_its_fix_pairs_within_a_millisecond() {
        let mut p = FixPairing::default();
        assert!(p.on_velocity(velocity(1.0)).is_empty());
        assert_eq!(
            stamps(&p.on_fix(fix(1.0005))),
            vec![(1.0005, Some(1.0))],
            "velocity first"
        );
        assert!(p.on_fix(fix(2.0)).is_empty(), "held for its velocity");
        assert_eq!(
            stamps(&p.on_velocity(velocity(2.0009))),
            vec![(2.0, Some(2.0009))],
            "fix first"
        );
        assert_eq!(p.unpaired_velocities(), 0);
    }

    #[test]
    fn unpaired_and_out_of_order_velocities_are_counted_and_dropped() {
        let mut p = FixPairing::default();
        // A velocity whose fix never comes: the next fix drops it.
        assert!(p.on_velocity(velocity(1.0)).is_empty());
        assert!(p.on_fix(fix(2.0)).is_empty());
        assert_eq!(p.unpaired_velocities(), 1);
        // 2 ms apart is not the same stamp; a velocity older than the held fix is stale.
        assert!(p.on_velocity(velocity(1.998)).is_empty());
        assert_eq!(p.unpaired_velocities(), 2);
        // The fix's velocity never comes: the next fix releases it alone.
        assert_eq!(stamps(&p.on_fix(fix(3.0))), vec![(2.0, None)]);
        // A later velocity releases the held fix alone and waits; IMU time drops it.
        assert_eq!(stamps(&p.on_velocity(velocity(4.0))), vec![(3.0, None)]);
        assert!(p.on_time(4.0 + PAIRING_WAIT_S).is_empty(), "not yet");
        assert!(p.on_time(4.3).is_empty());
        assert_eq!(p.unpaired_velocities(), 3);
        // A held fix leaves alone after the wait.
        assert!(p.on_fix(fix(5.0)).is_empty());
        assert!(p.on_time(5.1).is_empty());
        assert_eq!(stamps(&p.on_time(5.25)), vec![(5.0, None)]);
        // Fixes out of order: a later fix's velocity keeps waiting for it.
        assert!(p.on_velocity(velocity(7.0)).is_empty());
        assert!(p.on_fix(fix(6.0)).is_empty(), "held");
        assert_eq!(
            stamps(&p.on_fix(fix(7.0))),
            vec![(6.0, None), (7.0, Some(7.0))]
        );
        // A reset drops the waiting velocity.
        assert!(p.on_velocity(velocity(8.0)).is_empty());
        p.clear();
        assert!(p.on_time(100.0).is_empty());
        assert_eq!(p.unpaired_velocities(), 4);
    }
}
