//! Satellite–receiver geometry and the predicted pseudo-range and pseudo-range rate of one
//! satellite (ERMAKF paper eq. 8, with the earth-rotation (Sagnac) correction the paper
//! leaves implicit).
//!
//! Sign conventions (what the filter builds its H rows from):
//! - `los_ecef` is the unit vector from the receiver to the satellite, in the ECEF frame of
//!   reception.
//! - ∂ρ/∂r_rx = −los (moving the receiver toward the satellite shortens the range), and
//!   ∂ρ̇/∂v_rx = −los / k with k = 1 + O(10⁻⁵) (see [`SatGeometry::d_range_rate_d_rx_vel`]);
//!   using −los for both is accurate to about 10⁻⁵ relative.
//! - ∂ρ/∂(clock bias in m) = +1, ∂ρ̇/∂(clock drift in m/s) = +1.
//!
//! Math note (neglected partials): the Sagnac rotation angle ω_e·τ depends on the receiver
//! position through τ = ρ/c; its contribution to ∂ρ/∂r_rx is of order ω_e |r_sat| / c ≈
//! 6·10⁻⁶ and is left out of the partials (it is kept in the predicted values).

use nalgebra::Vector3;
use thiserror::Error;

use crate::earth::{
    ecef_to_llh, rot_ecef_to_enu, Llh, EARTH_RATE_RAD_S, SEMI_MINOR_AXIS_M, SPEED_OF_LIGHT_M_S,
};
use crate::gnss::atmosphere::{klobuchar_delay_m, TroposphereModel};
use crate::gnss::{Klobuchar, SatId, SatObservation};

/// Smallest receiver–satellite distance (m) for which the line of sight is accepted.
/// Choice: 1 m only guards the division by the range; no GNSS satellite is anywhere near.
pub const MIN_RANGE_M: f64 = 1.0;

/// Light-time iterations: each shrinks the error of τ by about ω_e |r_sat| / c ≈ 6·10⁻⁶,
/// so three leave it far below 10⁻¹⁵ s.
const LIGHT_TIME_ITERATIONS: usize = 3;

/// Errors of the GNSS measurement model, with the satellite they concern.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum GnssModelError {
    /// An input is NaN or infinite.
    #[error("{sat}: non-finite {what}")]
    NonFinite { sat: SatId, what: &'static str },
    /// The satellite position lies inside the earth (corrupt ephemeris or wrong units).
    #[error(
        "{sat}: satellite position {radius_m:.0} m from the earth's centre is inside the earth"
    )]
    SatelliteInsideEarth { sat: SatId, radius_m: f64 },
    /// Receiver and satellite coincide: no line of sight.
    #[error("{sat}: satellite only {range_m:.3} m from the receiver")]
    DegenerateRange { sat: SatId, range_m: f64 },
    /// The receiver position has no geodetic latitude (at the earth's centre), so the
    /// elevation, azimuth and atmospheric delays are undefined.
    #[error("{sat}: receiver position has no geodetic coordinates (earth's centre)")]
    ReceiverPositionUndefined { sat: SatId },
}

/// Rotation of ECEF coordinates about the earth's z axis by `angle_rad`:
/// R3(θ) = [[cos θ, sin θ, 0], [−sin θ, cos θ, 0], [0, 0, 1]].
///
/// A point fixed in inertial space has, in the ECEF frame a time Δt later, the coordinates
/// R3(ω_e Δt) times its earlier ECEF coordinates. This is the Sagnac rotation and the
/// inertial-to-ECEF rotation of the orbit simulator.
pub fn rotate_about_earth_axis(v: &Vector3<f64>, angle_rad: f64) -> Vector3<f64> {
    let (s, c) = angle_rad.sin_cos();
    Vector3::new(c * v[0] + s * v[1], -s * v[0] + c * v[1], v[2])
}

