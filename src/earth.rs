//! WGS84 earth model: ellipsoid constants, radii of curvature, normal gravity, earth rate,
//! and conversions between ECEF, geodetic (LLH) and local ENU coordinates.
//!
//! Conventions: latitude and longitude in radians, heights in metres above the ellipsoid,
//! the local-level navigation frame is East-North-Up (REP-103, and the papers' n-frame).

use nalgebra::{Matrix3, Vector3};

/// WGS84 semi-major axis a (m).
pub const SEMI_MAJOR_AXIS_M: f64 = 6_378_137.0;
/// WGS84 flattening f.
pub const FLATTENING: f64 = 1.0 / 298.257_223_563;
/// First eccentricity squared e² = f (2 − f).
pub const ECCENTRICITY_SQ: f64 = FLATTENING * (2.0 - FLATTENING);
/// Semi-minor axis b = a (1 − f) (m).
pub const SEMI_MINOR_AXIS_M: f64 = SEMI_MAJOR_AXIS_M * (1.0 - FLATTENING);
/// WGS84 earth rotation rate ω_ie (rad/s), also the rate used by IS-GPS-200.
pub const EARTH_RATE_RAD_S: f64 = 7.292_115_146_7e-5;
/// WGS84 gravitational constant GM (m³/s²).
pub const GM_M3_S2: f64 = 3.986_004_418e14;
/// Speed of light in vacuum (m/s).
pub const SPEED_OF_LIGHT_M_S: f64 = 299_792_458.0;
/// WGS84 normal gravity at the equator (m/s²).
pub const GRAVITY_EQUATOR_M_S2: f64 = 9.780_325_335_9;
/// Somigliana's constant k = (b γ_p − a γ_e) / (a γ_e).
const SOMIGLIANA_K: f64 = 0.001_931_852_652_41;
/// m = ω² a² b / GM, used by the height correction of normal gravity.
const GRAVITY_M: f64 = 0.003_449_786_506_84;

/// Geodetic position: latitude and longitude (rad), height above the ellipsoid (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Llh {
    pub lat_rad: f64,
    pub lon_rad: f64,
    pub height_m: f64,
}

impl Llh {
    pub fn new(lat_rad: f64, lon_rad: f64, height_m: f64) -> Self {
        Self {
            lat_rad,
            lon_rad,
            height_m,
        }
    }

    pub fn from_degrees(lat_deg: f64, lon_deg: f64, height_m: f64) -> Self {
        Self::new(lat_deg.to_radians(), lon_deg.to_radians(), height_m)
    }

    /// `[lat_rad, lon_rad, height_m]` as a vector (the order of the error state δL, δλ, δh).
    pub fn to_vector(self) -> Vector3<f64> {
        Vector3::new(self.lat_rad, self.lon_rad, self.height_m)
    }

    pub fn from_vector(v: &Vector3<f64>) -> Self {
        Self::new(v[0], v[1], v[2])
    }

    pub fn is_finite(&self) -> bool {
        self.lat_rad.is_finite() && self.lon_rad.is_finite() && self.height_m.is_finite()
    }
}

/// Meridian radius of curvature R_M (north-south) at latitude `lat_rad` (m).
pub fn meridian_radius_m(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    let w2 = 1.0 - ECCENTRICITY_SQ * s * s;
    SEMI_MAJOR_AXIS_M * (1.0 - ECCENTRICITY_SQ) / (w2 * w2.sqrt())
}

/// Transverse (prime vertical) radius of curvature R_N (east-west) at `lat_rad` (m).
pub fn transverse_radius_m(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    SEMI_MAJOR_AXIS_M / (1.0 - ECCENTRICITY_SQ * s * s).sqrt()
}

/// Normal gravity magnitude (m/s²) at geodetic latitude and ellipsoidal height:
/// Somigliana's closed formula on the ellipsoid, with the second-order free-air
/// correction of NIMA TR8350.2 (eq. 4-3) for height.
pub fn normal_gravity_m_s2(lat_rad: f64, height_m: f64) -> f64 {
    let s2 = lat_rad.sin().powi(2);
    let gamma0 =
        GRAVITY_EQUATOR_M_S2 * (1.0 + SOMIGLIANA_K * s2) / (1.0 - ECCENTRICITY_SQ * s2).sqrt();
    let a = SEMI_MAJOR_AXIS_M;
    gamma0
        * (1.0 - 2.0 / a * (1.0 + FLATTENING + GRAVITY_M - 2.0 * FLATTENING * s2) * height_m
            + 3.0 / (a * a) * height_m * height_m)
}

