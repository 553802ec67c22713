//! Scoring against a reference trajectory: position, velocity and attitude errors, their
//! RMSE, and the NEES of the filter's own covariance. Pure: the caller feeds solutions and
//! truth samples in time order.

use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};

use crate::adaptive::mahalanobis::chi_square_quantile;
use crate::earth::{self, Llh};
use crate::engine::Solution;
use crate::ins::error_state::{DP, DV, N, PHI};
use crate::ins::mechanization::wrap_pi;
use crate::ins::NavState;

/// One reference sample. Velocity and attitude are optional (a GNSS reference may have
/// neither).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthSample {
    pub t_s: f64,
    pub p: Llh,
    pub v_n: Option<Vector3<f64>>,
    pub q_nb: Option<UnitQuaternion<f64>>,
}

impl From<&NavState> for TruthSample {
    /// A full reference (position, velocity and attitude) from a true state, such as the
    /// simulator's.
    fn from(nav: &NavState) -> Self {
        Self {
            t_s: nav.t_s,
            p: nav.p,
            v_n: Some(nav.v_n),
            q_nb: Some(nav.q_nb),
        }
    }
}

/// A reference trajectory, interpolated linearly in time (attitude by slerp).
#[derive(Debug, Clone, Default)]
pub struct TruthTrack {
    samples: Vec<TruthSample>,
    /// Samples further apart than this are not interpolated across (s).
    max_gap_s: f64,
}

impl TruthTrack {
    /// A track from samples (sorted here; non-finite ones dropped).
    pub fn new(mut samples: Vec<TruthSample>, max_gap_s: f64) -> Self {
        samples.retain(|s| s.t_s.is_finite() && s.p.is_finite());
        samples.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        Self { samples, max_gap_s }
    }

    pub fn len(&self) -> usize {
        self.samples.len()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The reference at `t_s`, or None outside the track or across a gap.
    pub fn at(&self, t_s: f64) -> Option<TruthSample> {
        let i = self.samples.partition_point(|s| s.t_s <= t_s);
        let a = self.samples.get(i.checked_sub(1)?)?;
        if a.t_s == t_s {
            return Some(*a);
        }
        let b = self.samples.get(i)?;
        let span = b.t_s - a.t_s;
        if span > self.max_gap_s || span <= 0.0 {
            return None;
        }
        let w = (t_s - a.t_s) / span;
        // Interpolate the position in the ENU frame of `a` (exact enough over a gap of
        // a second at any speed a vehicle reaches).
        let d = earth::llh_to_enu(&b.p, &a.p);
        let p = earth::enu_to_llh(&(d * w), &a.p)?;
        let v_n = match (a.v_n, b.v_n) {
            (Some(va), Some(vb)) => Some(va.lerp(&vb, w)),
            _ => None,
        };
        let q_nb = match (a.q_nb, b.q_nb) {
            (Some(qa), Some(qb)) => Some(qa.slerp(&qb, w)),
            _ => None,
        };
        Some(TruthSample { t_s, p, v_n, q_nb })
    }
}

/// The errors of one solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolutionError {
    pub t_s: f64,
    /// Position error, ENU (m).
    pub position_enu_m: Vector3<f64>,
    /// Velocity error, ENU (m/s).
    pub velocity_enu_mps: Option<Vector3<f64>>,
    /// Roll, pitch, yaw errors (rad), wrapped to ±π.
    pub attitude_rpy_rad: Option<Vector3<f64>>,
    /// NEES of the states the reference has (position, then velocity and attitude).
    pub nees: f64,
    /// Degrees of freedom of `nees`.
    pub nees_dof: usize,
    /// NEES of the position alone (3 degrees of freedom).
    pub position_nees: f64,
}

/// Errors of `solution` against `truth` (at the same time).
pub fn solution_error(solution: &Solution, truth: &TruthSample) -> SolutionError {
    let nav = &solution.nav;
    let position_enu_m = earth::llh_to_enu(&nav.p, &truth.p);
    let velocity_enu_mps = truth.v_n.map(|v| nav.v_n - v);
    let phi = truth.q_nb.map(|q| -(nav.q_nb * q.inverse()).scaled_axis());
    let attitude_rpy_rad = truth.q_nb.map(|q| {
        let (r1, p1, y1) = nav.q_nb.euler_angles();
        let (r0, p0, y0) = q.euler_angles();
        Vector3::new(wrap_pi(r1 - r0), wrap_pi(p1 - p0), wrap_pi(y1 - y0))
    });
    // Error vector and its covariance in (E, N, U, vE, vN, vU, φE, φN, φU), restricted to
    // what the reference has.
    let (north, east) = earth::metres_per_radian(&nav.p);
    let mut t = SMatrix::<f64, 9, N>::zeros();
    t[(0, DP + 1)] = east;
    t[(1, DP)] = north;
    t[(2, DP + 2)] = 1.0;
    for i in 0..3 {
        t[(3 + i, DV + i)] = 1.0;
        t[(6 + i, PHI + i)] = 1.0;
    }
    let p9 = t * solution.covariance * t.transpose();
    let zero = Vector3::zeros();
    let e9 = SVector::<f64, 9>::from_iterator(
        position_enu_m
            .iter()
            .chain(velocity_enu_mps.as_ref().unwrap_or(&zero).iter())
            .chain(phi.as_ref().unwrap_or(&zero).iter())
            .copied(),
    );
    let mut keep: Vec<usize> = (0..3).collect();
    if velocity_enu_mps.is_some() {
        keep.extend(3..6);
    }
    if phi.is_some() {
        keep.extend(6..9);
    }
    let n = keep.len();
    let e = nalgebra::DVector::from_iterator(n, keep.iter().map(|&i| e9[i]));
    let p = nalgebra::DMatrix::from_fn(n, n, |r, c| p9[(keep[r], keep[c])]);
    let nees = p.cholesky().map_or(f64::NAN, |ch| e.dot(&ch.solve(&e)));
    let position_nees = p9
        .fixed_view::<3, 3>(0, 0)
        .into_owned()
        .cholesky()
        .map_or(f64::NAN, |ch| {
            position_enu_m.dot(&ch.solve(&position_enu_m))
        });
    SolutionError {
        t_s: nav.t_s,
        position_enu_m,
        velocity_enu_mps,
        attitude_rpy_rad,
        nees,
        nees_dof: n,
        position_nees,
    }
}

