//! Broadcast Keplerian ephemeris → satellite position, velocity and clock.
//!
//! One algorithm serves GPS LNAV (IS-GPS-200 20.3.3.4.3, Table 20-IV; also QZSS), Galileo
//! I/NAV and F/NAV (Galileo OS SIS ICD 5.1.1) and BeiDou D1/D2 (BDS-SIS-ICD 5.2.4.12), with
//! each system's constants. BeiDou GEO satellites (PRN 1–5 and 59–63) take the ICD's
//! special case: the orbit is computed in an inertial-like frame and then rotated by
//! R_Z(ω_e t_k) R_X(−5°) into CGCS2000. GLONASS (a numerically integrated state vector,
//! not Keplerian elements) is not handled.
//!
//! Velocity is the analytic time derivative of the position formulas (checked against a
//! central difference in the tests); the clock drift is the derivative of the clock
//! polynomial plus the derivative of the relativistic term.

use nalgebra::{Matrix3, Vector3};

use super::time::GpsTime;
use crate::earth::SPEED_OF_LIGHT_M_S;
use crate::gnss::satellite_bounds::plausible_satellite_state;
use crate::gnss::{Constellation, SatId};

/// Kepler-equation iterations: Newton from E = M converges quadratically; 10 steps
/// reach machine precision for any e < 0.9 (broadcast orbits have e < 0.03).
const KEPLER_ITERATIONS: usize = 10;
/// Stop the Kepler iteration once the correction is below this (rad).
const KEPLER_TOLERANCE_RAD: f64 = 1e-15;
/// Inclination of the BeiDou GEO reference frame about X (BDS ICD: −5°).
const BDS_GEO_TILT_RAD: f64 = -5.0 * std::f64::consts::PI / 180.0;

/// Which broadcast message the ephemeris came from (decides constants, clock reference and
/// validity window).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NavSource {
    /// GPS L1 C/A legacy navigation message.
    GpsLnav,
    /// QZSS LNAV (GPS-compatible).
    QzssLnav,
    /// Galileo I/NAV (E1-B / E5b-I); clock referred to the E1/E5b combination.
    GalileoInav,
    /// Galileo F/NAV (E5a-I); clock referred to the E1/E5a combination.
    GalileoFnav,
    /// BeiDou D1 (MEO/IGSO); clock referred to B3I.
    BeidouD1,
    /// BeiDou D2 (GEO); clock referred to B3I.
    BeidouD2,
}

/// Physical constants an ICD prescribes for its user algorithm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SystemConstants {
    /// Gravitational constant μ (m³/s²).
    pub gm_m3_s2: f64,
    /// Earth rotation rate Ω̇_e (rad/s).
    pub earth_rate_rad_s: f64,
}

/// IS-GPS-200: μ = 3.986005e14, Ω̇_e = 7.2921151467e-5.
pub const GPS_CONSTANTS: SystemConstants = SystemConstants {
    gm_m3_s2: 3.986_005e14,
    earth_rate_rad_s: 7.292_115_146_7e-5,
};
/// Galileo OS SIS ICD (GTRF): μ = 3.986004418e14, Ω̇_e = 7.2921151467e-5.
pub const GALILEO_CONSTANTS: SystemConstants = SystemConstants {
    gm_m3_s2: 3.986_004_418e14,
    earth_rate_rad_s: 7.292_115_146_7e-5,
};
/// BDS ICD (CGCS2000): μ = 3.986004418e14, Ω̇_e = 7.2921150e-5.
pub const BEIDOU_CONSTANTS: SystemConstants = SystemConstants {
    gm_m3_s2: 3.986_004_418e14,
    earth_rate_rad_s: 7.292_115_0e-5,
};

impl NavSource {
    /// The constellation this message belongs to.
    pub fn constellation(self) -> Constellation {
        match self {
            Self::GpsLnav => Constellation::Gps,
            Self::QzssLnav => Constellation::Qzss,
            Self::GalileoInav | Self::GalileoFnav => Constellation::Galileo,
            Self::BeidouD1 | Self::BeidouD2 => Constellation::Beidou,
        }
    }

