//! The level accelerometer biases as consider states while the heading is beyond the
//! filter's linear range.
//!
//! A level accelerometer bias and the tilt about the same axis move the velocity alike:
//! on a straight road only their sum is observed, and a turn tells them apart, because
//! the bias turns with the vehicle and the tilt does not. The filter maps the body-frame
//! bias into the navigation frame with its heading estimate; while that heading is known
//! to tens of degrees (a restart with a wide vertical gyro bias prior), its corrections
//! swing it by ±10° within seconds on a straight road, and the filter takes the swings for
//! turns: it tells the bias from the tilt where nothing does (measured after a consumer
//! gyro's tenfold bias jump: the tilt about the forward axis less the lateral bias, unseen
//! until the next turn, narrowed from 4.5° to 1.1° in 50 s, and the roll was then 1.8° off
//! at a σ of 0.53°; docs/results.md).
//!
//! Choice: while the heading 1-sigma exceeds [`BANK_ABOVE_RAD`] (where the heading bank
//! also deems the linearization poor), the body x and y accelerometer biases are consider
//! states (Schmidt–Kalman): the update neither corrects them nor narrows their variance;
//! their uncertainty still flows into the other states through the propagation. No
//! measurement model has the accelerometer biases in its rows, and with H zero in their
//! columns the Schmidt update equals the optimal one (EKF, cubature) except for those two
//! parts: the correction's bias entries are zeroed and their covariance block restored to
//! the prior's. With the IARF schemes' adaptive factor the gain is not the optimal one for
//! the prior, and the cross-covariances kept are the full update's, an approximation; the
//! block is restored only where what the update took from it is positive semi-definite
//! (always so for the optimal gain), which keeps the posterior so. The vertical bias is
//! left to the update: for a level vehicle it maps into the vertical, whatever the
//! heading.

use crate::ins::error_state::{StateMatrix, StateVector, ACC_BIAS, PHI};

use super::super::heading_bank::BANK_ABOVE_RAD;

/// The level (body x and y) accelerometer biases' indices in the state.
const LEVEL_ACCEL_BIASES: [usize; 2] = [ACC_BIAS, ACC_BIAS + 1];

