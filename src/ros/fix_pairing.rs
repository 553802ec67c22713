//! Pairs receiver fixes with the receiver velocities of the same stamp before the loose
//! update, so the engine gets one fix with its velocity (it refuses a second measurement
//! at one stamp). Pure logic over anything stamped, used by
//! [`FixVelocityJoin`](super::fix_velocity::FixVelocityJoin) to join `gnss/fix` with
//! `gnss/velocity` in the adapter (the live node and `gnss_ins replay` alike).
//!
//! Choice (deterministic, driven by message order and stamps only, never by a clock; and
//! the pairs do not depend on whether a fix or its velocity arrives first, since DDS gives
//! no order across topics):
//! - a fix is held until its velocity arrives, the next fix arrives, a later velocity
//!   arrives, or the IMU time passes its stamp by [`PAIRING_WAIT_S`]; it then goes on
//!   without a velocity;
//! - a velocity arriving first waits for its fix likewise; it is dropped and counted as
//!   unpaired when a later fix or velocity arrives or after [`PAIRING_WAIT_S`] of IMU time,
//!   and a velocity older than the held fix (its fix went on already) is dropped at once;
//! - whether there is a velocity stream at all is learnt, not assumed: until a velocity
//!   arrives the first fix is held like any other. When it leaves without one (the next
//!   fix or the wait released it), there is taken to be no velocity stream and later fixes
//!   pass at once, without the wait's latency; the first velocity to arrive turns the
//!   holding back on. So a stream with velocities pairs from its first fix on, in either
//!   arrival order; only a velocity stream that starts more than [`PAIRING_WAIT_S`] after
//!   the fixes may lose its first velocity (counted unpaired).
//!
//! The engine applies a fix released after the IMU passed its stamp by rolling back, so
//! holding costs only latency.

/// Something with a time of validity on the engine's time axis.
pub trait Stamped {
    /// Its stamp (s).
    fn t_s(&self) -> f64;
}

/// A fix and a velocity belong together when their stamps differ by at most this (s).
pub const PAIRING_TOLERANCE_S: f64 = 1e-3;
/// How long (IMU time, s) a fix or a velocity waits for its partner. Choice: receivers
/// send both within milliseconds; 0.2 s covers a loaded transport and stays far within
/// the engine's IMU buffer, so the late update rolls back.
pub const PAIRING_WAIT_S: f64 = 0.2;

/// A fix leaving the pairing, with the velocity of its stamp when one arrived.
#[derive(Debug, Clone, PartialEq)]
pub struct Released<F, V> {
    /// The fix.
    pub fix: F,
    /// Its velocity, if paired.
    pub velocity: Option<V>,
}

/// What the pairing knows of the velocity stream.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
enum VelocityStream {
    /// No velocity yet and no fix has left without one: fixes are held.
    #[default]
    Unknown,
    /// A velocity arrived: fixes are held for theirs.
    Present,
    /// A fix left without a velocity before any velocity arrived: fixes pass at once.
    Absent,
}

/// The pairing state: at most one held fix and one waiting velocity.
#[derive(Debug, Clone)]
pub struct FixPairing<F, V> {
    fix: Option<F>,
    velocity: Option<V>,
    stream: VelocityStream,
    unpaired_velocities: u64,
}

impl<F, V> Default for FixPairing<F, V> {
    fn default() -> Self {
        Self {
            fix: None,
            velocity: None,
            stream: VelocityStream::Unknown,
            unpaired_velocities: 0,
        }
    }
}

fn same_stamp(a_s: f64, b_s: f64) -> bool {
    (a_s - b_s).abs() <= PAIRING_TOLERANCE_S
}

impl<F: Stamped, V: Stamped> FixPairing<F, V> {
    /// Velocities dropped without a fix so far.
    pub fn unpaired_velocities(&self) -> u64 {
        self.unpaired_velocities
    }

    /// The held fix leaves without a velocity.
    fn release_alone(&mut self) -> Option<Released<F, V>> {
        let fix = self.fix.take()?;
        if self.stream == VelocityStream::Unknown {
            self.stream = VelocityStream::Absent;
        }
        Some(Released {
            fix,
            velocity: None,
        })
    }

