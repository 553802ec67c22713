//! A simulated GPS constellation: the baseline 24-slot constellation on Keplerian orbits
//! (optionally with extra satellites, as flown today), deterministic satellite clocks, and noise-controlled pseudo-range / rate observations
//! of a receiver whose true state the caller gives.
//!
//! Time: every `t_s` here is GPS time in seconds since the constellation's reference
//! epoch (the defined epoch of the slot table, 1993-07-01 00:00 UTC, a Thursday). Its GPS
//! time of week is [`GpsConstellation::gps_time_of_week_s`].
//!
//! Choices (documented once here):
//! - Orbits are pure two-body Keplerian (no J2 nodal regression, no perturbations); the
//!   earth turns at the WGS84 rate from the Greenwich hour angle of the slot table's epoch.
//! - Each slot's nominal orbit is circular; real GPS eccentricities are 0.00–0.02, so each
//!   satellite gets a deterministic eccentricity in [0.002, 0.014] and argument of perigee,
//!   with the mean anomaly chosen so that its mean argument of latitude is the slot's.
//! - PRN n is the n-th slot of the table (A1 = 1, A2 = 2, ..., F4 = 24); the real PRN–slot
//!   assignment changes with launches and is irrelevant here.
//! - The baseline 24 alone leaves 4–9 satellites above a 10° mask at mid-latitudes (about 7
//!   on average); [`GpsConstellation::augmented`] adds satellites like today's ~31.
//! - Satellite clocks are a0 + a1 t (a0 within ±300 µs, |a1| ≤ 4·10⁻¹² s/s, deterministic
//!   per PRN) plus the relativistic eccentricity term −2 r·v / c², which the message
//!   contract includes in the broadcast clock.

use nalgebra::Vector3;
use thiserror::Error;

use crate::earth::{ecef_to_llh, EARTH_RATE_RAD_S, GM_M3_S2, SPEED_OF_LIGHT_M_S};
use crate::gnss::atmosphere::{klobuchar_delay_m, saastamoinen_delay_m};
use crate::gnss::geometry::{
    elevation_azimuth, line_of_sight, rotate_about_earth_axis, GnssModelError,
};
use crate::gnss::{CarrierPhase, Constellation, GnssEpoch, Klobuchar, SatId, SatObservation};

