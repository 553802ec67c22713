//! Bounds on a satellite's state that no GNSS satellite leaves: a state computed from
//! broadcast elements, or received in a measurement message, outside them is corrupt (a
//! decoding error, a crafted message) and is left out instead of putting a satellite at
//! 1e59 m into the measurements.
//!
//! Choice: every GNSS orbit has a semi-major axis between 25,500 km (GLONASS) and
//! 42,200 km (GEO, IGSO) and an eccentricity below 0.1, so 20,000–50,000 km holds them
//! all; ECEF speeds stay below 5 km/s (10 km/s allowed); the ICDs' a_f0 fields reach
//! 0.06 s at most (Galileo) and a_f1 3.7e-9 s/s (GPS), bounded here by 1 s and 1e-6.

use nalgebra::Vector3;

/// Smallest distance of a GNSS satellite from the Earth's centre (m).
pub const MIN_ORBIT_RADIUS_M: f64 = 2.0e7;
/// Largest distance of a GNSS satellite from the Earth's centre (m).
pub const MAX_ORBIT_RADIUS_M: f64 = 5.0e7;
/// Largest ECEF speed of a GNSS satellite (m/s).
pub const MAX_SAT_SPEED_MPS: f64 = 1.0e4;
/// Largest satellite clock bias (s).
pub const MAX_SAT_CLOCK_BIAS_S: f64 = 1.0;
/// Largest satellite clock drift (s/s).
pub const MAX_SAT_CLOCK_DRIFT_S_S: f64 = 1.0e-6;

/// Whether a satellite state lies within the bounds above.
pub fn plausible_satellite_state(
    pos_ecef_m: &Vector3<f64>,
    vel_ecef_mps: &Vector3<f64>,
    clock_bias_s: f64,
    clock_drift_s_s: f64,
) -> bool {
    (MIN_ORBIT_RADIUS_M..=MAX_ORBIT_RADIUS_M).contains(&pos_ecef_m.norm())
        && vel_ecef_mps.norm() <= MAX_SAT_SPEED_MPS
        && clock_bias_s.abs() <= MAX_SAT_CLOCK_BIAS_S
        && clock_drift_s_s.abs() <= MAX_SAT_CLOCK_DRIFT_S_S
}