/// Geometry of one satellite seen from the receiver at reception time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatGeometry {
    /// Satellite position at transmission, rotated into the ECEF frame of reception (m).
    pub sat_pos_rx_frame_m: Vector3<f64>,
    /// Satellite ECEF velocity at transmission, rotated likewise (m/s).
    pub sat_vel_rx_frame_mps: Vector3<f64>,
    /// Geometric range ρ = |R3(ω_e τ) r_sat − r_rx| (m).
    pub range_m: f64,
    /// Signal travel time τ = ρ / c (s).
    pub light_time_s: f64,
    /// Sagnac term: ρ minus the range computed without the earth-rotation correction (m).
    pub sagnac_m: f64,
    /// Unit vector receiver → satellite, ECEF frame of reception.
    pub los_ecef: Vector3<f64>,
    /// Geometric range rate dρ/dt at the receiver (m/s), Sagnac rate included.
    pub range_rate_mps: f64,
    /// ∂ρ̇/∂v_rx = −los / k (see the math note of [`line_of_sight`]).
    pub d_range_rate_d_rx_vel: Vector3<f64>,
}

/// Sagnac-corrected range, line of sight and range rate of a satellite whose position
/// `sat_pos_ecef_m` and velocity `sat_vel_ecef_mps` are given at transmission time in the
/// ECEF frame of that time, seen from a receiver at `rx_pos_ecef_m` moving at
/// `rx_vel_ecef_mps` (ECEF at reception). `sat` only labels errors.
///
/// Math note: with τ(t) the light time of the signal received at t, the range is
/// ρ(t) = |R3(ω_e τ) r_s(t − τ) − r_r(t)| and τ = ρ/c. Differentiating,
///   ρ̇ = e · [R v_s (1 − τ̇) + ω_e τ̇ R K r_s − v_r],  K r = (y, −x, 0),  τ̇ = ρ̇ / c,
/// where e is the line of sight and R = R3(ω_e τ). Solving for ρ̇:
///   ρ̇ = e · (R v_s − v_r) / k,   k = 1 + (e · R v_s − ω_e e · R K r_s) / c.
/// The τ̇ terms are the rate of the light time and of the Sagnac rotation; they change ρ̇ by
/// up to about a centimetre per second, which a Doppler-derived rate contains.
pub fn line_of_sight(
    sat: SatId,
    sat_pos_ecef_m: &Vector3<f64>,
    sat_vel_ecef_mps: &Vector3<f64>,
    rx_pos_ecef_m: &Vector3<f64>,
    rx_vel_ecef_mps: &Vector3<f64>,
) -> Result<SatGeometry, GnssModelError> {
    check_finite(sat, sat_pos_ecef_m, "satellite position")?;
    check_finite(sat, sat_vel_ecef_mps, "satellite velocity")?;
    check_finite(sat, rx_pos_ecef_m, "receiver position")?;
    check_finite(sat, rx_vel_ecef_mps, "receiver velocity")?;
    let radius_m = sat_pos_ecef_m.norm();
    if radius_m < SEMI_MINOR_AXIS_M {
        return Err(GnssModelError::SatelliteInsideEarth { sat, radius_m });
    }
    let plain_range_m = (sat_pos_ecef_m - rx_pos_ecef_m).norm();
    if plain_range_m < MIN_RANGE_M {
        return Err(GnssModelError::DegenerateRange {
            sat,
            range_m: plain_range_m,
        });
    }

    // Fixed-point iteration τ ← |R3(ω_e τ) r_s − r_r| / c, from the unrotated range.
    let mut light_time_s = plain_range_m / SPEED_OF_LIGHT_M_S;
    for _ in 0..LIGHT_TIME_ITERATIONS {
        let rotated = rotate_about_earth_axis(sat_pos_ecef_m, EARTH_RATE_RAD_S * light_time_s);
        light_time_s = (rotated - rx_pos_ecef_m).norm() / SPEED_OF_LIGHT_M_S;
    }
    let angle_rad = EARTH_RATE_RAD_S * light_time_s;
    let sat_pos_rx_frame_m = rotate_about_earth_axis(sat_pos_ecef_m, angle_rad);
    let sat_vel_rx_frame_mps = rotate_about_earth_axis(sat_vel_ecef_mps, angle_rad);
    let delta = sat_pos_rx_frame_m - rx_pos_ecef_m;
    let range_m = delta.norm();
    if range_m < MIN_RANGE_M {
        return Err(GnssModelError::DegenerateRange { sat, range_m });
    }
    let los_ecef = delta / range_m;

    // K r_s rotated: R K r_s = (y', −x', 0) with (x', y') the rotated position.
    let k_r = Vector3::new(sat_pos_rx_frame_m[1], -sat_pos_rx_frame_m[0], 0.0);
    let k = 1.0
        + (los_ecef.dot(&sat_vel_rx_frame_mps) - EARTH_RATE_RAD_S * los_ecef.dot(&k_r))
            / SPEED_OF_LIGHT_M_S;
    let range_rate_mps = los_ecef.dot(&(sat_vel_rx_frame_mps - rx_vel_ecef_mps)) / k;

    Ok(SatGeometry {
        sat_pos_rx_frame_m,
        sat_vel_rx_frame_mps,
        range_m,
        light_time_s: range_m / SPEED_OF_LIGHT_M_S,
        sagnac_m: range_m - plain_range_m,
        los_ecef,
        range_rate_mps,
        d_range_rate_d_rx_vel: -los_ecef / k,
    })
}