/// Nominal GPS semi-major axis (m).
pub const GPS_SEMI_MAJOR_AXIS_M: f64 = 26_559_700.0;
/// Nominal GPS inclination (rad), 55°.
pub const GPS_INCLINATION_RAD: f64 = 55.0 * std::f64::consts::PI / 180.0;
/// Greenwich hour angle at the slot table's epoch, 18 h 36 min 14.4 s (rad).
const GREENWICH_ANGLE_AT_EPOCH_RAD: f64 =
    (18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0 * std::f64::consts::PI / 180.0;
/// GPS time of week at the reference epoch: Thursday 00:00 UTC plus GPS − UTC = 9 s (s).
pub const REFERENCE_EPOCH_GPS_TOW_S: f64 = 4.0 * 86_400.0 + 9.0;
/// Seconds per GPS week.
const SECONDS_PER_WEEK: f64 = 604_800.0;

/// The baseline 24-slot GPS constellation of the GPS SPS Performance Standard (2001 and
/// 2008 editions, Table 3.1/3.2-1): slot, right ascension of the ascending node (deg) and
/// argument of latitude (deg) at the defined epoch 1993-07-01 00:00 UTC (FK5/J2000).
const GPS_SLOTS: [(&str, f64, f64); 24] = [
    ("A1", 272.847, 268.126),
    ("A2", 272.847, 161.786),
    ("A3", 272.847, 11.676),
    ("A4", 272.847, 41.806),
    ("B1", 332.847, 80.956),
    ("B2", 332.847, 173.336),
    ("B3", 332.847, 309.976),
    ("B4", 332.847, 204.376),
    ("C1", 32.847, 111.876),
    ("C2", 32.847, 11.796),
    ("C3", 32.847, 339.666),
    ("C4", 32.847, 241.556),
    ("D1", 92.847, 135.226),
    ("D2", 92.847, 265.446),
    ("D3", 92.847, 35.156),
    ("D4", 92.847, 167.356),
    ("E1", 152.847, 197.046),
    ("E2", 152.847, 302.596),
    ("E3", 152.847, 66.066),
    ("E4", 152.847, 333.686),
    ("F1", 212.847, 238.886),
    ("F2", 212.847, 345.226),
    ("F3", 212.847, 105.206),
    ("F4", 212.847, 135.346),
];

/// Errors of the observation simulator.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SimError {
    /// A caller-supplied input is NaN or infinite.
    #[error("non-finite {what}")]
    NonFiniteInput { what: &'static str },
    /// The true receiver position has no geodetic coordinates (earth's centre).
    #[error("receiver position has no geodetic coordinates")]
    ReceiverPositionUndefined,
    /// The light-time iteration did not settle (cannot happen for receivers near the earth).
    #[error("{sat}: transmission time did not converge at t = {t_rx_s} s")]
    TransmissionTimeNotConverged { sat: SatId, t_rx_s: f64 },
    /// The measurement model refused the geometry.
    #[error(transparent)]
    Model(#[from] GnssModelError),
}

/// Classical Keplerian elements in the inertial frame of the reference epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeplerOrbit {
    /// Semi-major axis a (m).
    pub semi_major_axis_m: f64,
    /// Eccentricity e.
    pub eccentricity: f64,
    /// Inclination i (rad).
    pub inclination_rad: f64,
    /// Right ascension of the ascending node Ω (rad).
    pub raan_rad: f64,
    /// Argument of perigee ω (rad).
    pub arg_perigee_rad: f64,
    /// Mean anomaly at the reference epoch M₀ (rad).
    pub mean_anomaly_at_epoch_rad: f64,
}

impl KeplerOrbit {
    /// Mean motion n = sqrt(GM / a³) (rad/s).
    pub fn mean_motion_rad_s(&self) -> f64 {
        (GM_M3_S2 / self.semi_major_axis_m.powi(3)).sqrt()
    }

    /// Inertial position (m) and velocity (m/s) at `t_s` after the reference epoch.
    pub fn inertial_state(&self, t_s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let a = self.semi_major_axis_m;
        let e = self.eccentricity;
        let n = self.mean_motion_rad_s();
        let mean_anomaly = self.mean_anomaly_at_epoch_rad + n * t_s;
        // Kepler's equation E − e sin E = M by Newton's method; e ≤ 0.02 converges to
        // machine precision in three or four steps.
        let mut ecc_anomaly = mean_anomaly;
        for _ in 0..8 {
            ecc_anomaly -= (ecc_anomaly - e * ecc_anomaly.sin() - mean_anomaly)
                / (1.0 - e * ecc_anomaly.cos());
        }
        let (sin_e, cos_e) = ecc_anomaly.sin_cos();
        let root = (1.0 - e * e).sqrt();
        let e_dot = n / (1.0 - e * cos_e);
        // Perifocal coordinates.
        let x_pf = a * (cos_e - e);
        let y_pf = a * root * sin_e;
        let vx_pf = -a * sin_e * e_dot;
        let vy_pf = a * root * cos_e * e_dot;
        let (so, co) = self.raan_rad.sin_cos();
        let (sw, cw) = self.arg_perigee_rad.sin_cos();
        let (si, ci) = self.inclination_rad.sin_cos();
        let p = Vector3::new(co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si);
        let q = Vector3::new(-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si);
        (p * x_pf + q * y_pf, p * vx_pf + q * vy_pf)
    }
}

/// Deterministic satellite clock: a0 + a1 (t − 0), relativistic term added separately.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatClockModel {
    /// Offset at the reference epoch (s).
    pub bias_s: f64,
    /// Drift (s/s).
    pub drift_s_s: f64,
}

/// One simulated satellite.
#[derive(Debug, Clone, PartialEq)]
pub struct SimSatellite {
    /// Constellation and PRN.
    pub id: SatId,
    /// Slot name of the nominal constellation ("A1", ...).
    pub slot: String,
    /// Orbit.
    pub orbit: KeplerOrbit,
    /// Clock.
    pub clock: SatClockModel,
}

/// Satellite state at one GPS time, in the ECEF frame of that time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatState {
    /// ECEF position (m).
    pub pos_ecef_m: Vector3<f64>,
    /// ECEF velocity, relative to the rotating earth (m/s).
    pub vel_ecef_mps: Vector3<f64>,
    /// Clock offset, relativistic term included (s).
    pub clock_bias_s: f64,
    /// Clock drift, relativistic term's rate included (s/s).
    pub clock_drift_s_s: f64,
}

