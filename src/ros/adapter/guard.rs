//! What may be published: a solution whose every number is finite and whose variances
//! are not negative, and messages likewise. The node and `gnss_ins replay` drop and count
//! what this refuses, instead of handing out a NaN or a σ that is not a number.
//!
//! Choice: a negative variance is as unusable as a NaN (its σ is not a number, and a
//! consumer inverting the covariance would be misled), so it is refused too.

use crate::engine::Solution;
use crate::ros::convert::seconds_to_time;
use crate::ros::msg::{NavSatFix, Odometry};

/// Why a solution was not published.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Unpublishable {
    /// A value, or its time, is not finite.
    NonFinite,
    /// A covariance has a negative variance on its diagonal (the filter diverged).
    NegativeVariance,
}

/// Whether `solution` can be published: every number finite, its time a ROS stamp, every
/// variance (the covariance's diagonal) non-negative.
pub(super) fn judge(solution: &Solution) -> Result<(), Unpublishable> {
    let s = solution;
    let vectors = [s.gyro_bias_rad_s, s.accel_bias_m_s2, s.angular_rate_b_rad_s];
    let finite = s.nav.is_finite()
        && seconds_to_time(s.nav.t_s).is_ok()
        && vectors.iter().all(|v| all_finite(v.as_slice()))
        && s.clock_bias_m.is_finite()
        && s.clock_drift_mps.is_finite()
        && all_finite(s.covariance.as_slice());
    if !finite {
        return Err(Unpublishable::NonFinite);
    }
    if s.covariance.diagonal().iter().any(|v| *v < 0.0) {
        return Err(Unpublishable::NegativeVariance);
    }
    Ok(())
}

/// True when none of `values` is NaN or infinite.
///
/// Choice: integer arithmetic on the bits, without stopping at the first bad value, so
/// the compiler turns it into vector instructions for the 400 covariance entries of each
/// solution (where `all(is_finite)` tests them one by one). The exponent bits are all
/// ones exactly for ±∞ and NaN; adding the exponent's lowest bit to them then carries
/// into bit 63, which the OR over all values keeps.
fn all_finite(values: &[f64]) -> bool {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    const EXPONENT_LSB: u64 = 1 << 52;
    let carries = values.iter().fold(0, |seen, v| {
        seen | ((v.to_bits() & EXPONENT) + EXPONENT_LSB)
    });
    carries >> 63 == 0
}

/// Whether the messages of a judged solution can be published: every number finite,
/// every variance (the covariance diagonals) non-negative.
pub(super) fn judge_messages(odometry: &Odometry, fix: &NavSatFix) -> Result<(), Unpublishable> {
    let (pose, twist) = (&odometry.pose, &odometry.twist);
    let (p, q, v, w) = (
        &pose.pose.position,
        &pose.pose.orientation,
        &twist.twist.linear,
        &twist.twist.angular,
    );
    let values = [
        p.x,
        p.y,
        p.z,
        q.x,
        q.y,
        q.z,
        q.w,
        v.x,
        v.y,
        v.z,
        w.x,
        w.y,
        w.z,
        fix.latitude,
        fix.longitude,
        fix.altitude,
    ];
    let finite = all_finite(&values)
        && all_finite(&pose.covariance)
        && all_finite(&twist.covariance)
        && all_finite(&fix.position_covariance);
    if !finite {
        return Err(Unpublishable::NonFinite);
    }
    let negative = (0..6).any(|k| pose.covariance[7 * k] < 0.0 || twist.covariance[7 * k] < 0.0)
        || (0..3).any(|k| fix.position_covariance[4 * k] < 0.0);
    if negative {
        return Err(Unpublishable::NegativeVariance);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;
    use crate::earth::Llh;
    use crate::ins::error_state::StateMatrix;
    use crate::ins::NavState;

    fn solution() -> Solution {
        Solution {
            nav: NavState {
                t_s: 100.0,
                p: Llh::from_degrees(39.1, 117.2, 10.0),
                v_n: Vector3::new(1.0, 2.0, 0.0),
                q_nb: UnitQuaternion::identity(),
            },
            covariance: StateMatrix::identity(),
            gyro_bias_rad_s: Vector3::zeros(),
            accel_bias_m_s2: Vector3::zeros(),
            clock_bias_m: 3.0,
            clock_drift_mps: 0.1,
            angular_rate_b_rad_s: Vector3::zeros(),
        }
    }

    #[test]
    fn a_solution_with_a_non_finite_number_or_a_negative_variance_is_refused() {
        assert_eq!(judge(&solution()), Ok(()));
        let mut s = solution();
        s.covariance[(19, 3)] = f64::NAN;
        assert_eq!(judge(&s), Err(Unpublishable::NonFinite), "anywhere in P");
        let mut s = solution();
        s.clock_drift_mps = f64::INFINITY;
        assert_eq!(judge(&s), Err(Unpublishable::NonFinite));
        let mut s = solution();
        s.nav.t_s = 1e12;
        assert_eq!(judge(&s), Err(Unpublishable::NonFinite), "no ROS stamp");
        let mut s = solution();
        s.covariance[(7, 7)] = -1e-9;
        assert_eq!(judge(&s), Err(Unpublishable::NegativeVariance));
        let mut s = solution();
        s.covariance[(7, 6)] = -5.0;
        assert_eq!(
            judge(&s),
            Ok(()),
            "a negative covariance off the diagonal is no variance"
        );
    }

    #[test]
    fn all_finite_finds_every_kind_of_non_finite_value_anywhere() {
        let finite = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
        ];
        assert!(all_finite(&finite));
        assert!(all_finite(&[]));
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -f64::NAN] {
            for at in 0..finite.len() {
                let mut values = finite;
                values[at] = bad;
                assert!(!all_finite(&values), "{bad} at {at}");
            }
        }
    }
}