/// Elevation and azimuth (rad) of the direction `los_ecef` (unit, ECEF) at the receiver
/// `rx`: elevation in [−π/2, π/2] above the local horizontal (ENU), azimuth in [0, 2π)
/// clockwise from north.
pub fn elevation_azimuth(rx: &Llh, los_ecef: &Vector3<f64>) -> (f64, f64) {
    let enu = rot_ecef_to_enu(rx) * los_ecef;
    let elevation_rad = enu[2].clamp(-1.0, 1.0).asin();
    let azimuth_rad = enu[0].atan2(enu[1]).rem_euclid(2.0 * std::f64::consts::PI);
    (elevation_rad, azimuth_rad)
}

/// The model's prediction for one satellite at a receiver state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatPrediction {
    /// Geometric range, Sagnac-corrected (m).
    pub range_m: f64,
    /// Geometric range rate (m/s).
    pub range_rate_mps: f64,
    /// Unit vector receiver → satellite, ECEF. ∂ρ/∂r_rx = −los_ecef.
    pub los_ecef: Vector3<f64>,
    /// ∂ρ̇/∂v_rx (ECEF), −los_ecef to about 10⁻⁵ relative.
    pub d_range_rate_d_rx_vel: Vector3<f64>,
    /// Satellite elevation at the receiver (rad).
    pub elevation_rad: f64,
    /// Satellite azimuth at the receiver, clockwise from north (rad).
    pub azimuth_rad: f64,
    /// Ionospheric delay used (m).
    pub iono_m: f64,
    /// Tropospheric delay used (m).
    pub tropo_m: f64,
    /// Predicted pseudo-range ρ + b − c·δT + I + T (m).
    pub pseudorange_m: f64,
    /// Predicted pseudo-range rate ρ̇ + ḃ − c·δṪ (m/s).
    pub pseudorange_rate_mps: f64,
}

/// The delay models of a prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayModels<'a> {
    /// Klobuchar coefficients; None: no ionospheric delay.
    pub klobuchar: Option<&'a Klobuchar>,
    /// GPS time of week (s), for Klobuchar's local time.
    pub gps_tow_s: f64,
    /// Tropospheric delay model.
    pub troposphere: TroposphereModel,
}

/// Predicted pseudo-range and rate of `obs` for a receiver at `rx_pos_ecef_m` moving at
/// `rx_vel_ecef_mps` (ECEF), with clock bias `clock_bias_m` (c·δt_u) and drift
/// `clock_drift_mps` (c·δṫ_u):
///   ρ_pred = ρ + b − c·δT_sat + I + T,   ρ̇_pred = ρ̇ + ḃ − c·δṪ_sat.
///
/// Delays: the observation's own `iono_delay_m` / `tropo_delay_m` when present; otherwise
/// the Klobuchar model when `klobuchar` is given (else no ionospheric delay) and the
/// Saastamoinen model. `gps_tow_s` is the GPS time of week (for Klobuchar's local time).
/// [`predict_with`] takes another troposphere model.
///
/// Choice: the atmospheric delays' rates (millimetres per second at most) are not part of
/// the rate model.
pub fn predict(
    obs: &SatObservation,
    rx_pos_ecef_m: &Vector3<f64>,
    rx_vel_ecef_mps: &Vector3<f64>,
    clock_bias_m: f64,
    clock_drift_mps: f64,
    klobuchar: Option<&Klobuchar>,
    gps_tow_s: f64,
) -> Result<SatPrediction, GnssModelError> {
    let models = DelayModels {
        klobuchar,
        gps_tow_s,
        troposphere: TroposphereModel::default(),
    };
    predict_with(
        obs,
        rx_pos_ecef_m,
        rx_vel_ecef_mps,
        clock_bias_m,
        clock_drift_mps,
        &models,
    )
}

