//! The checks that relate two parameters (each parameter's own range is in the table and
//! is checked when the value is written). The first offending key is reported.

use super::Config;

/// A relation between parameters that does not hold: the key to name, its value as the
/// file writes it, the other key involved (for the origin) and the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct Conflict {
    pub key: &'static str,
    pub value: String,
    pub other: &'static str,
    pub reason: String,
}

/// Checks the relations between parameters of a configuration whose every value is in
/// its range.
pub fn relations(c: &Config) -> Result<(), Conflict> {
    let a = &c.adaptive;
    // Choice: the AR fit needs the order plus two samples, a KDE fit at least 10.
    // Saturating: the table caps the order at 100, the sum cannot overflow anyway.
    let needed = a.ar_max_order.saturating_add(2).max(10);
    if a.min_samples < needed {
        return Err(conflict(
            "adaptive.min_samples",
            a.min_samples,
            "adaptive.ar_max_order",
            format!("must be at least max(adaptive.ar_max_order + 2, 10) = {needed}"),
        ));
    }
    if a.min_samples > a.window_size_m {
        return Err(conflict(
            "adaptive.min_samples",
            a.min_samples,
            "adaptive.window_size_m",
            "must not exceed adaptive.window_size_m".to_owned(),
        ));
    }
    for (key, max, other, min) in [
        (
            "adaptive.pseudorange_sigma_max_m",
            a.pseudorange_sigma_max_m,
            "adaptive.pseudorange_sigma_min_m",
            a.pseudorange_sigma_min_m,
        ),
        (
            "adaptive.pseudorange_rate_sigma_max_mps",
            a.pseudorange_rate_sigma_max_mps,
            "adaptive.pseudorange_rate_sigma_min_mps",
            a.pseudorange_rate_sigma_min_mps,
        ),
    ] {
        if max < min {
            return Err(conflict(
                key,
                max,
                other,
                format!("must be at least {other}"),
            ));
        }
    }

    let f = &c.filter;
    if let Some(reason) = f.variant.base_conflict(f.base) {
        return Err(Conflict {
            key: "filter.base",
            value: f.base.as_str().to_owned(),
            other: "filter.variant",
            reason,
        });
    }
    let r = &c.robust;
    for (key, upper, other, lower) in [
        (
            "robust.adaptive_factor_c1",
            r.adaptive_factor_c1,
            "robust.adaptive_factor_c0",
            r.adaptive_factor_c0,
        ),
        ("robust.igg3_k1", r.igg3_k1, "robust.igg3_k0", r.igg3_k0),
    ] {
        if upper <= lower {
            return Err(conflict(key, upper, other, format!("must be > {other}")));
        }
    }
    Ok(())
}

fn conflict(
    key: &'static str,
    value: impl std::fmt::Display,
    other: &'static str,
    reason: String,
) -> Conflict {
    Conflict {
        key,
        value: value.to_string(),
        other,
        reason,
    }
}