/// Gravity vector in the ENU frame: (0, 0, −γ) (m/s²).
pub fn gravity_enu_m_s2(p: &Llh) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, -normal_gravity_m_s2(p.lat_rad, p.height_m))
}

/// Earth rate expressed in ENU: ω_ie^n = (0, ω cos L, ω sin L) (rad/s).
pub fn earth_rate_enu_rad_s(lat_rad: f64) -> Vector3<f64> {
    Vector3::new(
        0.0,
        EARTH_RATE_RAD_S * lat_rad.cos(),
        EARTH_RATE_RAD_S * lat_rad.sin(),
    )
}

/// Transport rate ω_en^n of the ENU frame for ENU velocity `v_n` (rad/s):
/// (−v_N/(R_M+h), v_E/(R_N+h), v_E tan L/(R_N+h)).
pub fn transport_rate_enu_rad_s(p: &Llh, v_n: &Vector3<f64>) -> Vector3<f64> {
    let rm_h = meridian_radius_m(p.lat_rad) + p.height_m;
    let rn_h = transverse_radius_m(p.lat_rad) + p.height_m;
    Vector3::new(
        -v_n[1] / rm_h,
        v_n[0] / rn_h,
        v_n[0] * p.lat_rad.tan() / rn_h,
    )
}

/// Geodetic to ECEF (m).
pub fn llh_to_ecef(p: &Llh) -> Vector3<f64> {
    let (sl, cl) = p.lat_rad.sin_cos();
    let (so, co) = p.lon_rad.sin_cos();
    let rn = transverse_radius_m(p.lat_rad);
    Vector3::new(
        (rn + p.height_m) * cl * co,
        (rn + p.height_m) * cl * so,
        (rn * (1.0 - ECCENTRICITY_SQ) + p.height_m) * sl,
    )
}

/// ECEF (m) to geodetic, by Heikkinen's exact closed form (no iteration), followed by
/// one Newton refinement of the latitude; accurate to well below a millimetre from a few
/// thousand kilometres from the earth's centre out to GNSS orbit altitudes (a property
/// test checks the round trip). Returns `None` for non-finite input or points within
/// 1 km of the earth's centre, where the closed form loses its accuracy.
pub fn ecef_to_llh(r: &Vector3<f64>) -> Option<Llh> {
    if !(r[0].is_finite() && r[1].is_finite() && r[2].is_finite()) || r.norm() < 1e3 {
        return None;
    }
    let a = SEMI_MAJOR_AXIS_M;
    let b = SEMI_MINOR_AXIS_M;
    let e2 = ECCENTRICITY_SQ;
    let ep2 = (a * a - b * b) / (b * b);
    let (x, y, z) = (r[0], r[1], r[2]);
    let p = x.hypot(y);
    let f = 54.0 * b * b * z * z;
    let g = p * p + (1.0 - e2) * z * z - e2 * (a * a - b * b);
    let c = e2 * e2 * f * p * p / (g * g * g);
    let s = (1.0 + c + (c * c + 2.0 * c).sqrt()).cbrt();
    let k = s + 1.0 + 1.0 / s;
    let big_p = f / (3.0 * k * k * g * g);
    let q = (1.0 + 2.0 * e2 * e2 * big_p).sqrt();
    let r0 = -big_p * e2 * p / (1.0 + q)
        + (0.5 * a * a * (1.0 + 1.0 / q)
            - big_p * (1.0 - e2) * z * z / (q * (1.0 + q))
            - 0.5 * big_p * p * p)
            .max(0.0)
            .sqrt();
    let v = ((p - e2 * r0).powi(2) + (1.0 - e2) * z * z).sqrt();
    let z0 = b * b * z / (a * v);
    let closed_form_lat = (z + ep2 * z0).atan2(p);
    // One refinement on the exact relations (it removes the closed form's rounding at
    // large heights): the height at the closed-form latitude, then the latitude.
    let rn = transverse_radius_m(closed_form_lat);
    let (sl, cl) = closed_form_lat.sin_cos();
    let h = if cl.abs() > sl.abs() {
        p / cl - rn
    } else {
        z / sl - rn * (1.0 - e2)
    };
    let lat = z.atan2(p * (1.0 - e2 * rn / (rn + h)));
    let lon = y.atan2(x);
    let llh = Llh::new(lat, lon, h);
    llh.is_finite().then_some(llh)
}