/// [`predict`] with the delay models given: a tropospheric delay the observation does
/// not carry comes from `models.troposphere`.
pub fn predict_with(
    obs: &SatObservation,
    rx_pos_ecef_m: &Vector3<f64>,
    rx_vel_ecef_mps: &Vector3<f64>,
    clock_bias_m: f64,
    clock_drift_mps: f64,
    models: &DelayModels<'_>,
) -> Result<SatPrediction, GnssModelError> {
    let DelayModels {
        klobuchar,
        gps_tow_s,
        troposphere,
    } = *models;
    let sat = obs.sat;
    let scalars = [
        (clock_bias_m, "receiver clock bias"),
        (clock_drift_mps, "receiver clock drift"),
        (obs.sat_clock_bias_s, "satellite clock bias"),
        (obs.sat_clock_drift_s_s, "satellite clock drift"),
        (gps_tow_s, "GPS time of week"),
    ];
    for (value, what) in scalars {
        if !value.is_finite() {
            return Err(GnssModelError::NonFinite { sat, what });
        }
    }
    let geometry = line_of_sight(
        sat,
        &obs.sat_pos_ecef_m,
        &obs.sat_vel_ecef_mps,
        rx_pos_ecef_m,
        rx_vel_ecef_mps,
    )?;
    let rx = ecef_to_llh(rx_pos_ecef_m).ok_or(GnssModelError::ReceiverPositionUndefined { sat })?;
    let (elevation_rad, azimuth_rad) = elevation_azimuth(&rx, &geometry.los_ecef);

    let iono_m = match (obs.iono_delay_m, klobuchar) {
        (Some(d), _) => d,
        (None, Some(k)) => klobuchar_delay_m(k, &rx, azimuth_rad, elevation_rad, gps_tow_s),
        (None, None) => 0.0,
    };
    let tropo_m = obs
        .tropo_delay_m
        .unwrap_or_else(|| troposphere.delay_m(&rx, elevation_rad));
    if !iono_m.is_finite() {
        return Err(GnssModelError::NonFinite {
            sat,
            what: "ionospheric delay",
        });
    }
    if !tropo_m.is_finite() {
        return Err(GnssModelError::NonFinite {
            sat,
            what: "tropospheric delay",
        });
    }

    let pseudorange_m = geometry.range_m + clock_bias_m - SPEED_OF_LIGHT_M_S * obs.sat_clock_bias_s
        + iono_m
        + tropo_m;
    let pseudorange_rate_mps =
        geometry.range_rate_mps + clock_drift_mps - SPEED_OF_LIGHT_M_S * obs.sat_clock_drift_s_s;
    Ok(SatPrediction {
        range_m: geometry.range_m,
        range_rate_mps: geometry.range_rate_mps,
        los_ecef: geometry.los_ecef,
        d_range_rate_d_rx_vel: geometry.d_range_rate_d_rx_vel,
        elevation_rad,
        azimuth_rad,
        iono_m,
        tropo_m,
        pseudorange_m,
        pseudorange_rate_mps,
    })
}

