//! What the range judge ([`super::error_correlation`]) finds beyond the satellites'
//! claims, as the covariance of the position (or velocity) it leaves the filter with:
//! the tightly-coupled counterpart of `FixConsistency::unclaimed_covariance`.
//!
//! A filter weighs each epoch's ranges as independent of the epoch before. Where their
//! errors are larger than claimed and correlated over seconds (foliage's multipath), it
//! follows the part that the ranges share through the geometry, and its innovations cannot
//! show it: on the default drive's foliage the tightly-coupled height was 10–12 m off at a
//! σ of 3.3–3.5 m (docs/results.md). The filter may carry that part whole: one epoch's
//! weighted least squares of the excess errors.
//!
//! Choice: the excess of a row is its variance beyond the claim, (s − 1) R with s the
//! judge's size factor (not its correlation factor: a correlated error of the claimed size
//! is the claimed size at each epoch), counted only where the judge also finds the
//! channel correlated in time (`Verdict::carried_size`), weighed as the
//! update weighs the rows (1 / (R f), f the whole inflation). The least squares is that
//! of the rows' common columns (position or velocity, and the clock), as the judge's
//! parity fit; an epoch whose rows cannot fix them leaves nothing.

use nalgebra::{Matrix3, Matrix4, Vector4};

/// One row of an epoch as the projection takes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExcessRow {
    /// The row's coefficients of position (or velocity) and clock (or clock drift).
    pub common: [f64; 4],
    /// The row's variance as the update weighs it (R f).
    pub weighed_variance: f64,
    /// Its variance beyond the claim ((s − 1) R).
    pub excess_variance: f64,
}

/// The covariance of the first three common columns that the rows' excess errors give
/// their weighted least squares, (Aᵀ W A)⁻¹ Aᵀ W E W A (Aᵀ W A)⁻¹, in the columns' units;
/// zero when no row has an excess, None when the rows cannot fix the columns.
pub fn projected_excess(rows: &[ExcessRow]) -> Option<Matrix3<f64>> {
    if rows.iter().all(|r| r.excess_variance <= 0.0) {
        return Some(Matrix3::zeros());
    }
    let mut normal = Matrix4::zeros();
    let mut excess = Matrix4::zeros();
    for row in rows {
        if !(row.weighed_variance > 0.0 && row.weighed_variance.is_finite()) {
            continue;
        }
        let a = Vector4::from(row.common);
        let w = 1.0 / row.weighed_variance;
        normal += a * a.transpose() * w;
        excess += a * a.transpose() * (w * w * row.excess_variance.max(0.0));
    }
    let inverse = normal.try_inverse()?;
    let covariance = inverse * excess * inverse;
    covariance
        .iter()
        .all(|v| v.is_finite())
        .then(|| covariance.fixed_view::<3, 3>(0, 0).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of a unit-vector geometry (east, north, up, and two tilted ones, each with
    /// the clock column 1), each weighed at `weighed` with `excess` beyond its claim.
    fn rows(weighed: f64, excess: f64) -> Vec<ExcessRow> {
        let s = 0.5_f64.sqrt();
        [
            [1.0, 0.0, 0.0, 1.0],
            [-1.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
            [0.0, -1.0, 0.0, 1.0],
            [s, 0.0, s, 1.0],
            [-s, 0.0, s, 1.0],
        ]
        .into_iter()
        .map(|common| ExcessRow {
            common,
            weighed_variance: weighed,
            excess_variance: excess,
        })
        .collect()
    }

    #[test]
    fn equal_excesses_give_the_least_squares_covariance_scaled() {
        // Every row weighed at 2 m² with 6 m² beyond the claim: the excess covariance is
        // (AᵀA)⁻¹ · 2² · 6 / 2² = 6 (AᵀA)⁻¹, three times the weighed solution's 2 (AᵀA)⁻¹.
        let rows = rows(2.0, 6.0);
        let normal = rows.iter().fold(Matrix4::zeros(), |n, r| {
            let a = Vector4::from(r.common);
            n + a * a.transpose()
        });
        let expected = (normal.try_inverse().unwrap() * 6.0)
            .fixed_view::<3, 3>(0, 0)
            .into_owned();
        let got = projected_excess(&rows).unwrap();
        assert!((got - expected).norm() < 1e-12, "{got} {expected}");
    }

    #[test]
    fn no_excess_gives_nothing_and_too_few_rows_cannot_say() {
        let rows = rows(1.0, 0.0);
        assert_eq!(projected_excess(&rows), Some(Matrix3::zeros()));
        let mut three = rows[..3].to_vec();
        three[0].excess_variance = 4.0;
        assert_eq!(projected_excess(&three), None);
    }

    #[test]
    fn one_satellites_excess_falls_along_its_line_of_sight() {
        let mut rows = rows(1.0, 0.0);
        rows[0].excess_variance = 9.0;
        let got = projected_excess(&rows).unwrap();
        assert!(got[(0, 0)] > 0.5, "east takes it: {got}");
        assert!(got[(1, 1)].abs() < 1e-12, "north does not: {got}");
    }
}