    /// A fix arrives: what goes to the engine now.
    pub fn on_fix(&mut self, fix: F) -> Vec<Released<F, V>> {
        let mut out = Vec::new();
        if let Some(v) = self.velocity.take() {
            if same_stamp(v.t_s(), fix.t_s()) {
                out.extend(self.release_alone());
                out.push(Released {
                    fix,
                    velocity: Some(v),
                });
                return out;
            }
            if v.t_s() < fix.t_s() {
                self.unpaired_velocities += 1;
            } else {
                // A later fix's velocity (out of order): it keeps waiting.
                self.velocity = Some(v);
            }
        }
        out.extend(self.release_alone());
        if self.stream == VelocityStream::Absent {
            out.push(Released {
                fix,
                velocity: None,
            });
        } else {
            self.fix = Some(fix);
        }
        out
    }

    /// A velocity arrives: what goes to the engine now.
    pub fn on_velocity(&mut self, velocity: V) -> Vec<Released<F, V>> {
        self.stream = VelocityStream::Present;
        let mut out = Vec::new();
        if let Some(held) = self.fix.take() {
            if same_stamp(held.t_s(), velocity.t_s()) {
                out.push(Released {
                    fix: held,
                    velocity: Some(velocity),
                });
                return out;
            }
            if velocity.t_s() < held.t_s() {
                // Its fix went on already (or never came).
                self.unpaired_velocities += 1;
                self.fix = Some(held);
                return out;
            }
            // A later velocity: the held fix's own will not come.
            self.fix = Some(held);
            out.extend(self.release_alone());
        }
        if self.velocity.replace(velocity).is_some() {
            self.unpaired_velocities += 1;
        }
        out
    }

    /// The IMU time reached `t_s`: a fix or velocity that waited [`PAIRING_WAIT_S`] leaves.
    pub fn on_time(&mut self, t_s: f64) -> Vec<Released<F, V>> {
        if self
            .velocity
            .as_ref()
            .is_some_and(|v| t_s > v.t_s() + PAIRING_WAIT_S)
        {
            self.velocity = None;
            self.unpaired_velocities += 1;
        }
        if self
            .fix
            .as_ref()
            .is_some_and(|held| t_s > held.t_s() + PAIRING_WAIT_S)
        {
            return self.release_alone().into_iter().collect();
        }
        Vec::new()
    }

    /// Drops what waits (the filter was reset); a waiting velocity counts as unpaired.
    /// What was learnt of the velocity stream is kept.
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

    /// A fix or a velocity: its stamp is all the pairing looks at.
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct At(f64);

    impl Stamped for At {
        fn t_s(&self) -> f64 {
            self.0
        }
    }

    type Pairing = FixPairing<At, At>;

    /// (fix stamp, velocity stamp) of what was released.
    fn stamps(r: &[Released<At, At>]) -> Vec<(f64, Option<f64>)> {
        r.iter()
            .map(|r| (r.fix.0, r.velocity.map(|v| v.0)))
            .collect()
    }

    #[test]
    fn without_velocities_only_the_first_fix_waits() {
        let mut p = Pairing::default();
        assert!(p.on_fix(At(1.0)).is_empty(), "a velocity may follow");
        assert_eq!(stamps(&p.on_fix(At(2.0))), vec![(1.0, None), (2.0, None)]);
        assert_eq!(stamps(&p.on_fix(At(3.0))), vec![(3.0, None)], "at once");
        assert!(p.on_time(10.0).is_empty());
        assert_eq!(p.unpaired_velocities(), 0);
        // The wait decides as well as the next fix does.
        let mut p = Pairing::default();
        assert!(p.on_fix(At(1.0)).is_empty());
        assert!(p.on_time(1.0 + PAIRING_WAIT_S).is_empty(), "not yet");
        assert_eq!(stamps(&p.on_time(1.25)), vec![(1.0, None)]);
        assert_eq!(stamps(&p.on_fix(At(2.0))), vec![(2.0, None)]);
    }

    #[test]
    fn the_first_fix_pairs_in_either_arrival_order() {
        let (fix, velocity) = (At(1.0), At(1.0005));
        let mut fix_first = Pairing::default();
        assert!(fix_first.on_fix(fix).is_empty());
        let a = fix_first.on_velocity(velocity);
        let mut velocity_first = Pairing::default();
        assert!(velocity_first.on_velocity(velocity).is_empty());
        let b = velocity_first.on_fix(fix);
        assert_eq!(stamps(&a), vec![(1.0, Some(1.0005))]);
        assert_eq!(a, b);
        assert_eq!(fix_first.unpaired_velocities(), 0);
        assert_eq!(velocity_first.unpaired_velocities(), 0);
    }