/// True state of the simulated receiver at reception time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceiverTruth {
    /// ECEF position (m).
    pub pos_ecef_m: Vector3<f64>,
    /// ECEF velocity (m/s).
    pub vel_ecef_mps: Vector3<f64>,
    /// Clock bias c·δt_u (m).
    pub clock_bias_m: f64,
    /// Clock drift c·δṫ_u (m/s).
    pub clock_drift_mps: f64,
}

/// The atmosphere the simulated signals cross, and what the observations report of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtmosphereTruth {
    /// Broadcast Klobuchar coefficients; the true ionosphere is `iono_scale` times the
    /// Klobuchar delay (none when absent). The epoch carries these coefficients.
    pub klobuchar: Option<Klobuchar>,
    /// Ratio of the true ionospheric delay to the Klobuchar one (1 = model is perfect).
    pub iono_scale: f64,
    /// Ratio of the true tropospheric delay to the Saastamoinen one (0 = none).
    pub tropo_scale: f64,
    /// Whether each observation carries the true delays in `iono_delay_m`/`tropo_delay_m`.
    pub report_delays: bool,
}

impl AtmosphereTruth {
    /// No atmosphere at all.
    pub fn vacuum() -> Self {
        Self {
            klobuchar: None,
            iono_scale: 0.0,
            tropo_scale: 0.0,
            report_delays: false,
        }
    }

    /// The broadcast models are the truth (Klobuchar with `klobuchar`, Saastamoinen),
    /// and the observations do not report the delays.
    pub fn models(klobuchar: Klobuchar) -> Self {
        Self {
            klobuchar: Some(klobuchar),
            iono_scale: 1.0,
            tropo_scale: 1.0,
            report_delays: false,
        }
    }
}

/// Noise added to one simulated observation (caller-drawn, so the simulator stays
/// deterministic and independent of any random-number crate).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ObservationNoise {
    /// Added to the pseudo-range (m).
    pub pseudorange_m: f64,
    /// Added to the pseudo-range rate (m/s).
    pub pseudorange_rate_mps: f64,
}

/// The simulated signal's carrier wavelength (GPS L1, m).
pub const L1_WAVELENGTH_M: f64 = crate::earth::SPEED_OF_LIGHT_M_S / 1_575.42e6;

/// Light-time solution: iterations and tolerance (s). Each iteration shrinks the error by
/// about |v_sat| / c ≈ 10⁻⁵.
const LIGHT_TIME_MAX_ITERATIONS: usize = 10;
const LIGHT_TIME_TOLERANCE_S: f64 = 1e-15;

/// The simulated constellation.
#[derive(Debug, Clone, PartialEq)]
pub struct GpsConstellation {
    satellites: Vec<SimSatellite>,
}

impl GpsConstellation {
    /// The baseline 24-slot GPS constellation (see the module notes for the choices).
    pub fn baseline_24() -> Self {
        Self::augmented(0)
    }

