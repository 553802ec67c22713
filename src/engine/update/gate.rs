//! The innovation gate of scalar measurements.

use crate::adaptive::common_mode::median;
use crate::filter::measurement_rows::{row_variance, Row};
use crate::ins::error_state::StateMatrix;

use super::super::adaptive_noise::Observable;

/// One scalar measurement as the gate sees it.
pub(super) struct GateRow<'a> {
    pub row: &'a Row,
    pub observable: Observable,
    /// Innovation predicted − measured.
    pub y: f64,
    /// Its variance R.
    pub r: f64,
}

/// The indices of the measurements that pass the gate `gate_sigma` (in units of √S; 0 =
/// off), in order; `gated(i, innovation, normalized)` is told of each one left out, with
/// its innovation measured − predicted and that divided by √S.
///
/// Choice: with three or more measurements of an observable, the gate tests each
/// innovation's distance from the median innovation of its observable, scaled by its own
/// √S. A receiver clock offset or drift error shifts all innovations of an observable
/// together; that is for the update to estimate, not a reason to reject every satellite.
/// With fewer, the plain |y|/√S test.
pub(super) fn gate(
    rows: &[GateRow],
    p: &StateMatrix,
    gate_sigma: f64,
    mut gated: impl FnMut(usize, f64, f64),
) -> Vec<usize> {
    if gate_sigma <= 0.0 {
        return (0..rows.len()).collect();
    }
    let common = |observable: Observable| {
        let mut ys: Vec<f64> = rows
            .iter()
            .filter(|g| g.observable == observable)
            .map(|g| g.y)
            .collect();
        if ys.len() >= 3 {
            median(&mut ys).unwrap_or(0.0)
        } else {
            0.0
        }
    };
    let mut offsets: Vec<(Observable, f64)> = Vec::new();
    for g in rows {
        if !offsets.iter().any(|(o, _)| *o == g.observable) {
            offsets.push((g.observable, common(g.observable)));
        }
    }
    let mut kept = Vec::with_capacity(rows.len());
    for (i, g) in rows.iter().enumerate() {
        let s = row_variance(g.row, p) + g.r;
        let offset = offsets
            .iter()
            .find(|(o, _)| *o == g.observable)
            .map_or(0.0, |(_, offset)| *offset);
        if (g.y - offset).abs() <= gate_sigma * s.sqrt() {
            kept.push(i);
        } else {
            gated(i, -g.y, -g.y / s.sqrt());
        }
    }
    kept
}
