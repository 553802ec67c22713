//! A smooth on/off window for trajectory segments: rises from 0 to 1 over a ramp, holds 1,
//! and falls back to 0 over a ramp at the end, with the quintic smoothstep
//! S(x) = 10x³ − 15x⁴ + 6x⁵ on each ramp.
//!
//! Math note: S(0) = 0, S(1) = 1 and S', S'' vanish at both ends, so the window is C² in
//! time. A segment's acceleration, yaw rate or climb angle is its plateau value times the
//! window, hence C²; the specific force and angular rate derived from them are C¹, which
//! keeps the true IMU well-behaved for trapezoidal and coning/sculling algorithms.

/// The window of one segment of length `duration_s` with ramps of `ramp_s` (≤ half the
/// duration) at each end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothWindow {
    duration_s: f64,
    ramp_s: f64,
}

/// The window's value, rate and running integral at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowValue {
    /// w(τ), between 0 and 1.
    pub value: f64,
    /// dw/dτ (1/s).
    pub rate_per_s: f64,
    /// ∫₀^τ w (s).
    pub integral_s: f64,
}

impl SmoothWindow {
    /// A window of `duration_s` whose ramps last `min(ramp_s, duration_s / 2)`. Both inputs
    /// are expected positive and finite (checked by the trajectory builder).
    pub fn new(duration_s: f64, ramp_s: f64) -> Self {
        Self {
            duration_s,
            ramp_s: ramp_s.min(0.5 * duration_s),
        }
    }

    /// ∫₀^T w, the area under the whole window (s): T − r.
    pub fn total_integral_s(&self) -> f64 {
        self.duration_s - self.ramp_s
    }

    /// Value, rate and integral at local time `tau_s`, clamped to [0, T].
    pub fn at(&self, tau_s: f64) -> WindowValue {
        let t = tau_s.clamp(0.0, self.duration_s);
        let r = self.ramp_s;
        if t < r {
            let x = t / r;
            WindowValue {
                value: smoothstep(x),
                rate_per_s: smoothstep_rate(x) / r,
                integral_s: r * smoothstep_integral(x),
            }
        } else if t <= self.duration_s - r {
            WindowValue {
                value: 1.0,
                rate_per_s: 0.0,
                integral_s: 0.5 * r + (t - r),
            }
        } else {
            let y = (self.duration_s - t) / r;
            WindowValue {
                value: smoothstep(y),
                rate_per_s: -smoothstep_rate(y) / r,
                integral_s: self.total_integral_s() - r * smoothstep_integral(y),
            }
        }
    }
}

/// S(x) = x³ (10 − 15x + 6x²).
fn smoothstep(x: f64) -> f64 {
    x * x * x * (10.0 + x * (-15.0 + 6.0 * x))
}

/// S'(x) = 30 x² (1 − x)².
fn smoothstep_rate(x: f64) -> f64 {
    30.0 * x * x * (1.0 - x) * (1.0 - x)
}

/// ∫₀^x S = x⁴ (5/2 − 3x + x²); equals ½ at x = 1.
fn smoothstep_integral(x: f64) -> f64 {
    x * x * x * x * (2.5 + x * (-3.0 + x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_plateau_and_continuity() {
        let w = SmoothWindow::new(10.0, 2.0);
        assert_eq!(w.at(0.0).value, 0.0);
        assert_eq!(w.at(10.0).value, 0.0);
        assert_eq!(w.at(5.0).value, 1.0);
        assert!((w.at(10.0).integral_s - 8.0).abs() < 1e-12);
        for t in [2.0, 8.0] {
            let a = w.at(t - 1e-9);
            let b = w.at(t + 1e-9);
            assert!((a.value - b.value).abs() < 1e-8);
            assert!((a.rate_per_s - b.rate_per_s).abs() < 1e-7);
            assert!((a.integral_s - b.integral_s).abs() < 1e-8);
        }
    }

    #[test]
    fn rate_and_integral_match_finite_differences_and_quadrature() {
        let w = SmoothWindow::new(7.0, 2.5);
        let h = 1e-5;
        let mut quad = 0.0;
        let n = 70_000;
        let dt = 7.0 / n as f64;
        for k in 0..n {
            let t = (k as f64 + 0.5) * dt;
            quad += w.at(t).value * dt;
            if k % 997 == 0 && t > h && t < 7.0 - h {
                let fd = (w.at(t + h).value - w.at(t - h).value) / (2.0 * h);
                assert!((fd - w.at(t).rate_per_s).abs() < 1e-7, "t={t}");
            }
        }
        assert!((quad - w.at(7.0).integral_s).abs() < 1e-8);
        assert!((w.at(3.3).integral_s - (0.5 * 2.5 + 0.8)).abs() < 1e-12);
    }

    #[test]
    fn short_segment_ramps_take_half_each() {
        let w = SmoothWindow::new(1.0, 5.0);
        assert!((w.total_integral_s() - 0.5).abs() < 1e-15);
        assert!((w.at(0.5).value - 1.0).abs() < 1e-15);
    }
}