/// Makes the correction `dx` and posterior `p` of an update of the prior covariance
/// `prior` the Schmidt update that keeps the level accelerometer biases, when the prior's
/// heading 1-sigma is beyond the linear range.
pub fn keep_level_accel_biases(prior: &StateMatrix, dx: &mut StateVector, p: &mut StateMatrix) {
    let yaw = PHI + 2;
    if prior[(yaw, yaw)] <= BANK_ABOVE_RAD.powi(2) {
        return;
    }
    let [a, b] = LEVEL_ACCEL_BIASES;
    // What the update took from the block: restored only when it is positive
    // semi-definite, so that the posterior stays so (see the module documentation).
    let taken = |i: usize, j: usize| prior[(i, j)] - p[(i, j)];
    let (taken_aa, taken_bb, taken_ab) = (taken(a, a), taken(b, b), taken(a, b));
    let restorable = taken_aa >= 0.0 && taken_bb >= 0.0 && taken_aa * taken_bb >= taken_ab.powi(2);
    for i in [a, b] {
        dx[i] = 0.0;
        if restorable {
            for j in [a, b] {
                p[(i, j)] = prior[(i, j)];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;
    use crate::filter::ekf;
    use crate::ins::error_state::N;

    /// A prior with every state correlated, the heading 1-sigma `yaw_sigma_rad`, three
    /// measurement rows that do not see the accelerometer biases, their noise and
    /// innovations.
    fn problem(yaw_sigma_rad: f64) -> (StateMatrix, DMatrix<f64>, DMatrix<f64>, DVector<f64>) {
        let a = StateMatrix::from_fn(|i, j| ((i * 7 + j * 3) % 11) as f64 * 0.05 - 0.2);
        let mut prior = a * a.transpose() + StateMatrix::identity() * 0.1;
        let yaw = PHI + 2;
        let scale = yaw_sigma_rad / prior[(yaw, yaw)].sqrt();
        prior.row_mut(yaw).scale_mut(scale);
        prior.column_mut(yaw).scale_mut(scale);
        let mut h = DMatrix::from_fn(3, N, |i, j| ((i * 5 + j) % 7) as f64 * 0.3 - 0.9);
        for j in ACC_BIAS..ACC_BIAS + 3 {
            h.column_mut(j).fill(0.0);
        }
        let r = DMatrix::from_diagonal(&DVector::from_vec(vec![0.5, 0.7, 0.9]));
        let y = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        (prior, h, r, y)
    }

    /// The full update of `problem`, then kept.
    fn kept(
        prior: &StateMatrix,
        h: &DMatrix<f64>,
        r: &DMatrix<f64>,
        y: &DVector<f64>,
    ) -> (StateVector, StateMatrix) {
        let p_dyn = DMatrix::from_column_slice(N, N, prior.as_slice());
        let full = ekf::update(&p_dyn, h, y, r, true).unwrap();
        let mut dx = StateVector::from_column_slice(full.dx.as_slice());
        let mut p = StateMatrix::from_column_slice(full.p.as_slice());
        keep_level_accel_biases(prior, &mut dx, &mut p);
        (dx, p)
    }

    /// Beyond the linear range the kept update is the Schmidt update: the gain's rows of
    /// the level biases zeroed, Joseph's form for that gain (valid for any gain).
    #[test]
    fn beyond_the_linear_range_the_update_is_schmidts() {
        let (prior, h, r, y) = problem(2.0 * BANK_ABOVE_RAD);
        let (dx, p) = kept(&prior, &h, &r, &y);
        let p_dyn = DMatrix::from_column_slice(N, N, prior.as_slice());
        let s = &h * &p_dyn * h.transpose() + &r;
        let mut k = &p_dyn * h.transpose() * s.try_inverse().unwrap();
        for &i in &LEVEL_ACCEL_BIASES {
            k.row_mut(i).fill(0.0);
        }
        let i_kh = DMatrix::<f64>::identity(N, N) - &k * &h;
        let schmidt = &i_kh * &p_dyn * i_kh.transpose() + &k * &r * k.transpose();
        let schmidt_dx = &k * &y;
        for i in 0..N {
            assert!((dx[i] - schmidt_dx[i]).abs() < 1e-9, "dx[{i}]");
            for j in 0..N {
                let d = (p[(i, j)] - schmidt[(i, j)]).abs();
                assert!(
                    d < 1e-9,
                    "P[{i}, {j}]: {} against {}",
                    p[(i, j)],
                    schmidt[(i, j)]
                );
            }
        }
        // The vertical bias is updated, the level ones are not.
        assert!(dx[ACC_BIAS + 2].abs() > 1e-6);
        assert!(p[(ACC_BIAS + 2, ACC_BIAS + 2)] < prior[(ACC_BIAS + 2, ACC_BIAS + 2)]);
    }

    /// An adaptive factor's update (the IARF schemes': the prior inflated by 1/α before
    /// the gain) can leave the level block larger than the prior's: what it took is not
    /// positive semi-definite, so the block is left as the update gave it, and the
    /// posterior stays positive semi-definite; the biases are still not corrected.
    #[test]
    fn a_block_the_update_grew_is_left_as_it_gave_it() {
        let (prior, h, r, y) = problem(2.0 * BANK_ABOVE_RAD);
        let inflated = DMatrix::from_column_slice(N, N, prior.as_slice()) * 4.0;
        let full = ekf::update(&inflated, &h, &y, &r, true).unwrap();
        let [a, b] = LEVEL_ACCEL_BIASES;
        assert!(full.p[(a, a)] > prior[(a, a)], "the update grew the block");
        let mut dx = StateVector::from_column_slice(full.dx.as_slice());
        let mut p = StateMatrix::from_column_slice(full.p.as_slice());
        keep_level_accel_biases(&prior, &mut dx, &mut p);
        assert_eq!((dx[a], dx[b]), (0.0, 0.0));
        assert!(dx[ACC_BIAS + 2].abs() > 1e-6);
        assert_eq!(p.as_slice(), full.p.as_slice());
        let smallest = p.symmetric_eigenvalues().min();
        assert!(smallest > -1e-9, "smallest eigenvalue {smallest}");
    }

    /// Within the linear range the full update stands.
    #[test]
    fn within_the_linear_range_the_full_update_stands() {
        let (prior, h, r, y) = problem(0.5 * BANK_ABOVE_RAD);
        let (dx, p) = kept(&prior, &h, &r, &y);
        let p_dyn = DMatrix::from_column_slice(N, N, prior.as_slice());
        let full = ekf::update(&p_dyn, &h, &y, &r, true).unwrap();
        assert_eq!(dx.as_slice(), full.dx.as_slice());
        assert_eq!(p.as_slice(), full.p.as_slice());
        assert!(dx[ACC_BIAS].abs() > 1e-6);
    }
}
