//! The recent receiver fixes of a loosely-coupled start without a receiver velocity: a
//! straight line of position against time fitted to the fixes of the last
//! [`MAX_BASELINE_S`], weighted by their covariances, gives the velocity (and its
//! covariance) and the position at the newest fix.
//!
//! Choices:
//! - Per ENU axis a weighted least-squares line; a fix whose residual exceeds
//!   [`OUTLIER_SIGMA`] of its own σ on any axis is dropped (the worst first) and the line
//!   fitted again, while three fixes remain: one outlier among the fixes of a start would
//!   otherwise set its heading (a 30 m outlier over a 5 s baseline turns the course by
//!   tens of degrees).
//! - The line's slope is the velocity at the fixes' weighted mean time; in a turn the
//!   course has turned on since, by the rate about the vertical times that lag, and in an
//!   acceleration the speed has changed, both of which the caller applies.
//! - The line's value at the newest fix lags an accelerating platform too: for a constant
//!   acceleration a it falls short by a·`quadratic_lag_s2` (0.5 m for 0.5 m/s² over five
//!   fixes a second apart, forty times the σ of an RTK fix), which the caller corrects
//!   with the acceleration it knows.

use std::collections::VecDeque;

use nalgebra::{Matrix2, Vector3};

use crate::config::Config;
use crate::earth::{self, Llh};

use super::update::{position_covariance, GnssFix};

/// Longest span of fixes fitted (s). Choice: 5 s, a baseline of 25 m at a walking 5 m/s
/// that turns a 1.5 m fix error into a course error of a few degrees, short enough that
/// a turn's course has not moved far (the lag is corrected, see above).
pub const MAX_BASELINE_S: f64 = 5.0;
/// Residual (in σ of its fix) beyond which a fix is dropped from the fit.
pub const OUTLIER_SIGMA: f64 = 4.0;
/// The median of χ²(1).
const CHI2_1_MEDIAN: f64 = 0.454_936;

/// A line fitted to the recent fixes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackFit {
    /// Time of the newest fix (s).
    pub t_s: f64,
    /// The line's position at `t_s`.
    pub position: Llh,
    /// Mean variance of that position over the axes (m²).
    pub position_var_m2: f64,
    /// The line's velocity (ENU, m/s) and the covariance of its horizontal part.
    pub v_enu_mps: Vector3<f64>,
    pub cov_v_h_m2_s2: Matrix2<f64>,
    /// `t_s` less the fixes' weighted mean time: how long ago the velocity held (s).
    pub lag_s: f64,
    /// How far the line's position at `t_s` falls short of a platform accelerating at
    /// 1 m/s² along its motion (m per m/s², i.e. s²): ½ (0 − L(0)), L the weighted line
    /// through the squared times (since the newest) of the fixes fitted.
    pub quadratic_lag_s2: f64,
}

/// The fixes of the last [`MAX_BASELINE_S`], oldest first.
#[derive(Debug, Clone, Default)]
pub struct FixTrack {
    fixes: VecDeque<GnssFix>,
}

impl FixTrack {
    /// Adds the newest fix and forgets those older than the baseline.
    pub fn push(&mut self, fix: &GnssFix) {
        self.fixes.push_back(fix.clone());
        while self
            .fixes
            .front()
            .is_some_and(|old| fix.t_s - old.t_s > MAX_BASELINE_S)
        {
            self.fixes.pop_front();
        }
    }

    /// The line through the fixes (see the module documentation); None with fewer than
    /// two fixes at different times.
    pub fn fit(&self, config: &Config) -> Option<TrackFit> {
        let newest = self.fixes.back()?;
        // (time since the newest, ENU offset from the newest, σ per axis).
        let mut points: Vec<(f64, Vector3<f64>, Vector3<f64>)> = self
            .fixes
            .iter()
            .map(|f| {
                let cov = position_covariance(f, config);
                (
                    f.t_s - newest.t_s,
                    earth::llh_to_enu(&f.position, &newest.position),
                    cov.diagonal().map(f64::sqrt),
                )
            })
            .collect();
        loop {
            let line = Line::fit(&points)?;
            let optimism = line.optimism(&points);
            let worst = points
                .iter()
                .enumerate()
                .map(|(i, (t, x, sigma))| (i, line.residual(*t, x).component_div(sigma).amax()))
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((i, r)) if r > OUTLIER_SIGMA * optimism.sqrt() && points.len() > 3 => {
                    points.remove(i);
                }
                _ => return Some(line.at(newest, optimism)),
            }
        }
    }
}

/// Per-axis weighted lines x = a + b t.
struct Line {
    a: Vector3<f64>,
    b: Vector3<f64>,
    var_a: Vector3<f64>,
    var_b: Vector3<f64>,
    mean_t: f64,
    /// The weighted line through t² (first axis's weights) at t = 0.
    t2_line_at_0: f64,
}

impl Line {
    fn fit(points: &[(f64, Vector3<f64>, Vector3<f64>)]) -> Option<Self> {
        let mut a = Vector3::zeros();
        let mut b = Vector3::zeros();
        let mut var_a = Vector3::zeros();
        let mut var_b = Vector3::zeros();
        let mut mean_t = 0.0;
        let mut t2_line_at_0 = 0.0;
        for axis in 0..3 {
            let (mut sw, mut swt, mut swtt, mut swx, mut swtx) = (0.0, 0.0, 0.0, 0.0, 0.0);
            let mut swttt = 0.0;
            for (t, x, sigma) in points {
                let w = 1.0 / (sigma[axis] * sigma[axis]);
                sw += w;
                swt += w * t;
                swtt += w * t * t;
                swttt += w * t * t * t;
                swx += w * x[axis];
                swtx += w * t * x[axis];
            }
            let det = sw * swtt - swt * swt;
            if !(det > 0.0 && det.is_finite()) {
                return None;
            }
            a[axis] = (swtt * swx - swt * swtx) / det;
            b[axis] = (sw * swtx - swt * swx) / det;
            var_a[axis] = swtt / det;
            var_b[axis] = sw / det;
            if axis == 0 {
                mean_t = swt / sw;
                t2_line_at_0 = (swtt * swtt - swt * swttt) / det;
            }
        }
        Some(Self {
            a,
            b,
            var_a,
            var_b,
            mean_t,
            t2_line_at_0,
        })
    }

