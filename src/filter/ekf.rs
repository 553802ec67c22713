//! The standard EKF steps of the ERMAKF paper, eqs. (10)–(11), for the closed-loop error
//! state: the prior error estimate is zero after every feedback, so the update is
//! δx̂ = K y with y the innovation (predicted minus measured).

use nalgebra::{DMatrix, DVector};

use crate::ins::error_state::N;
use crate::linalg::symmetrize;

/// Failures of a Kalman step; the state is left untouched when one is returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilterError {
    #[error("innovation covariance is not positive definite ({rows} measurements)")]
    SingularInnovationCovariance { rows: usize },
    #[error(
        "measurement dimensions disagree: H {h_rows}x{h_cols}, y {y_len}, R {r_rows}x{r_cols}"
    )]
    DimensionMismatch {
        h_rows: usize,
        h_cols: usize,
        y_len: usize,
        r_rows: usize,
        r_cols: usize,
    },
    #[error("the update produced a non-finite state or covariance")]
    NonFinite,
    /// The cubature update failed (a covariance could not be factored, a model output was
    /// not finite).
    #[error("cubature update: {0}")]
    Cubature(#[from] crate::filter::cubature::CubatureError),
    /// A step of the adaptive or robust schemes failed.
    #[error("adaptive/robust step: {0}")]
    Adaptive(#[from] crate::adaptive::math_error::AdaptiveMathError),
    /// A covariance could not be factored.
    #[error(transparent)]
    Linalg(#[from] crate::linalg::LinalgError),
}

/// The result of a measurement update.
#[derive(Debug, Clone)]
pub struct Update {
    /// Error-state estimate δx̂ = K y.
    pub dx: DVector<f64>,
    /// Posterior covariance.
    pub p: DMatrix<f64>,
    /// Innovation covariance S = H P⁻ Hᵀ + R.
    pub s: DMatrix<f64>,
    /// Normalized innovation squared yᵀ S⁻¹ y.
    pub nis: f64,
}

/// Measurement update, eq. (11), of the prior covariance `p` (n × n: the error state, or
/// the part of it that is not inert) with the innovation `y` (m), rows `h` (m × n) and
/// noise covariance `r` (m × m).
///
/// Math note: the covariance uses Joseph's form (I − KH) P (I − KH)ᵀ + K R Kᵀ when `joseph`
/// is set, which stays symmetric positive semi-definite for any gain; the short form
/// (I − KH) P of eq. (11) is kept as an option for comparison with the paper. K is formed
/// by a Cholesky solve with S, never an explicit inverse.
pub fn update(
    p: &DMatrix<f64>,
    h: &DMatrix<f64>,
    y: &DVector<f64>,
    r: &DMatrix<f64>,
    joseph: bool,
) -> Result<Update, FilterError> {
    let m = y.len();
    let n = p.nrows();
    if p.ncols() != n
        || n > N
        || h.nrows() != m
        || h.ncols() != n
        || r.nrows() != m
        || r.ncols() != m
    {
        return Err(FilterError::DimensionMismatch {
            h_rows: h.nrows(),
            h_cols: h.ncols(),
            y_len: m,
            r_rows: r.nrows(),
            r_cols: r.ncols(),
        });
    }
    let p_dyn = p;
    let pht = p_dyn * h.transpose();
    let mut s = h * &pht + r;
    s = (&s + s.transpose()) * 0.5;
    let chol = s
        .clone()
        .cholesky()
        .ok_or(FilterError::SingularInnovationCovariance { rows: m })?;
    // K = P Hᵀ S⁻¹  ⇔  S Kᵀ = H P.
    let k = kalman_gain(chol.l_dirty(), &pht);
    let dx_dyn = &k * y;
    let nis = y.dot(&chol.solve(y));
    let i_kh = DMatrix::<f64>::identity(n, n) - &k * h;
    let p_post = if joseph {
        &i_kh * p_dyn * i_kh.transpose() + k_r_kt(&k, r)
    } else {
        &i_kh * p_dyn
    };
    let p_post = symmetrize(&p_post);
    let dx = dx_dyn;
    if !(dx.iter().all(|v| v.is_finite())
        && p_post.iter().all(|v| v.is_finite())
        && nis.is_finite())
    {
        return Err(FilterError::NonFinite);
    }
    Ok(Update {
        dx,
        p: p_post,
        s,
        nis,
    })
}

/// The gain K = P Hᵀ S⁻¹ from the lower Cholesky factor `l` of S = L Lᵀ (only its lower
/// triangle is read) and P Hᵀ (n × m, n ≤ N): S Kᵀ = H P solved by forward substitution
/// L Z = H P and back substitution Lᵀ Kᵀ = Z, for all n right-hand sides at once.
///
/// Math note (layout): row i of H P is column i of P Hᵀ and row i of Kᵀ is column i of K,
/// both contiguous, so each step of either substitution updates N numbers side by side.
/// The forward sums run in increasing j, as a column-by-column solve adds them; the back
/// substitution sums Σ_{j>i} L[j, i] x_j in increasing j (a column-by-column solve may
/// group that sum differently: the two agree to rounding).
fn kalman_gain(l: &DMatrix<f64>, pht: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, m) = pht.shape();
    let mut k = pht.clone();
    let ks = k.as_mut_slice();
    for i in 0..m {
        let mut acc_n = [0.0; N];
        let acc = &mut acc_n[..n];
        acc.copy_from_slice(&ks[i * n..(i + 1) * n]);
        for j in 0..i {
            let l_ij = l[(i, j)];
            for (a, z) in acc.iter_mut().zip(&ks[j * n..(j + 1) * n]) {
                *a -= l_ij * z;
            }
        }
        let d = l[(i, i)];
        for (out, a) in ks[i * n..(i + 1) * n].iter_mut().zip(acc.iter()) {
            *out = a / d;
        }
    }
    for i in (0..m).rev() {
        let mut acc_n = [0.0; N];
        let acc = &mut acc_n[..n];
        acc.copy_from_slice(&ks[i * n..(i + 1) * n]);
        for j in i + 1..m {
            let l_ji = l[(j, i)];
            for (a, x) in acc.iter_mut().zip(&ks[j * n..(j + 1) * n]) {
                *a -= l_ji * x;
            }
        }
        let d = l[(i, i)];
        for (out, a) in ks[i * n..(i + 1) * n].iter_mut().zip(acc.iter()) {
            *out = a / d;
        }
    }
    k
}

/// K R Kᵀ, with R's columns applied as a scaling when R is diagonal (the usual case of
/// independent satellites), which saves a dense product.
fn k_r_kt(k: &DMatrix<f64>, r: &DMatrix<f64>) -> DMatrix<f64> {
    let m = r.nrows();
    let diagonal = (0..m).all(|i| (0..m).all(|j| i == j || r[(i, j)] == 0.0));
    if diagonal {
        let mut kr = k.clone();
        for (j, mut column) in kr.column_iter_mut().enumerate() {
            column *= r[(j, j)];
        }
        kr * k.transpose()
    } else {
        k * r * k.transpose()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_update_matches_closed_form() {
        let mut p = DMatrix::identity(N, N) * 4.0;
        p[(0, 1)] = 1.0;
        p[(1, 0)] = 1.0;
        let mut h = DMatrix::zeros(1, N);
        h[(0, 0)] = 1.0;
        let y = DVector::from_element(1, 2.0);
        let r = DMatrix::from_element(1, 1, 1.0);
        for joseph in [true, false] {
            let u = update(&p, &h, &y, &r, joseph).unwrap();
            // S = 5, K = [4, 1, 0...]/5
            assert!((u.dx[0] - 1.6).abs() < 1e-12);
            assert!((u.dx[1] - 0.4).abs() < 1e-12);
            assert!((u.p[(0, 0)] - 0.8).abs() < 1e-12);
            assert!((u.p[(1, 1)] - (4.0 - 0.2)).abs() < 1e-12);
            assert!((u.nis - 0.8).abs() < 1e-12);
        }
    }

    #[test]
    fn k_r_kt_with_diagonal_and_full_r_agree_with_the_dense_product() {
        let k = DMatrix::from_fn(4, 3, |i, j| (i as f64 + 1.0) * 0.3 - j as f64 * 0.7);
        let diag = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![2.0, 0.5, 3.0]));
        let mut full = diag.clone();
        full[(0, 2)] = 0.4;
        full[(2, 0)] = 0.4;
        for r in [diag, full] {
            let dense = &k * &r * k.transpose();
            assert!((k_r_kt(&k, &r) - dense).amax() < 1e-12);
        }
    }

    #[test]
    fn kalman_gain_matches_the_generic_cholesky_solve() {
        // A P and 24 rows H of the sizes of a 12-satellite epoch.
        let p = crate::ins::error_state::StateMatrix::from_fn(|i, j| {
            let d = (i as f64 - j as f64).abs();
            (1.0 + 0.3 * i as f64) * (1.0 + 0.3 * j as f64) * (-0.4 * d).exp()
        });
        let h = DMatrix::from_fn(24, N, |i, j| ((i * 7 + j * 3) % 11) as f64 / 5.0 - 1.0);
        let p_dyn = DMatrix::from_column_slice(N, N, p.as_slice());
        let pht = &p_dyn * h.transpose();
        let s = &h * &pht + DMatrix::identity(24, 24) * 4.0;
        let s = (&s + s.transpose()) * 0.5;
        let chol = s.cholesky().unwrap();
        let ours = kalman_gain(chol.l_dirty(), &pht);
        let generic = chol.solve(&pht.transpose()).transpose();
        let scale = generic.amax();
        assert!((ours - &generic).amax() <= 1e-12 * scale);
    }

    #[test]
    fn rejects_singular_innovation_covariance() {
        let p = DMatrix::zeros(N, N);
        let h = DMatrix::zeros(2, N);
        let y = DVector::zeros(2);
        let r = DMatrix::zeros(2, 2);
        assert!(matches!(
            update(&p, &h, &y, &r, true),
            Err(FilterError::SingularInnovationCovariance { rows: 2 })
        ));
    }
}