    /// The baseline 24 slots plus `extra_per_plane` satellites in each of the six planes,
    /// each placed at the middle of the plane's widest gap in argument of latitude (the
    /// widest gap recomputed after each insertion). PRNs 25, 26, ... go to the extra
    /// satellites plane by plane (A to F), slot names "A5", "A6", ....
    ///
    /// Choice: today's operational GPS flies about 31 satellites, the baseline slots plus
    /// spares near them; the official positions of the spares change with every launch,
    /// so this reproducible gap-filling rule stands in for them. With one extra per plane
    /// (30 satellites) the visible count at mid-latitudes is close to the real one.
    pub fn augmented(extra_per_plane: usize) -> Self {
        let mut slots: Vec<(String, f64, f64)> = GPS_SLOTS
            .iter()
            .map(|&(name, raan, arg_lat)| (name.to_string(), raan, arg_lat))
            .collect();
        for plane in 0..6 {
            let letter = (b'A' + plane as u8) as char;
            let raan_deg = GPS_SLOTS[4 * plane].1;
            let mut arg_lats: Vec<f64> = GPS_SLOTS[4 * plane..4 * plane + 4]
                .iter()
                .map(|s| s.2)
                .collect();
            for extra in 0..extra_per_plane {
                arg_lats.sort_by(f64::total_cmp);
                // Widest gap between consecutive slots, wrapping through 360°.
                let mut best = (0.0, 0.0);
                for (i, &a) in arg_lats.iter().enumerate() {
                    let next = arg_lats.get(i + 1).copied().unwrap_or(arg_lats[0] + 360.0);
                    if next - a > best.0 {
                        best = (next - a, a);
                    }
                }
                let arg_lat = (best.1 + 0.5 * best.0).rem_euclid(360.0);
                arg_lats.push(arg_lat);
                slots.push((format!("{letter}{}", 5 + extra), raan_deg, arg_lat));
            }
        }
        // Extra satellites are pushed plane by plane, so PRN order is the order above.
        let deg = std::f64::consts::PI / 180.0;
        let satellites = slots
            .into_iter()
            .enumerate()
            .map(|(i, (slot, raan_deg, arg_lat_deg))| {
                let k = i as f64 + 1.0;
                // Deterministic "irrational" spreads (golden-ratio fractions).
                let frac1 = (k * 0.618_033_988_75).fract();
                let frac2 = (k * 0.381_966_011_25 + 0.1).fract();
                let eccentricity = 0.002 + 0.012 * frac1;
                let arg_perigee_rad = 2.0 * std::f64::consts::PI * frac2;
                SimSatellite {
                    id: SatId {
                        constellation: Constellation::Gps,
                        prn: (i + 1) as u16,
                    },
                    slot,
                    orbit: KeplerOrbit {
                        semi_major_axis_m: GPS_SEMI_MAJOR_AXIS_M,
                        eccentricity,
                        inclination_rad: GPS_INCLINATION_RAD,
                        raan_rad: raan_deg * deg,
                        arg_perigee_rad,
                        mean_anomaly_at_epoch_rad: arg_lat_deg * deg - arg_perigee_rad,
                    },
                    clock: SatClockModel {
                        bias_s: 3e-4 * (1.9 * k + 0.4).sin(),
                        drift_s_s: 4e-12 * (2.7 * k).cos(),
                    },
                }
            })
            .collect();
        Self { satellites }
    }

    /// All satellites, in PRN order.
    pub fn satellites(&self) -> &[SimSatellite] {
        &self.satellites
    }

    /// The satellite with this id, if simulated.
    pub fn satellite(&self, id: SatId) -> Option<&SimSatellite> {
        self.satellites.iter().find(|s| s.id == id)
    }

    /// GPS time of week (s) of `t_s` seconds after the reference epoch.
    pub fn gps_time_of_week_s(t_s: f64) -> f64 {
        (REFERENCE_EPOCH_GPS_TOW_S + t_s).rem_euclid(SECONDS_PER_WEEK)
    }

    /// Position, velocity (ECEF of time `t_s`) and clock of `sat` at `t_s`.
    ///
    /// Math note: r_e = R3(θ) r_i with θ = θ₀ + ω_e t; differentiating,
    /// v_e = R3(θ) (v_i − ω_e × r_i).
    pub fn state(sat: &SimSatellite, t_s: f64) -> SatState {
        let (r_i, v_i) = sat.orbit.inertial_state(t_s);
        let theta = GREENWICH_ANGLE_AT_EPOCH_RAD + EARTH_RATE_RAD_S * t_s;
        let w_cross_r = Vector3::new(-EARTH_RATE_RAD_S * r_i[1], EARTH_RATE_RAD_S * r_i[0], 0.0);
        let c2 = SPEED_OF_LIGHT_M_S * SPEED_OF_LIGHT_M_S;
        // Relativistic clock term −2 r·v / c² and its rate −2 (v² − GM/r) / c²
        // (two-body acceleration r̈ = −GM r / r³).
        let relativistic_s = -2.0 * r_i.dot(&v_i) / c2;
        let relativistic_rate = -2.0 * (v_i.norm_squared() - GM_M3_S2 / r_i.norm()) / c2;
        SatState {
            pos_ecef_m: rotate_about_earth_axis(&r_i, theta),
            vel_ecef_mps: rotate_about_earth_axis(&(v_i - w_cross_r), theta),
            clock_bias_s: sat.clock.bias_s + sat.clock.drift_s_s * t_s + relativistic_s,
            clock_drift_s_s: sat.clock.drift_s_s + relativistic_rate,
        }
    }