/// Root-mean-square summary of many errors.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct ErrorSummary {
    pub epochs: usize,
    pub pos_rmse_e_m: f64,
    pub pos_rmse_n_m: f64,
    pub pos_rmse_u_m: f64,
    pub pos_rmse_horizontal_m: f64,
    /// Horizontal RMSE after removing the mean east and north error of these epochs (m):
    /// what a filter can change when the reference carries a common offset (a datum
    /// offset of an RTK base, see docs/walk_0827.md).
    pub pos_rmse_horizontal_offset_removed_m: f64,
    pub pos_rmse_3d_m: f64,
    pub vel_rmse_3d_mps: f64,
    pub att_rmse_roll_deg: f64,
    pub att_rmse_pitch_deg: f64,
    pub att_rmse_yaw_deg: f64,
    pub nees_mean: f64,
    /// Fraction of the epochs with a NEES whose NEES lies inside its two-sided 95 % χ²
    /// bounds for its degrees of freedom: about 0.95 for a covariance that states the
    /// errors honestly, far less for an over-confident one (NaN without any NEES).
    pub nees_in_bounds_95: f64,
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).sqrt()
    }
}

/// Summarizes `errors` (NaN for what no error carries).
pub fn summarize(errors: &[SolutionError]) -> ErrorSummary {
    let pos = |i: usize| rms(errors.iter().map(|e| e.position_enu_m[i]));
    let vel = rms(errors
        .iter()
        .filter_map(|e| e.velocity_enu_mps.map(|v| v.norm())));
    let att = |i: usize| {
        rms(errors
            .iter()
            .filter_map(|e| e.attitude_rpy_rad.map(|a| a[i])))
        .to_degrees()
    };
    let nees: Vec<f64> = errors
        .iter()
        .map(|e| e.nees)
        .filter(|v| v.is_finite())
        .collect();
    let (e, n, u) = (pos(0), pos(1), pos(2));
    // The RMS about the mean is the population standard deviation of each axis.
    let spread = |i: usize| {
        let mean = errors.iter().map(|e| e.position_enu_m[i]).sum::<f64>() / errors.len() as f64;
        rms(errors.iter().map(|e| e.position_enu_m[i] - mean))
    };
    ErrorSummary {
        epochs: errors.len(),
        pos_rmse_e_m: e,
        pos_rmse_n_m: n,
        pos_rmse_u_m: u,
        pos_rmse_horizontal_m: e.hypot(n),
        pos_rmse_horizontal_offset_removed_m: spread(0).hypot(spread(1)),
        pos_rmse_3d_m: (e * e + n * n + u * u).sqrt(),
        vel_rmse_3d_mps: vel,
        att_rmse_roll_deg: att(0),
        att_rmse_pitch_deg: att(1),
        att_rmse_yaw_deg: att(2),
        nees_mean: if nees.is_empty() {
            f64::NAN
        } else {
            nees.iter().sum::<f64>() / nees.len() as f64
        },
        nees_in_bounds_95: nees_in_bounds_95(errors),
    }
}