/// Rotation from ECEF to local ENU at `p`: v_enu = C_en · v_ecef.
pub fn rot_ecef_to_enu(p: &Llh) -> Matrix3<f64> {
    let (sl, cl) = p.lat_rad.sin_cos();
    let (so, co) = p.lon_rad.sin_cos();
    Matrix3::new(-so, co, 0.0, -sl * co, -sl * so, cl, cl * co, cl * so, sl)
}

/// ECEF point to ENU coordinates (m) relative to the datum `origin`.
pub fn ecef_to_enu(r: &Vector3<f64>, origin: &Llh) -> Vector3<f64> {
    rot_ecef_to_enu(origin) * (r - llh_to_ecef(origin))
}

/// ENU coordinates (m) relative to `origin` back to ECEF.
pub fn enu_to_ecef(enu: &Vector3<f64>, origin: &Llh) -> Vector3<f64> {
    llh_to_ecef(origin) + rot_ecef_to_enu(origin).transpose() * enu
}

/// Geodetic point to ENU (m) relative to `origin`.
pub fn llh_to_enu(p: &Llh, origin: &Llh) -> Vector3<f64> {
    ecef_to_enu(&llh_to_ecef(p), origin)
}

/// ENU (m) relative to `origin` to geodetic.
pub fn enu_to_llh(enu: &Vector3<f64>, origin: &Llh) -> Option<Llh> {
    ecef_to_llh(&enu_to_ecef(enu, origin))
}

/// Diagonal of the map from (δL, δλ, δh) to local (δE, δN, δU) metres at `p`:
/// δE = (R_N+h) cos L δλ, δN = (R_M+h) δL, δU = δh. Returned as (m/rad north, m/rad east).
pub fn metres_per_radian(p: &Llh) -> (f64, f64) {
    let north = meridian_radius_m(p.lat_rad) + p.height_m;
    let east = (transverse_radius_m(p.lat_rad) + p.height_m) * p.lat_rad.cos();
    (north, east)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_gravity_matches_published_values() {
        // WGS84 normal gravity on the ellipsoid: equator 9.7803253359, pole 9.8321849378 m/s².
        assert!((normal_gravity_m_s2(0.0, 0.0) - 9.780_325_335_9).abs() < 1e-9);
        let pole = normal_gravity_m_s2(std::f64::consts::FRAC_PI_2, 0.0);
        assert!((pole - 9.832_184_937_8).abs() < 1e-8, "{pole}");
        // Free-air gradient ≈ −3.086e-6 s⁻² near the surface.
        let g45 = normal_gravity_m_s2(45f64.to_radians(), 0.0);
        let g45_1km = normal_gravity_m_s2(45f64.to_radians(), 1000.0);
        assert!(((g45_1km - g45) / 1000.0 + 3.086e-6).abs() < 1e-8);
    }

    #[test]
    fn ecef_of_known_point() {
        // On the equator at the prime meridian, 0 m: (a, 0, 0).
        let r = llh_to_ecef(&Llh::new(0.0, 0.0, 0.0));
        assert!((r - Vector3::new(SEMI_MAJOR_AXIS_M, 0.0, 0.0)).norm() < 1e-9);
        // North pole: (0, 0, b).
        let r = llh_to_ecef(&Llh::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0));
        assert!((r[2] - SEMI_MINOR_AXIS_M).abs() < 1e-6);
    }

    #[test]
    fn enu_rotation_is_orthonormal_and_up_is_radial_normal() {
        let p = Llh::from_degrees(40.1, -105.1, 1500.0);
        let c = rot_ecef_to_enu(&p);
        assert!((c * c.transpose() - Matrix3::identity()).norm() < 1e-14);
        let up = c.row(2).transpose();
        let r1 = llh_to_ecef(&p);
        let r2 = llh_to_ecef(&Llh {
            height_m: p.height_m + 1.0,
            ..p
        });
        assert!(((r2 - r1) - up).norm() < 1e-9);
    }
}