    fn residual(&self, t: f64, x: &Vector3<f64>) -> Vector3<f64> {
        x - self.a - self.b * t
    }

    /// How much the fixes scatter about the line beyond what they claim: the factor on
    /// their variances (at least 1) that their horizontal residuals call for.
    ///
    /// Choice: the median of the squared normalized residuals over the median of χ²(1)
    /// (0.455), times n/(n − 2) for the two parameters the line took from n fixes (a
    /// robust reduced χ², which one outlier does not inflate); at least 1, so honest
    /// claims are kept, and 1 below three fixes. A receiver claiming a fifth of its error
    /// otherwise made a start at rest see motion and take a heading 80° off with a σ of 5°
    /// (tests/fix_consistency.rs).
    fn optimism(&self, points: &[(f64, Vector3<f64>, Vector3<f64>)]) -> f64 {
        let n = points.len();
        if n < 3 {
            return 1.0;
        }
        let mut squares: Vec<f64> = points
            .iter()
            .flat_map(|(t, x, sigma)| {
                let r = self.residual(*t, x).component_div(sigma);
                [r.x * r.x, r.y * r.y]
            })
            .collect();
        squares.sort_by(f64::total_cmp);
        let m = squares.len();
        let median = 0.5 * (squares[(m - 1) / 2] + squares[m / 2]);
        let factor = median / CHI2_1_MEDIAN * n as f64 / (n - 2) as f64;
        if factor.is_finite() {
            factor.max(1.0)
        } else {
            1.0
        }
    }

    /// The fit at the newest fix, its covariances scaled by `optimism`.
    fn at(&self, newest: &GnssFix, optimism: f64) -> TrackFit {
        let var_a = self.var_a * optimism;
        let var_b = self.var_b * optimism;
        TrackFit {
            t_s: newest.t_s,
            position: earth::enu_to_llh(&self.a, &newest.position).unwrap_or(newest.position),
            position_var_m2: var_a.sum() / 3.0,
            v_enu_mps: self.b,
            cov_v_h_m2_s2: Matrix2::new(var_b[0], 0.0, 0.0, var_b[1]),
            lag_s: -self.mean_t,
            quadratic_lag_s2: -0.5 * self.t2_line_at_0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fix(t_s: f64, east_m: f64) -> GnssFix {
        let origin = Llh::from_degrees(39.1, 117.2, 20.0);
        GnssFix {
            t_s,
            position: earth::enu_to_llh(&Vector3::new(east_m, 0.0, 0.0), &origin).unwrap(),
            position_covariance_enu_m2: Some(nalgebra::Matrix3::identity() * 0.25),
            velocity_enu_mps: None,
            velocity_covariance_enu_m2_s2: None,
        }
    }

    #[test]
    fn the_lags_of_an_accelerating_track_are_known() {
        // 0.5 m/s² from rest, fixes a second apart: the line's slope is the speed at the
        // mean time, 2 s back, and its value at the newest fix is a·quadratic_lag short.
        let config = Config::default();
        let mut track = FixTrack::default();
        let a = 0.5;
        for k in 0..5 {
            let t = f64::from(k);
            track.push(&fix(t, 0.5 * a * t * t));
        }
        let fit = track.fit(&config).unwrap();
        assert!((fit.lag_s - 2.0).abs() < 1e-9);
        assert!(
            (fit.v_enu_mps[0] - a * (4.0 - fit.lag_s)).abs() < 1e-9,
            "{fit:?}"
        );
        let short_m = earth::llh_to_enu(&fit.position, &fix(4.0, 0.5 * a * 16.0).position)[0];
        assert!((fit.quadratic_lag_s2 - 1.0).abs() < 1e-9, "{fit:?}");
        assert!(
            (short_m + a * fit.quadratic_lag_s2).abs() < 1e-6,
            "{short_m}"
        );
    }

    #[test]
    fn a_line_through_the_fixes_without_the_outlier() {
        let config = Config::default();
        let mut track = FixTrack::default();
        for k in 0..6 {
            let t = f64::from(k);
            track.push(&fix(t, 10.0 * t));
        }
        let clean = track.fit(&config).unwrap();
        assert!((clean.v_enu_mps[0] - 10.0).abs() < 1e-3);
        assert!(clean.v_enu_mps[1].abs() < 1e-3);
        assert!((clean.lag_s - 2.5).abs() < 1e-9);
        // The newest fix 30 m off to the north: dropped, the same line.
        let mut track = FixTrack::default();
        for k in 0..6 {
            let t = f64::from(k);
            let mut f = fix(t, 10.0 * t);
            if k == 5 {
                let origin = f.position;
                f.position = earth::enu_to_llh(&Vector3::new(0.0, 30.0, 0.0), &origin).unwrap();
            }
            track.push(&f);
        }
        let fit = track.fit(&config).unwrap();
        assert!((fit.v_enu_mps[0] - 10.0).abs() < 1e-3, "{fit:?}");
        assert!(fit.v_enu_mps[1].abs() < 1e-3, "{fit:?}");
        // Older than the baseline (5 s) is forgotten.
        track.push(&fix(20.0, 200.0));
        assert!(track.fit(&config).is_none());
    }
}