    /// The ICD constants of the user algorithm.
    pub fn constants(self) -> SystemConstants {
        match self {
            Self::GpsLnav | Self::QzssLnav => GPS_CONSTANTS,
            Self::GalileoInav | Self::GalileoFnav => GALILEO_CONSTANTS,
            Self::BeidouD1 | Self::BeidouD2 => BEIDOU_CONSTANTS,
        }
    }
}

/// Group delays broadcast with the clock, by system (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GroupDelay {
    /// GPS/QZSS LNAV T_GD (L1 C/A correction; the L1/L2 P(Y) clock reference).
    Gps { tgd_s: f64 },
    /// Galileo BGD(E1,E5a) (I/NAV and F/NAV) and BGD(E1,E5b) (I/NAV only).
    Galileo {
        bgd_e1_e5a_s: f64,
        bgd_e1_e5b_s: Option<f64>,
    },
    /// BeiDou T_GD1 (B1I) and T_GD2 (B2I); the clock refers to B3I.
    Beidou { tgd1_s: f64, tgd2_s: f64 },
}

/// Broadcast ephemeris and clock of one satellite, in SI units, reference times in GPST.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeplerianEphemeris {
    /// The satellite.
    pub sat: SatId,
    /// The message it came from.
    pub source: NavSource,
    /// Reference time of the ephemeris, in GPST (converted from GST/BDT).
    pub toe: GpsTime,
    /// Reference time of the clock, in GPST.
    pub toc: GpsTime,
    /// Square root of the semi-major axis (√m).
    pub sqrt_a_sqrt_m: f64,
    /// Eccentricity.
    pub eccentricity: f64,
    /// Inclination at toe i₀ (rad).
    pub inclination_rad: f64,
    /// Rate of inclination (rad/s).
    pub inclination_rate_rad_s: f64,
    /// Longitude of the ascending node at the week start Ω₀ (rad).
    pub raan_rad: f64,
    /// Rate of right ascension Ω̇ (rad/s).
    pub raan_rate_rad_s: f64,
    /// Argument of perigee ω (rad).
    pub arg_perigee_rad: f64,
    /// Mean anomaly at toe M₀ (rad).
    pub mean_anomaly_rad: f64,
    /// Mean motion difference Δn (rad/s).
    pub mean_motion_diff_rad_s: f64,
    /// Harmonic corrections: argument of latitude (rad).
    pub cuc_rad: f64,
    /// Harmonic corrections: argument of latitude (rad).
    pub cus_rad: f64,
    /// Harmonic corrections: orbit radius (m).
    pub crc_m: f64,
    /// Harmonic corrections: orbit radius (m).
    pub crs_m: f64,
    /// Harmonic corrections: inclination (rad).
    pub cic_rad: f64,
    /// Harmonic corrections: inclination (rad).
    pub cis_rad: f64,
    /// Clock bias a_f0 (s).
    pub af0_s: f64,
    /// Clock drift a_f1 (s/s).
    pub af1_s_s: f64,
    /// Clock drift rate a_f2 (s/s²).
    pub af2_s_s2: f64,
    /// Group delays broadcast with the clock.
    pub group_delay: GroupDelay,
    /// Issue of data (GPS IODE, Galileo IODnav, BeiDou AODE).
    pub issue_of_data: u16,
    /// Raw health word (GPS 6-bit health, Galileo HS/DVS bits, BeiDou SatH1); 0 = healthy.
    pub health: u16,
    /// Validity half-window about toe (s): the ephemeris is used for |t − toe| ≤ this.
    pub validity_s: f64,
}

/// Satellite state from the broadcast ephemeris at one GPST instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatState {
    /// Position in the ECEF frame of the evaluation time (m).
    pub pos_ecef_m: Vector3<f64>,
    /// Velocity in ECEF (m/s).
    pub vel_ecef_mps: Vector3<f64>,
    /// Clock offset a_f0 + a_f1 Δt + a_f2 Δt² + Δt_r, group delay NOT applied (s).
    pub clock_bias_s: f64,
    /// Clock drift, relativistic rate included (s/s).
    pub clock_drift_s_s: f64,
    /// The relativistic term Δt_r = F e √A sin E_k alone (s).
    pub relativistic_s: f64,
    /// Eccentric anomaly E_k (rad).
    pub eccentric_anomaly_rad: f64,
}

