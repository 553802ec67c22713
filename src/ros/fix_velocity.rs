//! `gnss/fix` joined with the `gnss/velocity` of its stamp: the [`FixPairing`] over the
//! converted messages, plus the rule which velocity frames are usable. The adapter joins
//! through [`FixVelocityJoin`] for the live node and `gnss_ins replay` alike.

use crate::engine::GnssFix;
use crate::ros::convert::GnssVelocity;
use crate::ros::fix_pairing::{FixPairing, Released, Stamped};

/// A fix with the `frame_id` of its NavSatFix.
#[derive(Debug, Clone, PartialEq)]
pub struct FramedFix {
    /// The fix, without velocity.
    pub fix: GnssFix,
    /// `header.frame_id` of the NavSatFix.
    pub frame_id: String,
}

impl Stamped for FramedFix {
    fn t_s(&self) -> f64 {
        self.fix.t_s
    }
}

impl Stamped for GnssVelocity {
    fn t_s(&self) -> f64 {
        self.t_s
    }
}

/// What became of the velocity of a joined fix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum VelocityUse {
    /// No velocity of the fix's stamp arrived.
    None,
    /// Its velocity is in the fix.
    Paired,
    /// Its velocity was in this frame, neither the map frame nor the fix's: not used.
    ForeignFrame(String),
}

/// A fix ready for the engine.
#[derive(Debug, Clone, PartialEq)]
pub struct Joined {
    /// The fix, with its velocity when one was paired and usable.
    pub fix: GnssFix,
    /// `header.frame_id` of its NavSatFix.
    pub frame_id: String,
    /// What became of its velocity.
    pub velocity: VelocityUse,
}

/// Joins fixes and velocities (see [`crate::ros::fix_pairing`] for when a fix waits).
#[derive(Debug, Clone)]
pub struct FixVelocityJoin {
    pairing: FixPairing<FramedFix, GnssVelocity>,
    map_frame: String,
}

impl FixVelocityJoin {
    /// A join whose ENU frame is `map_frame`.
    ///
    /// Convention: the twist is the ENU velocity (REP-105) when `header.frame_id` is the
    /// map frame; a velocity in its fix's frame (what GNSS drivers such as ublox_gps send)
    /// is read as ENU too. Any other frame is not used.
    pub fn new(map_frame: &str) -> Self {
        Self {
            pairing: FixPairing::default(),
            map_frame: map_frame.to_owned(),
        }
    }

    /// A fix arrives: the fixes for the engine now.
    pub fn on_fix(&mut self, fix: FramedFix) -> Vec<Joined> {
        let released = self.pairing.on_fix(fix);
        self.joined(released)
    }

    /// A velocity arrives: the fixes for the engine now.
    pub fn on_velocity(&mut self, velocity: GnssVelocity) -> Vec<Joined> {
        let released = self.pairing.on_velocity(velocity);
        self.joined(released)
    }

    /// The IMU time reached `t_s` (call before the engine gets that sample): the fixes
    /// that waited long enough.
    pub fn on_time(&mut self, t_s: f64) -> Vec<Joined> {
        let released = self.pairing.on_time(t_s);
        self.joined(released)
    }

    /// Drops what waits (the filter was reset).
    pub fn clear(&mut self) {
        self.pairing.clear();
    }

    /// Velocities dropped for want of a fix of their stamp.
    pub fn unpaired_velocities(&self) -> u64 {
        self.pairing.unpaired_velocities()
    }

    fn joined(&self, released: Vec<Released<FramedFix, GnssVelocity>>) -> Vec<Joined> {
        released
            .into_iter()
            .map(|Released { fix, velocity }| {
                let FramedFix { mut fix, frame_id } = fix;
                let velocity = match velocity {
                    None => VelocityUse::None,
                    Some(v) if v.frame_id == self.map_frame || v.frame_id == frame_id => {
                        fix.velocity_enu_mps = Some(v.velocity_enu_mps);
                        fix.velocity_covariance_enu_m2_s2 = v.covariance_enu_m2_s2;
                        VelocityUse::Paired
                    }
                    Some(v) => VelocityUse::ForeignFrame(v.frame_id),
                };
                Joined {
                    fix,
                    frame_id,
                    velocity,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::Llh;
    use nalgebra::Vector3;

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

    fn velocity(t_s: f64, frame_id: &str) -> GnssVelocity {
        GnssVelocity {
            t_s,
            frame_id: frame_id.to_owned(),
            velocity_enu_mps: Vector3::new(1.0, 2.0, t_s),
            covariance_enu_m2_s2: None,
        }
    }

    #[test]
    fn velocities_in_the_map_or_the_fixs_frame_join_others_do_not() {
        let mut join = FixVelocityJoin::new("odom_enu");
        for (t_s, frame, expected) in [
            (1.0, "odom_enu", VelocityUse::Paired),
            (2.0, "gnss", VelocityUse::Paired),
            (
                3.0,
                "base_link",
                VelocityUse::ForeignFrame("base_link".to_owned()),
            ),
        ] {
            assert!(join.on_fix(fix(t_s)).is_empty());
            let joined = join.on_velocity(velocity(t_s, frame));
            assert_eq!(joined.len(), 1);
            assert_eq!(joined[0].velocity, expected, "{frame}");
            assert_eq!(joined[0].frame_id, "gnss");
            let v = joined[0].fix.velocity_enu_mps;
            if expected == VelocityUse::Paired {
                assert_eq!(v, Some(Vector3::new(1.0, 2.0, t_s)));
            } else {
                assert_eq!(v, None, "a foreign velocity stays out of the fix");
            }
        }
        assert_eq!(join.unpaired_velocities(), 0);
    }
}