    #[test]
    fn a_stream_pairs_every_fix_whatever_the_order_of_each_pair() {
        // Each epoch's two messages in an order from the bits of `orders`.
        for orders in 0u32..16 {
            let mut p = Pairing::default();
            let mut released = Vec::new();
            for k in 0..4 {
                let t = f64::from(k);
                if orders & (1 << k) == 0 {
                    released.extend(p.on_fix(At(t)));
                    released.extend(p.on_velocity(At(t)));
                } else {
                    released.extend(p.on_velocity(At(t)));
                    released.extend(p.on_fix(At(t)));
                }
                released.extend(p.on_time(t + 0.01));
            }
            let expected: Vec<_> = (0..4).map(|k| (f64::from(k), Some(f64::from(k)))).collect();
            assert_eq!(stamps(&released), expected, "orders {orders:04b}");
            assert_eq!(p.unpaired_velocities(), 0);
        }
    }

    #[test]
    fn velocity_after_or_before_its_fix_pairs_within_a_millisecond() {
        let mut p = Pairing::default();
        assert!(p.on_velocity(At(1.0)).is_empty());
        assert_eq!(
            stamps(&p.on_fix(At(1.0005))),
            vec![(1.0005, Some(1.0))],
            "velocity first"
        );
        assert!(p.on_fix(At(2.0)).is_empty(), "held for its velocity");
        assert_eq!(
            stamps(&p.on_velocity(At(2.0009))),
            vec![(2.0, Some(2.0009))],
            "fix first"
        );
        assert_eq!(p.unpaired_velocities(), 0);
    }

    #[test]
    fn unpaired_and_out_of_order_velocities_are_counted_and_dropped() {
        let mut p = Pairing::default();
        // A velocity whose fix never comes: the next fix drops it.
        assert!(p.on_velocity(At(1.0)).is_empty());
        assert!(p.on_fix(At(2.0)).is_empty());
        assert_eq!(p.unpaired_velocities(), 1);
        // 2 ms apart is not the same stamp; a velocity older than the held fix is stale.
        assert!(p.on_velocity(At(1.998)).is_empty());
        assert_eq!(p.unpaired_velocities(), 2);
        // The fix's velocity never comes: the next fix releases it alone.
        assert_eq!(stamps(&p.on_fix(At(3.0))), vec![(2.0, None)]);
        // A later velocity releases the held fix alone and waits; IMU time drops it.
        assert_eq!(stamps(&p.on_velocity(At(4.0))), vec![(3.0, None)]);
        assert!(p.on_time(4.0 + PAIRING_WAIT_S).is_empty(), "not yet");
        assert!(p.on_time(4.3).is_empty());
        assert_eq!(p.unpaired_velocities(), 3);
        // A held fix leaves alone after the wait; with velocities seen, fixes still wait.
        assert!(p.on_fix(At(5.0)).is_empty());
        assert!(p.on_time(5.1).is_empty());
        assert_eq!(stamps(&p.on_time(5.25)), vec![(5.0, None)]);
        assert!(p.on_fix(At(5.5)).is_empty(), "held");
        assert_eq!(stamps(&p.on_time(5.75)), vec![(5.5, None)]);
        // Fixes out of order: a later fix's velocity keeps waiting for it.
        assert!(p.on_velocity(At(7.0)).is_empty());
        assert!(p.on_fix(At(6.0)).is_empty(), "held");
        assert_eq!(
            stamps(&p.on_fix(At(7.0))),
            vec![(6.0, None), (7.0, Some(7.0))]
        );
        // A reset drops the waiting velocity.
        assert!(p.on_velocity(At(8.0)).is_empty());
        p.clear();
        assert!(p.on_time(100.0).is_empty());
        assert_eq!(p.unpaired_velocities(), 4);
    }

    #[test]
    fn a_late_velocity_stream_turns_holding_back_on() {
        let mut p = Pairing::default();
        assert!(p.on_fix(At(1.0)).is_empty());
        assert_eq!(stamps(&p.on_fix(At(2.0))), vec![(1.0, None), (2.0, None)]);
        // Its fix went on alone: this velocity cannot pair; later fixes wait again.
        assert!(p.on_velocity(At(2.0)).is_empty());
        assert!(p.on_fix(At(3.0)).is_empty());
        assert_eq!(p.unpaired_velocities(), 1);
        assert_eq!(stamps(&p.on_velocity(At(3.0))), vec![(3.0, Some(3.0))]);
    }
}