impl KeplerianEphemeris {
    /// Whether this is a BeiDou GEO satellite (PRN 1–5 and 59–63), which takes the ICD's
    /// rotated-frame algorithm.
    pub fn is_beidou_geo(&self) -> bool {
        self.sat.constellation == Constellation::Beidou && matches!(self.sat.prn, 1..=5 | 59..=63)
    }

    /// Whether all elements are finite and the orbit is elliptic with a positive axis.
    pub fn is_valid(&self) -> bool {
        let values = [
            self.sqrt_a_sqrt_m,
            self.eccentricity,
            self.inclination_rad,
            self.inclination_rate_rad_s,
            self.raan_rad,
            self.raan_rate_rad_s,
            self.arg_perigee_rad,
            self.mean_anomaly_rad,
            self.mean_motion_diff_rad_s,
            self.cuc_rad,
            self.cus_rad,
            self.crc_m,
            self.crs_m,
            self.cic_rad,
            self.cis_rad,
            self.af0_s,
            self.af1_s_s,
            self.af2_s_s2,
        ];
        values.iter().all(|v| v.is_finite())
            && self.toe.is_finite()
            && self.toc.is_finite()
            && self.sqrt_a_sqrt_m > 0.0
            && (0.0..1.0).contains(&self.eccentricity)
    }