    /// Simulated observation of `sat` by a receiver in state `rx` at true GPS reception
    /// time `t_rx_s`:
    ///   ρ_obs = ρ + b − c·δT_sat(t_tx) + I + T + noise,  ρ̇_obs = ρ̇ + ḃ − c·δṪ_sat + noise,
    ///   λφ = ρ + b − c·δT_sat(t_tx) − I + T (L1, no ambiguity and no noise: the scenario
    ///   adds them, see [`crate::sim::carrier`]).
    /// The transmission time t_tx solves c (t_rx − t_tx) = |R3(ω_e (t_rx − t_tx)) r_s(t_tx)
    /// − r_rx| by iteration, evaluating the orbit at each trial t_tx; the observation
    /// carries the satellite state at t_tx in the ECEF frame of t_tx, as the message
    /// contract says. The rate has no atmospheric-rate term (as the model).
    pub fn simulate_observation(
        sat: &SimSatellite,
        t_rx_s: f64,
        rx: &ReceiverTruth,
        atmosphere: &AtmosphereTruth,
        noise: &ObservationNoise,
    ) -> Result<SatObservation, SimError> {
        let (mut obs, _) = Self::observe(sat, t_rx_s, rx, atmosphere)?;
        if !(noise.pseudorange_m.is_finite() && noise.pseudorange_rate_mps.is_finite()) {
            return Err(SimError::NonFiniteInput { what: "noise" });
        }
        obs.pseudorange_m = obs.pseudorange_m.map(|p| p + noise.pseudorange_m);
        obs.pseudorange_rate_mps = obs
            .pseudorange_rate_mps
            .map(|r| r + noise.pseudorange_rate_mps);
        Ok(obs)
    }

    /// All satellites at or above `elevation_mask_rad` at true reception time `t_rx_s`,
    /// as one epoch (`t_s` = `t_rx_s`, the epoch carries the broadcast Klobuchar
    /// coefficients of `atmosphere`). `noise` is asked once per visible satellite, in PRN
    /// order.
    pub fn simulate_epoch(
        &self,
        t_rx_s: f64,
        rx: &ReceiverTruth,
        atmosphere: &AtmosphereTruth,
        elevation_mask_rad: f64,
        mut noise: impl FnMut(SatId) -> ObservationNoise,
    ) -> Result<GnssEpoch, SimError> {
        let mut satellites = Vec::new();
        for sat in &self.satellites {
            let (obs, elevation_rad) = Self::observe(sat, t_rx_s, rx, atmosphere)?;
            if elevation_rad >= elevation_mask_rad {
                let n = noise(sat.id);
                if !(n.pseudorange_m.is_finite() && n.pseudorange_rate_mps.is_finite()) {
                    return Err(SimError::NonFiniteInput { what: "noise" });
                }
                satellites.push(SatObservation {
                    pseudorange_m: obs.pseudorange_m.map(|p| p + n.pseudorange_m),
                    pseudorange_rate_mps: obs
                        .pseudorange_rate_mps
                        .map(|r| r + n.pseudorange_rate_mps),
                    ..obs
                });
            }
        }
        Ok(GnssEpoch {
            t_s: t_rx_s,
            gps_time_of_week_s: Self::gps_time_of_week_s(t_rx_s),
            satellites,
            klobuchar: atmosphere.klobuchar,
        })
    }

