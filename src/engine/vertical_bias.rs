//! The gyro bias about the vertical, measured in motion against the GNSS course: a
//! loosely-coupled restart after a divergence waits for it
//! ([`super::initializer::Initializer::after_divergence`]).
//!
//! Choice: measured, not assumed. With the 10× prior of
//! [`super::initializer::DIVERGED_GYRO_BIAS_SIGMA_FACTOR`] about the vertical too
//! (5,000 °/h for a consumer MEMS, 1.4 °/s) the heading of a filter started at once drifts
//! by tens of degrees on a straight road, where position fixes without a velocity do not
//! see it: after a consumer gyro's biases jumped tenfold the restarted filter (loosely
//! coupled, tests/divergence_monitor.rs) was 40° off in heading 35 s after its start (σ
//! 27°), beyond the linear range of an error-state filter, and its correction at the next
//! acceleration left roll, pitch and the accelerometer biases over-confident (2° against a
//! σ of 0.22°, 40 mg against 4 mg): NEES up to 276. With the vertical bias known to the
//! class's σ the same restart stayed at 21. So the restart starts like a first start in
//! motion, with the vertical bias no worse known than the class's turn-on σ. The car must
//! drive for it (about 30 s at 12 m/s) and publishes nothing meanwhile.
//!
//! Math note: the course rate is the gyro's rate about the vertical less its bias, taking
//! the body's forward axis along the course as the alignment in motion does; each end of
//! the span has the course's own variance and the side-slip's. A course carried forward
//! by its lag with the raw rate holds the bias times the lag; hence
//! b = (gyro turn − course turn) / (span − change of lag), with the variance of both ends'
//! courses over the same span squared.

use crate::ins::mechanization::wrap_pi;

/// One course of the moving platform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Course {
    pub t_s: f64,
    /// ENU yaw of the velocity (rad) and its variance, side-slip included (rad²).
    pub yaw_rad: f64,
    pub var_rad2: f64,
    /// How long the velocity was carried forward with the raw gyro rate (s).
    pub lag_s: f64,
}

/// The bias about the vertical (rad/s) and its 1-sigma.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalBias {
    pub bias_rad_s: f64,
    pub sigma_rad_s: f64,
}

/// The span of consecutive courses so far.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VerticalBiasSpan {
    first: Option<Course>,
    last: Option<Course>,
    /// Change of the course since the first (unwrapped) and the gyro's turn about the
    /// vertical, earth rate removed, over the same time (rad).
    course_turn_rad: f64,
    gyro_turn_rad: f64,
}

impl VerticalBiasSpan {
    /// Starts again (not moving).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Adds a course, with the gyro's mean rate about the vertical (earth rate removed)
    /// over the time since the last one, which may be at most `max_gap_s` ago (else a new
    /// span begins); the bias once its 1-sigma is at most `max_sigma_rad_s`.
    pub fn push(
        &mut self,
        course: Course,
        rate_up_rad_s: f64,
        max_gap_s: f64,
        max_sigma_rad_s: f64,
    ) -> Option<VerticalBias> {
        match (self.first, self.last) {
            (Some(first), Some(last))
                if course.t_s > last.t_s && course.t_s - last.t_s <= max_gap_s =>
            {
                self.course_turn_rad += wrap_pi(course.yaw_rad - last.yaw_rad);
                self.gyro_turn_rad += rate_up_rad_s * (course.t_s - last.t_s);
                self.last = Some(course);
                let span_s = (course.t_s - first.t_s) - (course.lag_s - first.lag_s);
                if span_s <= 0.0 {
                    return None;
                }
                let sigma_rad_s = (first.var_rad2 + course.var_rad2).sqrt() / span_s;
                return (sigma_rad_s <= max_sigma_rad_s).then(|| VerticalBias {
                    bias_rad_s: (self.gyro_turn_rad - self.course_turn_rad) / span_s,
                    sigma_rad_s,
                });
            }
            // A stamp not after the last: ignored.
            (Some(_), Some(last)) if course.t_s <= last.t_s => return None,
            _ => {}
        }
        *self = Self {
            first: Some(course),
            last: Some(course),
            ..Self::default()
        };
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn course(t_s: f64, yaw_rad: f64) -> Course {
        Course {
            t_s,
            yaw_rad,
            var_rad2: 0.05f64.powi(2),
            lag_s: 0.0,
        }
    }

    #[test]
    fn a_gyro_that_turns_faster_than_the_course_gives_its_bias_once_the_span_is_long() {
        // The course turns at 0.02 rad/s, the gyro reads 0.03 rad/s: bias 0.01 rad/s.
        let mut span = VerticalBiasSpan::default();
        let mut found = None;
        for k in 0..=60 {
            let t_s = f64::from(k);
            found = span.push(course(t_s, 0.02 * t_s), 0.03, 1.1, 0.005);
            if found.is_some() {
                break;
            }
        }
        let bias = found.expect("measured within 60 s");
        assert!((bias.bias_rad_s - 0.01).abs() < 1e-12, "{bias:?}");
        // σ = √2 · 0.05 / span ≤ 0.005 first at a span of 15 s.
        assert!((bias.sigma_rad_s - 0.05 * 2f64.sqrt() / 15.0).abs() < 1e-12);
    }

    #[test]
    fn a_gap_or_a_stamp_going_back_starts_again_or_is_ignored() {
        let mut span = VerticalBiasSpan::default();
        for k in 0..10 {
            span.push(course(f64::from(k), 0.0), 0.0, 1.1, 1.0);
        }
        assert_eq!(span.push(course(5.0, 0.0), 0.0, 1.1, 1.0), None);
        // A 3 s gap: a new span, which has no length yet.
        assert_eq!(span.push(course(12.0, 0.0), 0.0, 1.1, 1.0), None);
        let bias = span.push(course(13.0, 0.0), 0.0, 1.1, 1.0).unwrap();
        assert!((bias.sigma_rad_s - 0.05 * 2f64.sqrt()).abs() < 1e-12);
    }
}