    /// Satellite position, velocity and clock at GPST `t` (the transmission time). None if
    /// the ephemeris is not valid (see [`Self::is_valid`]), `t` is not finite, or the
    /// result lies outside the bounds of any GNSS orbit and clock (corrupt elements).
    ///
    /// Math note (time of the ephemeris): t_k = t − toe uses GPST on both sides; for
    /// BeiDou and Galileo the reference times were converted to GPST, so t_k equals the
    /// ICD's BDT/GST difference exactly.
    pub fn state_at(&self, t: &GpsTime) -> Option<SatState> {
        if !self.is_valid() || !t.is_finite() {
            return None;
        }
        let constants = self.source.constants();
        let tk = t.seconds_since(&self.toe);
        let a = self.sqrt_a_sqrt_m * self.sqrt_a_sqrt_m;
        let e = self.eccentricity;
        let n0 = (constants.gm_m3_s2 / (a * a * a)).sqrt();
        let n = n0 + self.mean_motion_diff_rad_s;
        let mk = self.mean_anomaly_rad + n * tk;
        let ek = solve_kepler(mk, e);
        let (sin_e, cos_e) = ek.sin_cos();
        let one_minus_ecos = 1.0 - e * cos_e;
        let ek_dot = n / one_minus_ecos;

        // True anomaly and argument of latitude.
        let sqrt_1me2 = (1.0 - e * e).sqrt();
        let nu = (sqrt_1me2 * sin_e).atan2(cos_e - e);
        let nu_dot = ek_dot * sqrt_1me2 / one_minus_ecos;
        let phi = nu + self.arg_perigee_rad;
        let (sin2p, cos2p) = (2.0 * phi).sin_cos();
        let du = self.cus_rad * sin2p + self.cuc_rad * cos2p;
        let dr = self.crs_m * sin2p + self.crc_m * cos2p;
        let di = self.cis_rad * sin2p + self.cic_rad * cos2p;
        let u = phi + du;
        let r = a * one_minus_ecos + dr;
        let i = self.inclination_rad + di + self.inclination_rate_rad_s * tk;
        let u_dot = nu_dot * (1.0 + 2.0 * (self.cus_rad * cos2p - self.cuc_rad * sin2p));
        let r_dot =
            a * e * sin_e * ek_dot + 2.0 * nu_dot * (self.crs_m * cos2p - self.crc_m * sin2p);
        let i_dot = self.inclination_rate_rad_s
            + 2.0 * nu_dot * (self.cis_rad * cos2p - self.cic_rad * sin2p);

        // Position and velocity in the orbital plane.
        let (sin_u, cos_u) = u.sin_cos();
        let xp = r * cos_u;
        let yp = r * sin_u;
        let xp_dot = r_dot * cos_u - r * u_dot * sin_u;
        let yp_dot = r_dot * sin_u + r * u_dot * cos_u;

        let toe_sow = self.toe_seconds_of_week();
        let geo = self.is_beidou_geo();
        // Longitude of the ascending node: in ECEF for the GPS-like case; in the inertial-
        // like frame of the epoch t (no −Ω̇_e t_k term) for BeiDou GEO.
        let (omega, omega_dot) = if geo {
            (
                self.raan_rad + self.raan_rate_rad_s * tk - constants.earth_rate_rad_s * toe_sow,
                self.raan_rate_rad_s,
            )
        } else {
            (
                self.raan_rad + (self.raan_rate_rad_s - constants.earth_rate_rad_s) * tk
                    - constants.earth_rate_rad_s * toe_sow,
                self.raan_rate_rad_s - constants.earth_rate_rad_s,
            )
        };
        let (sin_o, cos_o) = omega.sin_cos();
        let (sin_i, cos_i) = i.sin_cos();
        let pos = Vector3::new(
            xp * cos_o - yp * cos_i * sin_o,
            xp * sin_o + yp * cos_i * cos_o,
            yp * sin_i,
        );
        let vel = Vector3::new(
            xp_dot * cos_o - yp_dot * cos_i * sin_o + yp * sin_i * sin_o * i_dot
                - pos[1] * omega_dot,
            xp_dot * sin_o + yp_dot * cos_i * cos_o - yp * sin_i * cos_o * i_dot
                + pos[0] * omega_dot,
            yp_dot * sin_i + yp * cos_i * i_dot,
        );
        let (pos_ecef_m, vel_ecef_mps) = if geo {
            geo_to_ecef(&pos, &vel, constants.earth_rate_rad_s, tk)
        } else {
            (pos, vel)
        };

        // Clock: polynomial about toc plus the relativistic term (ICD 20.3.3.3.3.1).
        let f = -2.0 * constants.gm_m3_s2.sqrt() / (SPEED_OF_LIGHT_M_S * SPEED_OF_LIGHT_M_S);
        let relativistic_s = f * e * self.sqrt_a_sqrt_m * sin_e;
        let relativistic_rate = f * e * self.sqrt_a_sqrt_m * cos_e * ek_dot;
        let dtc = t.seconds_since(&self.toc);
        let clock_bias_s =
            self.af0_s + self.af1_s_s * dtc + self.af2_s_s2 * dtc * dtc + relativistic_s;
        let clock_drift_s_s = self.af1_s_s + 2.0 * self.af2_s_s2 * dtc + relativistic_rate;
        if !plausible_satellite_state(&pos_ecef_m, &vel_ecef_mps, clock_bias_s, clock_drift_s_s) {
            return None;
        }
        Some(SatState {
            pos_ecef_m,
            vel_ecef_mps,
            clock_bias_s,
            clock_drift_s_s,
            relativistic_s,
            eccentric_anomaly_rad: ek,
        })
    }

    /// toe as seconds of the system's own week (GPS/GST week; BDT week for BeiDou), the
    /// quantity the ICDs multiply by Ω̇_e.
    fn toe_seconds_of_week(&self) -> f64 {
        match self.source {
            NavSource::BeidouD1 | NavSource::BeidouD2 => {
                let bdt = self.toe.tow_s + super::time::BDT_MINUS_GPST_S;
                bdt.rem_euclid(super::time::SECONDS_PER_WEEK)
            }
            _ => self.toe.tow_s,
        }
    }
}

/// Eccentric anomaly from the mean anomaly by Newton's method on M = E − e sin E.
fn solve_kepler(mean_anomaly_rad: f64, e: f64) -> f64 {
    let mut ek = mean_anomaly_rad;
    for _ in 0..KEPLER_ITERATIONS {
        let step = (ek - e * ek.sin() - mean_anomaly_rad) / (1.0 - e * ek.cos());
        ek -= step;
        if step.abs() < KEPLER_TOLERANCE_RAD {
            break;
        }
    }
    ek
}