    /// Noise-free observation and the satellite's elevation (rad).
    fn observe(
        sat: &SimSatellite,
        t_rx_s: f64,
        rx: &ReceiverTruth,
        atmosphere: &AtmosphereTruth,
    ) -> Result<(SatObservation, f64), SimError> {
        let finite = t_rx_s.is_finite()
            && rx.pos_ecef_m.iter().all(|x| x.is_finite())
            && rx.vel_ecef_mps.iter().all(|x| x.is_finite())
            && rx.clock_bias_m.is_finite()
            && rx.clock_drift_mps.is_finite();
        if !finite {
            return Err(SimError::NonFiniteInput {
                what: "receiver truth or time",
            });
        }
        let scales_finite = atmosphere.iono_scale.is_finite() && atmosphere.tropo_scale.is_finite();
        if !scales_finite {
            return Err(SimError::NonFiniteInput {
                what: "atmosphere scale",
            });
        }
        let rx_llh = ecef_to_llh(&rx.pos_ecef_m).ok_or(SimError::ReceiverPositionUndefined)?;

        // Light time: τ ← |R3(ω_e τ) r_s(t_rx − τ) − r_rx| / c.
        let mut light_time_s = 0.075;
        let mut converged = false;
        for _ in 0..LIGHT_TIME_MAX_ITERATIONS {
            let tx = Self::state(sat, t_rx_s - light_time_s);
            let rotated = rotate_about_earth_axis(&tx.pos_ecef_m, EARTH_RATE_RAD_S * light_time_s);
            let next = (rotated - rx.pos_ecef_m).norm() / SPEED_OF_LIGHT_M_S;
            let step = (next - light_time_s).abs();
            light_time_s = next;
            if step < LIGHT_TIME_TOLERANCE_S {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(SimError::TransmissionTimeNotConverged {
                sat: sat.id,
                t_rx_s,
            });
        }
        let tx = Self::state(sat, t_rx_s - light_time_s);
        let rotated = rotate_about_earth_axis(&tx.pos_ecef_m, EARTH_RATE_RAD_S * light_time_s);
        let range_m = (rotated - rx.pos_ecef_m).norm();

        let geometry = line_of_sight(
            sat.id,
            &tx.pos_ecef_m,
            &tx.vel_ecef_mps,
            &rx.pos_ecef_m,
            &rx.vel_ecef_mps,
        )?;
        let (elevation_rad, azimuth_rad) = elevation_azimuth(&rx_llh, &geometry.los_ecef);
        let tow_s = Self::gps_time_of_week_s(t_rx_s);
        let iono_m = atmosphere.klobuchar.map_or(0.0, |k| {
            atmosphere.iono_scale
                * klobuchar_delay_m(&k, &rx_llh, azimuth_rad, elevation_rad, tow_s)
        });
        let tropo_m = atmosphere.tropo_scale * saastamoinen_delay_m(&rx_llh, elevation_rad);

        let c = SPEED_OF_LIGHT_M_S;
        let obs = SatObservation {
            sat: sat.id,
            pseudorange_m: Some(range_m + rx.clock_bias_m - c * tx.clock_bias_s + iono_m + tropo_m),
            pseudorange_rate_mps: Some(
                geometry.range_rate_mps + rx.clock_drift_mps - c * tx.clock_drift_s_s,
            ),
            pseudorange_sigma_m: None,
            pseudorange_rate_sigma_mps: None,
            cn0_dbhz: None,
            sat_pos_ecef_m: tx.pos_ecef_m,
            sat_vel_ecef_mps: tx.vel_ecef_mps,
            sat_clock_bias_s: tx.clock_bias_s,
            sat_clock_drift_s_s: tx.clock_drift_s_s,
            iono_delay_m: atmosphere.report_delays.then_some(iono_m),
            tropo_delay_m: atmosphere.report_delays.then_some(tropo_m),
            carrier_phase: Some(CarrierPhase {
                cycles: (range_m + rx.clock_bias_m - c * tx.clock_bias_s - iono_m + tropo_m)
                    / L1_WAVELENGTH_M,
                wavelength_m: Some(L1_WAVELENGTH_M),
                sigma_cycles: None,
                lock_time_s: None,
                loss_of_lock: false,
                half_cycle_unresolved: false,
            }),
        };
        Ok((obs, elevation_rad))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::{llh_to_ecef, Llh};

    fn receiver(p: &Llh) -> ReceiverTruth {
        ReceiverTruth {
            pos_ecef_m: llh_to_ecef(p),
            vel_ecef_mps: Vector3::zeros(),
            clock_bias_m: 0.0,
            clock_drift_mps: 0.0,
        }
    }

    /// Visible counts above 10° every 15 min over one day at four mid-latitude sites.
    fn visible_counts(c: &GpsConstellation) -> Vec<usize> {
        let mut counts = Vec::new();
        for (lat, lon) in [(45.0, 10.0), (40.0, -105.0), (-35.0, 149.0), (52.0, 0.0)] {
            let rx = receiver(&Llh::from_degrees(lat, lon, 100.0));
            for k in 0..96 {
                let epoch = c
                    .simulate_epoch(
                        900.0 * k as f64,
                        &rx,
                        &AtmosphereTruth::vacuum(),
                        10f64.to_radians(),
                        |_| ObservationNoise::default(),
                    )
                    .unwrap();
                counts.push(epoch.satellites.len());
            }
        }
        counts
    }

    #[test]
    fn enough_satellites_are_visible_at_mid_latitudes() {
        // Baseline 24 slots: the constellation is designed for ≥ 4 satellites everywhere;
        // on average about 0.30 · 24 ≈ 7 are above 10° (the fraction of the orbit sphere
        // above a 10° mask).
        let baseline = visible_counts(&GpsConstellation::baseline_24());
        assert!(baseline.iter().all(|&n| n >= 4), "{baseline:?}");
        let mean = baseline.iter().sum::<usize>() as f64 / baseline.len() as f64;
        assert!((6.3..7.5).contains(&mean), "{mean}");
        // 30 satellites (like today's operational constellation): ≥ 5 always, ≥ 8 most
        // of the time.
        let thirty = visible_counts(&GpsConstellation::augmented(1));
        assert!(thirty.iter().all(|&n| n >= 5), "{thirty:?}");
        let share_8 = thirty.iter().filter(|&&n| n >= 8).count() as f64 / thirty.len() as f64;
        assert!(share_8 > 0.7, "{share_8}");
        // 36 satellites: ≥ 6 always, ≥ 8 nearly always.
        let thirty_six = visible_counts(&GpsConstellation::augmented(2));
        assert!(thirty_six.iter().all(|&n| n >= 6), "{thirty_six:?}");
        let share_8 =
            thirty_six.iter().filter(|&&n| n >= 8).count() as f64 / thirty_six.len() as f64;
        assert!(share_8 > 0.95, "{share_8}");
    }

    #[test]
    fn augmented_constellation_fills_the_widest_gaps() {
        let c = GpsConstellation::augmented(1);
        assert_eq!(c.satellites().len(), 30);
        let a5 = &c.satellites()[24];
        assert_eq!((a5.slot.as_str(), a5.id.prn), ("A5", 25));
        // Plane A slots at 11.676, 41.806, 161.786, 268.126°: gaps 30.13, 119.98, 106.34,
        // 103.55°; the widest, 41.806 → 161.786, has its middle at 101.796°.
        let mean_arg_lat = a5.orbit.mean_anomaly_at_epoch_rad + a5.orbit.arg_perigee_rad;
        assert!((mean_arg_lat.to_degrees() - 101.796).abs() < 1e-9);
        assert!(c.satellite(a5.id).is_some());
    }

    #[test]
    fn orbit_has_gps_period_radius_and_consistent_velocity() {
        let c = GpsConstellation::baseline_24();
        for sat in c.satellites() {
            let o = &sat.orbit;
            let period = 2.0 * std::f64::consts::PI / o.mean_motion_rad_s();
            // Half a sidereal day: 11 h 58 min (43 082 s) within a few seconds.
            assert!((period - 43_082.0).abs() < 10.0, "{period}");
            let (r0, _) = o.inertial_state(1000.0);
            let (r1, _) = o.inertial_state(1000.0 + period);
            assert!((r0 - r1).norm() < 1e-5);
            for t in [0.0, 5000.0, 20_000.0] {
                let (r, v) = o.inertial_state(t);
                let a = o.semi_major_axis_m;
                assert!(r.norm() >= a * (1.0 - o.eccentricity) - 1e-3);
                assert!(r.norm() <= a * (1.0 + o.eccentricity) + 1e-3);
                // Vis-viva: v² = GM (2/r − 1/a).
                let vv = GM_M3_S2 * (2.0 / r.norm() - 1.0 / a);
                assert!((v.norm_squared() - vv).abs() / vv < 1e-12);
                // Inclination of the orbit normal.
                let h = r.cross(&v).normalize();
                assert!((h[2].acos() - GPS_INCLINATION_RAD).abs() < 1e-12);
                // ECEF velocity and clock drift against central differences.
                let dt = 0.5;
                let sp = GpsConstellation::state(sat, t + dt);
                let sm = GpsConstellation::state(sat, t - dt);
                let s0 = GpsConstellation::state(sat, t);
                let fd_v = (sp.pos_ecef_m - sm.pos_ecef_m) / (2.0 * dt);
                assert!(
                    (fd_v - s0.vel_ecef_mps).norm() < 1e-4,
                    "{}",
                    (fd_v - s0.vel_ecef_mps).norm()
                );
                let fd_clock = (sp.clock_bias_s - sm.clock_bias_s) / (2.0 * dt);
                assert!((fd_clock - s0.clock_drift_s_s).abs() < 1e-15);
                // ECEF position stays at the inertial radius.
                assert!((s0.pos_ecef_m.norm() - o.inertial_state(t).0.norm()).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn simulated_rate_is_the_time_derivative_of_the_simulated_pseudorange() {
        let c = GpsConstellation::augmented(1);
        let p = Llh::from_degrees(45.0, 10.0, 300.0);
        let v = Vector3::new(12.0, -30.0, 1.5);
        let truth = |t: f64| ReceiverTruth {
            pos_ecef_m: llh_to_ecef(&p) + v * t,
            vel_ecef_mps: v,
            clock_bias_m: 3000.0 + 25.0 * t,
            clock_drift_mps: 25.0,
        };
        let t0 = 7200.0;
        let epoch = c
            .simulate_epoch(t0, &truth(0.0), &AtmosphereTruth::vacuum(), 0.0, |_| {
                ObservationNoise::default()
            })
            .unwrap();
        assert!(epoch.satellites.len() >= 5);
        let h = 0.01;
        let none = ObservationNoise::default();
        let vacuum = AtmosphereTruth::vacuum();
        for obs in &epoch.satellites {
            let sat = c.satellite(obs.sat).unwrap();
            let plus =
                GpsConstellation::simulate_observation(sat, t0 + h, &truth(h), &vacuum, &none)
                    .unwrap();
            let minus =
                GpsConstellation::simulate_observation(sat, t0 - h, &truth(-h), &vacuum, &none)
                    .unwrap();
            let fd = (plus.pseudorange_m.unwrap() - minus.pseudorange_m.unwrap()) / (2.0 * h);
            let rate = obs.pseudorange_rate_mps.unwrap();
            assert!((fd - rate).abs() < 2e-5, "{}: {fd} vs {rate}", obs.sat);
        }
    }

    #[test]
    fn noise_is_added_as_given_and_bad_inputs_are_typed_errors() {
        let c = GpsConstellation::baseline_24();
        let rx = receiver(&Llh::from_degrees(45.0, 10.0, 0.0));
        let sat = &c.satellites()[0];
        let atmosphere = AtmosphereTruth::vacuum();
        let clean = GpsConstellation::simulate_observation(
            sat,
            100.0,
            &rx,
            &atmosphere,
            &ObservationNoise::default(),
        )
        .unwrap();
        let noisy = GpsConstellation::simulate_observation(
            sat,
            100.0,
            &rx,
            &atmosphere,
            &ObservationNoise {
                pseudorange_m: 1.5,
                pseudorange_rate_mps: -0.25,
            },
        )
        .unwrap();
        assert_eq!(
            noisy.pseudorange_m.unwrap() - clean.pseudorange_m.unwrap(),
            1.5
        );
        assert_eq!(
            noisy.pseudorange_rate_mps.unwrap() - clean.pseudorange_rate_mps.unwrap(),
            -0.25
        );
        let centre = ReceiverTruth {
            pos_ecef_m: Vector3::zeros(),
            ..rx
        };
        assert_eq!(
            GpsConstellation::simulate_observation(
                sat,
                100.0,
                &centre,
                &atmosphere,
                &ObservationNoise::default()
            ),
            Err(SimError::ReceiverPositionUndefined)
        );
        assert!(matches!(
            GpsConstellation::simulate_observation(
                sat,
                f64::NAN,
                &rx,
                &atmosphere,
                &ObservationNoise::default()
            ),
            Err(SimError::NonFiniteInput { .. })
        ));
    }

    #[test]
    fn reported_delays_and_time_of_week() {
        let c = GpsConstellation::baseline_24();
        let rx = receiver(&Llh::from_degrees(45.0, 10.0, 0.0));
        let k = Klobuchar {
            alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -1.1921e-7],
            beta: [1.1469e5, 0.0, -1.9661e5, -6.5536e4],
        };
        let mut atmosphere = AtmosphereTruth::models(k);
        let silent = c
            .simulate_epoch(0.0, &rx, &atmosphere, 0.1, |_| ObservationNoise::default())
            .unwrap();
        atmosphere.report_delays = true;
        let reported = c
            .simulate_epoch(0.0, &rx, &atmosphere, 0.1, |_| ObservationNoise::default())
            .unwrap();
        assert_eq!(silent.klobuchar, Some(k));
        for (a, b) in silent.satellites.iter().zip(&reported.satellites) {
            assert!(a.iono_delay_m.is_none() && a.tropo_delay_m.is_none());
            assert_eq!(a.pseudorange_m, b.pseudorange_m);
            assert!(b.iono_delay_m.unwrap() > 0.0 && b.tropo_delay_m.unwrap() > 2.0);
        }
        assert_eq!(GpsConstellation::gps_time_of_week_s(0.0), 345_609.0);
        assert_eq!(
            GpsConstellation::gps_time_of_week_s(604_800.0 - 345_609.0),
            0.0
        );
    }
}