fn check_finite(sat: SatId, v: &Vector3<f64>, what: &'static str) -> Result<(), GnssModelError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(GnssModelError::NonFinite { sat, what })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{llh_to_ecef, SEMI_MAJOR_AXIS_M};
    use crate::gnss::atmosphere::saastamoinen_delay_m;
    use crate::gnss::Constellation;

    const G01: SatId = SatId {
        constellation: Constellation::Gps,
        prn: 1,
    };

    /// A satellite at GPS orbit radius in direction (east, north, up) from `rx`.
    fn satellite_towards(rx: &Llh, enu_dir: Vector3<f64>) -> Vector3<f64> {
        let r_rx = llh_to_ecef(rx);
        let dir = rot_ecef_to_enu(rx).transpose() * enu_dir.normalize();
        // Solve |r_rx + s dir| = 26 559.7 km for s > 0.
        let a_orbit = 26_559_700.0;
        let b = r_rx.dot(&dir);
        let s = -b + (b * b - r_rx.norm_squared() + a_orbit * a_orbit).sqrt();
        r_rx + s * dir
    }

    #[test]
    fn sagnac_matches_first_order_formula_and_has_tens_of_metres_at_most() {
        let mut max_abs = 0.0f64;
        for lat_i in -4..=4 {
            for lon_i in 0..6 {
                let rx = Llh::from_degrees(20.0 * lat_i as f64, 60.0 * lon_i as f64, 100.0);
                let r_rx = llh_to_ecef(&rx);
                for az_i in 0..8 {
                    for el_deg in [5.0f64, 30.0, 60.0, 89.0] {
                        let az = (45.0 * az_i as f64).to_radians();
                        let el = el_deg.to_radians();
                        let dir = Vector3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin());
                        let r_sat = satellite_towards(&rx, dir);
                        let g =
                            line_of_sight(G01, &r_sat, &Vector3::zeros(), &r_rx, &Vector3::zeros())
                                .unwrap();
                        // First-order Sagnac term ω_e (x_s y_r − y_s x_r) / c.
                        let first_order = EARTH_RATE_RAD_S
                            * (r_sat[0] * r_rx[1] - r_sat[1] * r_rx[0])
                            / SPEED_OF_LIGHT_M_S;
                        assert!(
                            (g.sagnac_m - first_order).abs() < 2e-3,
                            "{} {}",
                            g.sagnac_m,
                            first_order
                        );
                        max_abs = max_abs.max(g.sagnac_m.abs());
                    }
                }
            }
        }
        // Tens of metres at most (≈ ω_e a r_sat / c ≈ 41 m is the geometric bound).
        assert!(max_abs > 20.0 && max_abs < 41.5, "{max_abs}");
    }

    #[test]
    fn sagnac_shortens_the_range_to_an_eastern_satellite() {
        // Receiver on the equator at λ = 0; satellite low in the east. The receiver moves
        // east, toward the satellite, while the signal travels: the range is shorter.
        let rx = Llh::new(0.0, 0.0, 0.0);
        let r_sat = satellite_towards(&rx, Vector3::new(1.0, 0.0, 0.2));
        let g = line_of_sight(
            G01,
            &r_sat,
            &Vector3::zeros(),
            &llh_to_ecef(&rx),
            &Vector3::zeros(),
        )
        .unwrap();
        assert!(g.sagnac_m < -10.0, "{}", g.sagnac_m);
        // And longer to a western one.
        let r_sat = satellite_towards(&rx, Vector3::new(-1.0, 0.0, 0.2));
        let g = line_of_sight(
            G01,
            &r_sat,
            &Vector3::zeros(),
            &llh_to_ecef(&rx),
            &Vector3::zeros(),
        )
        .unwrap();
        assert!(g.sagnac_m > 10.0, "{}", g.sagnac_m);
    }

    /// Range of the signal received at `t` from a satellite moving on r_s(t) = p0 + v t
    /// (ECEF) by a receiver on r_r(t) = q0 + u t, solving the light-time equation
    /// c τ = |R3(ω_e τ) r_s(t − τ) − r_r(t)| by plain iteration (independent of
    /// `line_of_sight`).
    fn true_range(
        t: f64,
        p0: &Vector3<f64>,
        v: &Vector3<f64>,
        q0: &Vector3<f64>,
        u: &Vector3<f64>,
    ) -> (f64, f64) {
        let r_r = q0 + u * t;
        let mut tau = 0.07;
        for _ in 0..10 {
            let r_s = p0 + v * (t - tau);
            tau = (rotate_about_earth_axis(&r_s, EARTH_RATE_RAD_S * tau) - r_r).norm()
                / SPEED_OF_LIGHT_M_S;
        }
        (tau * SPEED_OF_LIGHT_M_S, tau)
    }

    #[test]
    fn range_rate_matches_finite_difference_of_range() {
        let rx = Llh::from_degrees(48.0, 11.0, 500.0);
        let q0 = llh_to_ecef(&rx);
        let u = Vector3::new(20.0, -35.0, 4.0);
        let mut worst = 0.0f64;
        let mut worst_naive = 0.0f64;
        for (i, dir) in [
            Vector3::new(1.0, 0.3, 0.3),
            Vector3::new(-0.4, 1.0, 0.8),
            Vector3::new(0.2, -1.0, 0.1),
            Vector3::new(0.0, 0.1, 1.0),
        ]
        .iter()
        .enumerate()
        {
            let p0 = satellite_towards(&rx, *dir);
            // A satellite-like velocity: 3.9 km/s, different directions.
            let v = Vector3::new(2000.0, -3000.0 + 500.0 * i as f64, 1500.0);
            let t = 0.0;
            let h = 0.01;
            let (rho_plus, _) = true_range(t + h, &p0, &v, &q0, &u);
            let (rho_minus, _) = true_range(t - h, &p0, &v, &q0, &u);
            let fd = (rho_plus - rho_minus) / (2.0 * h);
            let (_, tau) = true_range(t, &p0, &v, &q0, &u);
            let r_s_tx = p0 + v * (t - tau);
            let g = line_of_sight(G01, &r_s_tx, &v, &(q0 + u * t), &u).unwrap();
            worst = worst.max((g.range_rate_mps - fd).abs());
            // The naive rate without the Sagnac/light-time rate misses by millimetres
            // per second or more: the check can fail.
            let naive = g.los_ecef.dot(&(v - u));
            worst_naive = worst_naive.max((naive - fd).abs());
        }
        assert!(worst < 2e-5, "range rate vs finite difference: {worst} m/s");
        assert!(worst_naive > 1e-3, "{worst_naive}");
    }

    #[test]
    fn elevation_and_azimuth_of_known_directions() {
        let rx = Llh::from_degrees(30.0, 40.0, 0.0);
        let c_ne = rot_ecef_to_enu(&rx).transpose();
        let east = c_ne * Vector3::new(1.0, 0.0, 0.0);
        let (el, az) = elevation_azimuth(&rx, &east);
        assert!(el.abs() < 1e-12 && (az - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let dir = c_ne * Vector3::new(-1.0, -1.0, 2f64.sqrt()).normalize();
        let (el, az) = elevation_azimuth(&rx, &dir);
        assert!((el - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        assert!((az - 225f64.to_radians()).abs() < 1e-12);
    }

    fn observation(r_sat: Vector3<f64>) -> SatObservation {
        SatObservation {
            sat: G01,
            pseudorange_m: Some(2.2e7),
            pseudorange_rate_mps: None,
            pseudorange_sigma_m: None,
            pseudorange_rate_sigma_mps: None,
            cn0_dbhz: None,
            sat_pos_ecef_m: r_sat,
            sat_vel_ecef_mps: Vector3::new(0.0, 0.0, 3000.0),
            sat_clock_bias_s: 1e-4,
            sat_clock_drift_s_s: 1e-11,
            iono_delay_m: None,
            tropo_delay_m: None,
            carrier_phase: None,
        }
    }

    #[test]
    fn predict_composes_range_clocks_and_delays() {
        let rx = Llh::from_degrees(45.0, 10.0, 0.0);
        let r_rx = llh_to_ecef(&rx);
        let mut obs = observation(satellite_towards(&rx, Vector3::new(0.3, 0.5, 0.6)));
        let p = predict(&obs, &r_rx, &Vector3::zeros(), 1234.0, -5.0, None, 1000.0).unwrap();
        let c = SPEED_OF_LIGHT_M_S;
        assert_eq!(p.iono_m, 0.0);
        assert_eq!(p.tropo_m, saastamoinen_delay_m(&rx, p.elevation_rad));
        let expected = p.range_m + 1234.0 - c * 1e-4 + p.tropo_m;
        assert!((p.pseudorange_m - expected).abs() < 1e-6);
        assert!((p.pseudorange_rate_mps - (p.range_rate_mps - 5.0 - c * 1e-11)).abs() < 1e-9);
        // Supplied delays take precedence over the models.
        obs.iono_delay_m = Some(3.5);
        obs.tropo_delay_m = Some(2.0);
        let k = Klobuchar {
            alpha: [1e-8, 0.0, 0.0, 0.0],
            beta: [1e5, 0.0, 0.0, 0.0],
        };
        // The receiver state of `p`, with the Klobuchar model given.
        let predict_klobuchar = |obs: &SatObservation| {
            predict(
                obs,
                &r_rx,
                &Vector3::zeros(),
                1234.0,
                -5.0,
                Some(&k),
                1000.0,
            )
            .unwrap()
        };
        let q = predict_klobuchar(&obs);
        assert_eq!((q.iono_m, q.tropo_m), (3.5, 2.0));
        obs.iono_delay_m = None;
        let q = predict_klobuchar(&obs);
        let expected_iono = klobuchar_delay_m(&k, &rx, q.azimuth_rad, q.elevation_rad, 1000.0);
        assert_eq!(q.iono_m, expected_iono);
        assert!(q.iono_m > 0.0);
        // Another troposphere model changes the delay and nothing else.
        obs.tropo_delay_m = None;
        let q = predict_klobuchar(&obs);
        assert_eq!(q.tropo_m, saastamoinen_delay_m(&rx, q.elevation_rad));
        for troposphere in [
            TroposphereModel::Off,
            TroposphereModel::Saastamoinen(crate::gnss::atmosphere::TropoMapping::Cosecant),
        ] {
            let models = DelayModels {
                klobuchar: Some(&k),
                gps_tow_s: 1000.0,
                troposphere,
            };
            let t = predict_with(&obs, &r_rx, &Vector3::zeros(), 1234.0, -5.0, &models).unwrap();
            assert_eq!(t.tropo_m, troposphere.delay_m(&rx, t.elevation_rad));
            assert_ne!(t.tropo_m, q.tropo_m);
            assert_eq!(t.iono_m, q.iono_m);
            let expected = q.pseudorange_m - q.tropo_m + t.tropo_m;
            assert!((t.pseudorange_m - expected).abs() < 1e-6);
        }
    }

    #[test]
    fn predict_rejects_bad_inputs_with_typed_errors() {
        let rx = Llh::from_degrees(45.0, 10.0, 0.0);
        let r_rx = llh_to_ecef(&rx);
        let good = observation(satellite_towards(&rx, Vector3::new(0.3, 0.5, 0.6)));
        let zero = Vector3::zeros();

        let mut obs = good.clone();
        obs.sat_pos_ecef_m[1] = f64::NAN;
        assert!(matches!(
            predict(&obs, &r_rx, &zero, 0.0, 0.0, None, 0.0),
            Err(GnssModelError::NonFinite { .. })
        ));
        let mut obs = good.clone();
        obs.sat_pos_ecef_m = Vector3::new(1000.0, 0.0, 0.0);
        assert!(matches!(
            predict(&obs, &r_rx, &zero, 0.0, 0.0, None, 0.0),
            Err(GnssModelError::SatelliteInsideEarth { .. })
        ));
        let mut obs = good.clone();
        obs.sat_pos_ecef_m = Vector3::new(SEMI_MAJOR_AXIS_M * 3.0, 0.0, 0.0);
        let at_sat = obs.sat_pos_ecef_m;
        assert!(matches!(
            predict(&obs, &at_sat, &zero, 0.0, 0.0, None, 0.0),
            Err(GnssModelError::DegenerateRange { .. })
        ));
        assert!(matches!(
            predict(&good, &zero, &zero, 0.0, 0.0, None, 0.0),
            Err(GnssModelError::ReceiverPositionUndefined { .. })
        ));
        assert!(matches!(
            predict(&good, &r_rx, &zero, f64::INFINITY, 0.0, None, 0.0),
            Err(GnssModelError::NonFinite { .. })
        ));
        let mut obs = good;
        obs.iono_delay_m = Some(f64::NAN);
        assert!(matches!(
            predict(&obs, &r_rx, &zero, 0.0, 0.0, None, 0.0),
            Err(GnssModelError::NonFinite { .. })
        ));
    }
}