/// See [`ErrorSummary::nees_in_bounds_95`].
fn nees_in_bounds_95(errors: &[SolutionError]) -> f64 {
    let mut bounds: Vec<(usize, Option<(f64, f64)>)> = Vec::new();
    let (mut judged, mut inside) = (0usize, 0usize);
    for e in errors.iter().filter(|e| e.nees.is_finite()) {
        let dof = e.nees_dof;
        let bound = match bounds.iter().find(|(d, _)| *d == dof) {
            Some((_, b)) => *b,
            None => {
                let b = match (
                    chi_square_quantile(0.025, dof),
                    chi_square_quantile(0.975, dof),
                ) {
                    (Ok(lo), Ok(hi)) => Some((lo, hi)),
                    _ => None,
                };
                bounds.push((dof, b));
                b
            }
        };
        if let Some((lo, hi)) = bound {
            judged += 1;
            inside += usize::from((lo..=hi).contains(&e.nees));
        }
    }
    if judged == 0 {
        f64::NAN
    } else {
        inside as f64 / judged as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn track_interpolates_position_velocity_and_attitude() {
        let a = Llh::from_degrees(40.0, -105.0, 1600.0);
        let b = earth::enu_to_llh(&Vector3::new(10.0, -4.0, 2.0), &a).unwrap();
        let track = TruthTrack::new(
            vec![
                TruthSample {
                    t_s: 1.0,
                    p: b,
                    v_n: Some(Vector3::new(2.0, 0.0, 0.0)),
                    q_nb: Some(UnitQuaternion::from_euler_angles(0.0, 0.0, 0.2)),
                },
                TruthSample {
                    t_s: 0.0,
                    p: a,
                    v_n: Some(Vector3::new(0.0, 0.0, 0.0)),
                    q_nb: Some(UnitQuaternion::from_euler_angles(0.0, 0.0, 0.0)),
                },
            ],
            2.0,
        );
        let mid = track.at(0.25).unwrap();
        let d = earth::llh_to_enu(&mid.p, &a);
        assert!((d - Vector3::new(2.5, -1.0, 0.5)).norm() < 1e-6);
        assert!((mid.v_n.unwrap()[0] - 0.5).abs() < 1e-12);
        assert!((mid.q_nb.unwrap().euler_angles().2 - 0.05).abs() < 1e-12);
        assert!(track.at(-0.1).is_none());
        assert!(track.at(1.1).is_none());
        let gappy = TruthTrack::new(track.samples.clone(), 0.5);
        assert!(gappy.at(0.5).is_none());
    }

    #[test]
    fn the_position_nees_is_the_position_error_under_its_own_covariance() {
        let mut state = crate::engine::FilterState::moving(1e-10);
        state.p[(DP, DP)] = 4.0 / earth::metres_per_radian(&state.nav.p).0.powi(2);
        state.p[(DP + 2, DP + 2)] = 1.0;
        let solution = state.solution();
        let mut truth = TruthSample::from(&solution.nav);
        truth.p = earth::enu_to_llh(&Vector3::new(0.0, -3.0, 0.0), &solution.nav.p).unwrap();
        let e = solution_error(&solution, &truth);
        // 3 m north under a north σ of 2 m.
        assert!((e.position_nees - 2.25).abs() < 1e-6, "{}", e.position_nees);
        // No velocity or attitude error and no correlation: the full NEES is the same.
        assert!((e.nees - e.position_nees).abs() < 1e-6, "{}", e.nees);
    }

    #[test]
    fn summary_of_known_errors() {
        let e = |x: f64, y: f64, z: f64| SolutionError {
            t_s: 0.0,
            position_enu_m: Vector3::new(x, y, z),
            velocity_enu_mps: Some(Vector3::new(0.0, 0.0, 2.0)),
            attitude_rpy_rad: Some(Vector3::new(0.0, 0.0, 1f64.to_radians())),
            nees: 3.0,
            nees_dof: 9,
            position_nees: 1.0,
        };
        let s = summarize(&[e(3.0, 0.0, 0.0), e(-3.0, 4.0, 0.0)]);
        assert_eq!(s.epochs, 2);
        assert!((s.pos_rmse_e_m - 3.0).abs() < 1e-12);
        assert!((s.pos_rmse_n_m - 8f64.sqrt()).abs() < 1e-12);
        assert!((s.pos_rmse_3d_m - 17f64.sqrt()).abs() < 1e-12);
        // Means (0, 2): deviations (±3, ∓2).
        assert!((s.pos_rmse_horizontal_offset_removed_m - 13f64.sqrt()).abs() < 1e-12);
        assert!((s.vel_rmse_3d_mps - 2.0).abs() < 1e-12);
        assert!((s.att_rmse_yaw_deg - 1.0).abs() < 1e-12);
        assert!((s.nees_mean - 3.0).abs() < 1e-12);
        // 3.0 lies inside [2.70, 19.02], the 95 % bounds of chi-square with 9 dof.
        assert_eq!(s.nees_in_bounds_95, 1.0);
    }

    #[test]
    fn nees_outside_the_95_percent_bounds_is_counted_per_degrees_of_freedom() {
        let e = |nees: f64, nees_dof: usize| SolutionError {
            t_s: 0.0,
            position_enu_m: Vector3::zeros(),
            velocity_enu_mps: None,
            attitude_rpy_rad: None,
            nees,
            nees_dof,
            position_nees: nees,
        };
        // 3 dof: [0.216, 9.35]; 9 dof: [2.70, 19.02].
        let errors = [
            e(0.1, 3),
            e(5.0, 3),
            e(10.0, 3),
            e(2.0, 9),
            e(18.0, 9),
            e(f64::NAN, 9),
        ];
        assert_eq!(summarize(&errors).nees_in_bounds_95, 2.0 / 5.0);
        assert!(summarize(&[e(f64::NAN, 3)]).nees_in_bounds_95.is_nan());
    }
}