/// BDS ICD GEO case: r = R_Z(Ω̇_e t_k) R_X(−5°) r_GK, and its time derivative
/// v = Ṙ_Z R_X r_GK + R_Z R_X v_GK, with R_X(φ) = [[1,0,0],[0,cos φ,sin φ],[0,−sin φ,cos φ]]
/// and R_Z(φ) = [[cos φ,sin φ,0],[−sin φ,cos φ,0],[0,0,1]].
fn geo_to_ecef(
    pos_gk: &Vector3<f64>,
    vel_gk: &Vector3<f64>,
    earth_rate_rad_s: f64,
    tk: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let (sx, cx) = BDS_GEO_TILT_RAD.sin_cos();
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cx, sx, 0.0, -sx, cx);
    let angle = earth_rate_rad_s * tk;
    let (sz, cz) = angle.sin_cos();
    let rz = Matrix3::new(cz, sz, 0.0, -sz, cz, 0.0, 0.0, 0.0, 1.0);
    let rz_dot = earth_rate_rad_s * Matrix3::new(-sz, cz, 0.0, -cz, -sz, 0.0, 0.0, 0.0, 0.0);
    let tilted_pos = rx * pos_gk;
    (rz * tilted_pos, rz_dot * tilted_pos + rz * (rx * vel_gk))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// G32 of the walk_0827 navigation file (RINEX values), toe 2381/410400.
    pub(crate) fn g32() -> KeplerianEphemeris {
        KeplerianEphemeris {
            sat: SatId {
                constellation: Constellation::Gps,
                prn: 32,
            },
            source: NavSource::GpsLnav,
            toe: GpsTime::new(2381, 410_400.0),
            toc: GpsTime::new(2381, 410_400.0),
            sqrt_a_sqrt_m: 0.515364527702e4,
            eccentricity: 0.863428541925e-2,
            inclination_rad: 0.965781992719,
            inclination_rate_rad_s: 0.971469037013e-10,
            raan_rad: 0.224492021439e1,
            raan_rate_rad_s: -0.795997442203e-8,
            arg_perigee_rad: -0.206125929204e1,
            mean_anomaly_rad: 0.273480178381e1,
            mean_motion_diff_rad_s: 0.471448209139e-8,
            cuc_rad: -0.897794961929e-6,
            cus_rad: 0.561214983463e-5,
            crc_m: 0.271718750000e3,
            crs_m: -0.167812500000e2,
            cic_rad: 0.111758708954e-7,
            cis_rad: -0.162050127983e-6,
            af0_s: -0.344484578818e-3,
            af1_s_s: 0.131876731757e-10,
            af2_s_s2: 0.0,
            group_delay: GroupDelay::Gps {
                tgd_s: 0.931322574615e-9,
            },
            issue_of_data: 83,
            health: 0,
            validity_s: 7_200.0,
        }
    }

    #[test]
    fn orbit_radius_period_and_relativistic_term_are_those_of_a_gps_orbit() {
        let eph = g32();
        let a = eph.sqrt_a_sqrt_m.powi(2);
        let e = eph.eccentricity;
        // IS-GPS-200: semi-major axis ≈ 26 560 km, period half a sidereal day (≈ 43 082 s).
        let period_s = 2.0 * std::f64::consts::PI * (a.powi(3) / GPS_CONSTANTS.gm_m3_s2).sqrt();
        assert!((period_s - 43_082.0).abs() < 20.0, "{period_s}");
        let f = -4.442_807_633e-10; // F of IS-GPS-200 20.3.3.3.3.1 (s/√m)
        let bound_s = (f * e * eph.sqrt_a_sqrt_m).abs();
        let mut max_rel = 0.0f64;
        for k in 0..=48 {
            let t = eph.toe.add_seconds(-7_200.0 + 300.0 * f64::from(k));
            let s = eph.state_at(&t).unwrap();
            let r = s.pos_ecef_m.norm();
            // Radius within the ellipse's bounds (± harmonic corrections of < 1 km).
            assert!(r > a * (1.0 - e) - 1e3 && r < a * (1.0 + e) + 1e3, "{r}");
            assert!(s.relativistic_s.abs() <= bound_s * (1.0 + 1e-9));
            max_rel = max_rel.max(s.relativistic_s.abs());
            // ECEF speed of a GPS satellite: about 3.9 km/s ± the earth-rotation term.
            let v = s.vel_ecef_mps.norm();
            assert!(v > 2_500.0 && v < 4_200.0, "{v}");
        }
        // Over two hours E sweeps ~60°: the term reaches a good part of its bound (≈ 19.8 ns).
        assert!((bound_s - 19.77e-9).abs() < 0.05e-9, "{bound_s}");
        assert!(max_rel > 0.5 * bound_s);
    }

    #[test]
    fn corrupt_but_finite_elements_give_no_satellite() {
        let t = g32().toe.add_seconds(60.0);
        assert!(g32().state_at(&t).is_some());
        let corruptions: [fn(&mut KeplerianEphemeris); 5] = [
            |e| e.sqrt_a_sqrt_m = 1e29,
            |e| e.crs_m = 1e59,
            |e| e.sqrt_a_sqrt_m = 100.0,
            |e| e.af0_s = 1e3,
            |e| e.af1_s_s = 1e-3,
        ];
        for (k, corrupt) in corruptions.iter().enumerate() {
            let mut eph = g32();
            corrupt(&mut eph);
            assert!(
                eph.is_valid(),
                "corruption {k} is finite and passes is_valid"
            );
            assert_eq!(eph.state_at(&t), None, "corruption {k}");
        }
    }

    fn central_difference(eph: &KeplerianEphemeris, t: &GpsTime) -> (Vector3<f64>, f64) {
        let h = 0.5;
        let p = eph.state_at(&t.add_seconds(h)).unwrap();
        let m = eph.state_at(&t.add_seconds(-h)).unwrap();
        (
            (p.pos_ecef_m - m.pos_ecef_m) / (2.0 * h),
            (p.clock_bias_s - m.clock_bias_s) / (2.0 * h),
        )
    }

    #[test]
    fn velocity_and_clock_drift_equal_the_central_difference() {
        let mut eph = g32();
        eph.af2_s_s2 = 1e-18;
        for k in 0..10 {
            let t = eph.toe.add_seconds(-7_000.0 + 1_500.0 * f64::from(k));
            let s = eph.state_at(&t).unwrap();
            let (v, drift) = central_difference(&eph, &t);
            // Central difference error ~ h² |r⃛| / 6 ≈ 1e-4 m/s at h = 0.5 s.
            assert!(
                (s.vel_ecef_mps - v).norm() < 1e-3,
                "{} vs {}",
                s.vel_ecef_mps,
                v
            );
            assert!((s.clock_drift_s_s - drift).abs() < 1e-15);
        }
    }

    /// A BeiDou GEO whose broadcast elements describe a satellite fixed over longitude
    /// 110.5° E in CGCS2000: circular orbit at the geostationary radius, inclined 5° in the
    /// ICD's tilted reference frame, node at Ω_k = π (see the test below).
    fn geo() -> KeplerianEphemeris {
        let w = BEIDOU_CONSTANTS.earth_rate_rad_s;
        let a = (BEIDOU_CONSTANTS.gm_m3_s2 / (w * w)).cbrt();
        let toe = GpsTime::from_bdt(1025, 406_800.0);
        let mut eph = g32();
        eph.sat = SatId {
            constellation: Constellation::Beidou,
            prn: 3,
        };
        eph.source = NavSource::BeidouD2;
        eph.toe = toe;
        eph.toc = toe;
        eph.sqrt_a_sqrt_m = a.sqrt();
        eph.eccentricity = 0.0;
        eph.inclination_rad = 5f64.to_radians();
        eph.inclination_rate_rad_s = 0.0;
        // Ω_k = Ω₀ + Ω̇ t_k − Ω̇_e toe = π at toe, fixed in the tilted inertial frame.
        eph.raan_rad = std::f64::consts::PI + w * 406_800.0;
        eph.raan_rate_rad_s = 0.0;
        eph.arg_perigee_rad = 0.0;
        eph.mean_anomaly_rad = 0.0;
        eph.mean_motion_diff_rad_s = 0.0;
        eph.cuc_rad = 0.0;
        eph.cus_rad = 0.0;
        eph.crc_m = 0.0;
        eph.crs_m = 0.0;
        eph.cic_rad = 0.0;
        eph.cis_rad = 0.0;
        eph.group_delay = GroupDelay::Beidou {
            tgd1_s: 0.0,
            tgd2_s: 0.0,
        };
        eph
    }

    #[test]
    fn beidou_geo_case_keeps_a_geostationary_satellite_fixed_over_the_equator() {
        // Math note: in the tilted frame the orbit is r_GK = a(−cos u, −sin u cos 5°,
        // sin u sin 5°) (node at Ω = π); R_X(−5°) turns it into a(−cos u, −sin u, 0), an
        // equatorial circle traversed at ω_e, which R_Z(ω_e t_k) freezes in ECEF. So the
        // ICD algorithm must give a fixed point on the equator; the GPS-like algorithm on
        // the same elements gives a 5°-inclined orbit instead.
        let eph = geo();
        assert!(eph.is_beidou_geo());
        let start = eph.state_at(&eph.toe).unwrap();
        for k in 0..=24 {
            let t = eph.toe.add_seconds(-3_600.0 + 300.0 * f64::from(k));
            let s = eph.state_at(&t).unwrap();
            assert!(
                (s.pos_ecef_m - start.pos_ecef_m).norm() < 1e-3,
                "{}",
                s.pos_ecef_m
            );
            assert!(s.pos_ecef_m[2].abs() < 1e-3);
            assert!(s.vel_ecef_mps.norm() < 1e-6, "{}", s.vel_ecef_mps);
            let (v, _) = central_difference(&eph, &t);
            assert!((s.vel_ecef_mps - v).norm() < 1e-6);
        }
        // The same elements as a MEO (GPS-like algorithm) swing ±5° in latitude.
        let mut meo = eph;
        meo.sat.prn = 30;
        let max_lat_deg = (0..=24)
            .map(|k| {
                let t = meo.toe.add_seconds(-43_200.0 + 3_600.0 * f64::from(k));
                let p = meo.state_at(&t).unwrap().pos_ecef_m;
                (p[2] / p.norm()).asin().to_degrees().abs()
            })
            .fold(0.0, f64::max);
        assert!(max_lat_deg > 4.0, "{max_lat_deg}");
    }

    #[test]
    fn geo_velocity_equals_central_difference_for_a_general_orbit() {
        let mut eph = geo();
        eph.eccentricity = 0.001;
        eph.inclination_rad = 0.1;
        eph.inclination_rate_rad_s = 1e-10;
        eph.raan_rate_rad_s = -1e-9;
        eph.cus_rad = 1e-5;
        eph.crc_m = 300.0;
        eph.cis_rad = 1e-7;
        for k in 0..8 {
            let t = eph.toe.add_seconds(-3_000.0 + 900.0 * f64::from(k));
            let s = eph.state_at(&t).unwrap();
            let (v, _) = central_difference(&eph, &t);
            assert!(
                (s.vel_ecef_mps - v).norm() < 1e-3,
                "{} vs {}",
                s.vel_ecef_mps,
                v
            );
        }
    }

    #[test]
    fn invalid_elements_give_none() {
        let mut eph = g32();
        eph.eccentricity = 1.2;
        assert!(eph.state_at(&eph.toe).is_none());
        let mut eph = g32();
        eph.crs_m = f64::NAN;
        assert!(eph.state_at(&eph.toe).is_none());
        assert!(g32().state_at(&GpsTime::new(2381, f64::INFINITY)).is_none());
    }
}
