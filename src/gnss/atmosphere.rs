//! Atmospheric propagation delays on a GNSS pseudo-range, in metres:
//! the broadcast Klobuchar ionosphere (IS-GPS-200, 20.3.3.5.2.5) and the Saastamoinen
//! troposphere with a standard atmosphere.

use crate::earth::{Llh, SPEED_OF_LIGHT_M_S};
use crate::gnss::Klobuchar;

/// Night-time constant vertical delay of the Klobuchar model (s).
const KLOBUCHAR_NIGHT_DELAY_S: f64 = 5.0e-9;
/// Local time of the Klobuchar day-time maximum (s after local midnight).
const KLOBUCHAR_PEAK_LOCAL_TIME_S: f64 = 50_400.0;
/// Floor of the Klobuchar period (s).
const KLOBUCHAR_MIN_PERIOD_S: f64 = 72_000.0;
/// Bound on the ionospheric pierce-point latitude (semicircles).
const KLOBUCHAR_MAX_PIERCE_LAT_SC: f64 = 0.416;
/// Seconds per day.
const SECONDS_PER_DAY: f64 = 86_400.0;

/// Broadcast Klobuchar L1 ionospheric delay (m), IS-GPS-200 20.3.3.5.2.5 (Figure 20-4).
///
/// `p` is the receiver, `azimuth_rad` and `elevation_rad` the satellite direction at the
/// receiver, `gps_time_of_week_s` the GPS time (any whole number of days may be added:
/// only the time of day enters). The model gives the delay at the GPS L1 frequency
/// (1575.42 MHz); it applies unchanged to Galileo E1, which shares that frequency.
///
/// Choice: the model's input elevation is clamped to [0, π/2]. Below the horizon the
/// ICD formula is undefined in spirit (its obliquity factor keeps growing); the clamp keeps
/// the result finite and equal to the horizon value. Non-finite inputs give a non-finite
/// result, which callers check.
pub fn klobuchar_delay_m(
    k: &Klobuchar,
    p: &Llh,
    azimuth_rad: f64,
    elevation_rad: f64,
    gps_time_of_week_s: f64,
) -> f64 {
    let pi = std::f64::consts::PI;
    // The ICD works in semicircles (1 semicircle = π rad).
    let el_sc = elevation_rad.clamp(0.0, 0.5 * pi) / pi;
    let lat_sc = p.lat_rad / pi;
    let lon_sc = p.lon_rad / pi;

    // Earth-centred angle between the user and the ionospheric pierce point (semicircles).
    let psi_sc = 0.0137 / (el_sc + 0.11) - 0.022;
    let pierce_lat_sc = (lat_sc + psi_sc * azimuth_rad.cos())
        .clamp(-KLOBUCHAR_MAX_PIERCE_LAT_SC, KLOBUCHAR_MAX_PIERCE_LAT_SC);
    let pierce_lon_sc = lon_sc + psi_sc * azimuth_rad.sin() / (pierce_lat_sc * pi).cos();
    // Geomagnetic latitude of the pierce point (semicircles).
    let mag_lat_sc = pierce_lat_sc + 0.064 * ((pierce_lon_sc - 1.617) * pi).cos();

    // Local time at the pierce point, in [0, 86400) s.
    let local_time_s = (4.32e4 * pierce_lon_sc + gps_time_of_week_s).rem_euclid(SECONDS_PER_DAY);

    // Obliquity (slant) factor.
    let obliquity = 1.0 + 16.0 * (0.53 - el_sc).powi(3);

    let amplitude_s = polynomial(&k.alpha, mag_lat_sc).max(0.0);
    let period_s = polynomial(&k.beta, mag_lat_sc).max(KLOBUCHAR_MIN_PERIOD_S);
    let phase_rad = 2.0 * pi * (local_time_s - KLOBUCHAR_PEAK_LOCAL_TIME_S) / period_s;

    let delay_s = if phase_rad.abs() < 1.57 {
        let x2 = phase_rad * phase_rad;
        obliquity * (KLOBUCHAR_NIGHT_DELAY_S + amplitude_s * (1.0 - x2 / 2.0 + x2 * x2 / 24.0))
    } else {
        obliquity * KLOBUCHAR_NIGHT_DELAY_S
    };
    SPEED_OF_LIGHT_M_S * delay_s
}

/// c₀ + c₁ x + c₂ x² + c₃ x³ (Horner).
fn polynomial(c: &[f64; 4], x: f64) -> f64 {
    ((c[3] * x + c[2]) * x + c[1]) * x + c[0]
}

/// Lowest height (m) at which the standard-atmosphere troposphere model is evaluated.
pub const TROPO_MODEL_MIN_HEIGHT_M: f64 = -500.0;
/// Highest height (m): the tropopause of the standard atmosphere, where its constant
/// temperature lapse rate ends.
pub const TROPO_MODEL_MAX_HEIGHT_M: f64 = 11_000.0;

/// Sea-level pressure of the standard atmosphere (hPa).
const SEA_LEVEL_PRESSURE_HPA: f64 = 1013.25;
/// Sea-level temperature of the standard atmosphere (K), 15 °C.
const SEA_LEVEL_TEMPERATURE_K: f64 = 288.15;
/// Temperature lapse rate of the standard atmosphere (K/m).
const LAPSE_RATE_K_PER_M: f64 = 0.0065;
/// Relative humidity assumed everywhere (fraction).
const RELATIVE_HUMIDITY: f64 = 0.7;

/// Saastamoinen tropospheric delay (m) at the receiver `p` for a satellite at
/// `elevation_rad`, hydrostatic plus wet, from a standard atmosphere.
///
/// Choices:
/// - Standard atmosphere (ICAO / US 1976 troposphere): P = 1013.25 (1 − 2.25577·10⁻⁵ h)^5.25588
///   hPa, T = 288.15 − 0.0065 h K, relative humidity 0.7 at all heights; water-vapour
///   partial pressure e = 0.7 · e_s(T) with the Magnus saturation formula of Alduchov &
///   Eskridge (1996), e_s = 6.1094 exp(17.625 t / (t + 243.04)) hPa, t in °C.
///   The ellipsoidal height stands in for the height above sea level (the geoid
///   undulation, tens of metres, changes the delay by millimetres).
/// - Zenith delays (Saastamoinen 1972, as written by Davis et al. 1985):
///   hydrostatic 0.0022768 P / (1 − 0.00266 cos 2φ − 0.00028 h_km),
///   wet 0.002277 (1255 / T + 0.05) e; both in metres with P, e in hPa.
/// - Mapping to the slant: the Black & Eisner (1984) function
///   m(E) = 1.001 / sqrt(0.002001 + sin² E), the one of RTCA DO-229 for SBAS. Unlike
///   1 / sin E it stays finite at the horizon (≈ 22.4) and is within a few per cent of
///   the Niell functions above 5°. [`saastamoinen_mapped_delay_m`] takes another.
/// - Elevations below the horizon are clamped to 0.
/// - Outside [`TROPO_MODEL_MIN_HEIGHT_M`, `TROPO_MODEL_MAX_HEIGHT_M`] (or for a
///   non-finite height) the model is not valid and the function returns 0.
pub fn saastamoinen_delay_m(p: &Llh, elevation_rad: f64) -> f64 {
    saastamoinen_mapped_delay_m(p, elevation_rad, TropoMapping::BlackEisner)
}

/// Lowest elevation (rad) at which the cosecant mapping is evaluated: 1°, where it is
/// 57.3. Choice: the plain 1 / sin E is infinite at the horizon; below 1° (far under any
/// elevation mask) the 1° value is used so the delay stays finite, as the prediction of
/// a satellite below the horizon during the first iterations of a solution needs.
pub const COSECANT_MIN_ELEVATION_RAD: f64 = 1.0 * std::f64::consts::PI / 180.0;

/// How a zenith tropospheric delay is mapped to the slant of a satellite's elevation E.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum TropoMapping {
    /// Black & Eisner (1984), m(E) = 1.001 / sqrt(0.002001 + sin² E), RTCA DO-229's:
    /// finite at the horizon (≈ 22.4), within a few per cent of the Niell functions
    /// above 5°.
    #[default]
    BlackEisner,
    /// m(E) = 1 / sin E (1 / cos z), floored at [`COSECANT_MIN_ELEVATION_RAD`]. It is
    /// RTKLIB's (`tropmodel`), so selecting it reproduces RTKLIB's single-point
    /// solutions; it exceeds Black & Eisner by 3 % at 10° and 0.3 % at 30°.
    Cosecant,
}

impl TropoMapping {
    /// The mapping factor at `elevation_rad` (clamped to [0, π/2]).
    pub fn factor(self, elevation_rad: f64) -> f64 {
        let el = elevation_rad.clamp(0.0, 0.5 * std::f64::consts::PI);
        match self {
            Self::BlackEisner => {
                let sin_el = el.sin();
                1.001 / (0.002001 + sin_el * sin_el).sqrt()
            }
            Self::Cosecant => 1.0 / el.max(COSECANT_MIN_ELEVATION_RAD).sin(),
        }
    }
}

/// The tropospheric delay model of a pseudo-range prediction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TroposphereModel {
    /// No tropospheric delay (for comparisons with tools run without one).
    Off,
    /// Saastamoinen zenith delays of the standard atmosphere with this mapping.
    Saastamoinen(TropoMapping),
}

impl Default for TroposphereModel {
    /// Saastamoinen with the Black & Eisner mapping.
    fn default() -> Self {
        Self::Saastamoinen(TropoMapping::BlackEisner)
    }
}

impl TroposphereModel {
    /// The delay (m) at the receiver `p` for a satellite at `elevation_rad`.
    pub fn delay_m(self, p: &Llh, elevation_rad: f64) -> f64 {
        match self {
            Self::Off => 0.0,
            Self::Saastamoinen(mapping) => saastamoinen_mapped_delay_m(p, elevation_rad, mapping),
        }
    }
}

/// Saastamoinen tropospheric delay (m) as [`saastamoinen_delay_m`], with the zenith
/// delays mapped to the slant by `mapping`.
pub fn saastamoinen_mapped_delay_m(p: &Llh, elevation_rad: f64, mapping: TropoMapping) -> f64 {
    let h = p.height_m;
    if !(TROPO_MODEL_MIN_HEIGHT_M..=TROPO_MODEL_MAX_HEIGHT_M).contains(&h) {
        return 0.0;
    }
    saastamoinen_zenith_delay_m(p.lat_rad, h) * mapping.factor(elevation_rad)
}

/// Saastamoinen zenith delay (m), hydrostatic plus wet, of the standard atmosphere at
/// latitude `lat_rad` and height `height_m` (assumed inside the model's range).
fn saastamoinen_zenith_delay_m(lat_rad: f64, height_m: f64) -> f64 {
    let pressure_hpa = SEA_LEVEL_PRESSURE_HPA * (1.0 - 2.25577e-5 * height_m).powf(5.25588);
    let temperature_k = SEA_LEVEL_TEMPERATURE_K - LAPSE_RATE_K_PER_M * height_m;
    let t_c = temperature_k - 273.15;
    let saturation_hpa = 6.1094 * (17.625 * t_c / (t_c + 243.04)).exp();
    let vapour_hpa = RELATIVE_HUMIDITY * saturation_hpa;

    let hydrostatic = 0.0022768 * pressure_hpa
        / (1.0 - 0.00266 * (2.0 * lat_rad).cos() - 0.00028 * height_m * 1e-3);
    let wet = 0.002277 * (1255.0 / temperature_k + 0.05) * vapour_hpa;
    hydrostatic + wet
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Broadcast coefficients used in the tests (typical values of a GPS navigation
    /// message; α in s, s/sc, s/sc², s/sc³, β in s, s/sc, ...).
    fn coefficients() -> Klobuchar {
        Klobuchar {
            alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -1.1921e-7],
            beta: [1.1469e5, 0.0, -1.9661e5, -6.5536e4],
        }
    }

    #[test]
    fn klobuchar_matches_independent_python_values() {
        // Reference values from tests/data/atmosphere_reference.py (an independent Python
        // transcription of IS-GPS-200 Figure 20-4), output in
        // tests/data/atmosphere_reference.txt. Hand check of the first case
        // (φ = 40° N, λ = 100° W, E = 20°, A = 210°, t = 593 100 s):
        //   E = 0.111111 sc, ψ = 0.0137/0.221111 − 0.022 = 0.039960 sc,
        //   φi = 0.222222 + 0.039960 cos 210° = 0.187616 sc,
        //   λi = −0.555556 + 0.039960 sin 210° / cos(0.187616 π) = −0.579591 sc,
        //   φm = 0.187616 + 0.064 cos((−0.579591 − 1.617) π) = 0.239793 sc,
        //   t = 43 200 (−0.579591) + 593 100 = 568 061.7 → 49 661.7 s of the day,
        //   F = 1 + 16 (0.53 − 0.111111)³ = 2.176025,
        //   AMP = 1.1176e-8 + 7.4506e-9 φm − 5.9605e-8 φm² − 1.1921e-7 φm³ = 7.8916e-9 s,
        //   PER = 114 690 − 196 610 φm² − 65 536 φm³ = 102 481 s,
        //   x = 2π (49 661.7 − 50 400)/102 481 = −0.045268 rad,
        //   T = F (5e-9 + AMP (1 − x²/2 + x⁴/24)) = 2.80348e-8 s → 8.4046 m.
        let k = coefficients();
        let cases: [(f64, f64, f64, f64, f64, f64); 4] = [
            // lat_deg, lon_deg, az_deg, el_deg, tow_s, expected_m
            (40.0, -100.0, 210.0, 20.0, 593_100.0, 8.404_620_251_2),
            (45.0, 7.0, 90.0, 60.0, 43_200.0, 3.869_833_568_7),
            (-33.9, 151.2, 300.0, 12.0, 3_600.0, 8.374_923_669_2),
            (10.0, 30.0, 0.0, 90.0, 200_000.0, 3.677_192_098_2),
        ];
        for (lat, lon, az, el, tow, expected) in cases {
            let p = Llh::from_degrees(lat, lon, 0.0);
            let d = klobuchar_delay_m(&k, &p, az.to_radians(), el.to_radians(), tow);
            assert!(
                (d - expected).abs() < 1e-6,
                "lat {lat} lon {lon}: {d} vs {expected}"
            );
        }
    }

    #[test]
    fn klobuchar_stays_within_its_physical_bounds() {
        let k = coefficients();
        let c = SPEED_OF_LIGHT_M_S;
        // Largest amplitude over the geomagnetic-latitude range (|φm| ≤ 0.416 + 0.064),
        // on a grid fine enough (10⁻⁵ sc) that the sampled maximum is exact to 10⁻¹⁸ s.
        let amp_max = (0..=96_000)
            .map(|i| polynomial(&k.alpha, -0.48 + 1e-5 * i as f64).max(0.0))
            .fold(0.0, f64::max);
        for lat_i in -8..=8 {
            for el_i in 0..=9 {
                for tow_i in 0..24 {
                    let p = Llh::from_degrees(10.0 * lat_i as f64, 13.0 * lat_i as f64, 0.0);
                    let el = (10.0 * el_i as f64).to_radians();
                    let d =
                        klobuchar_delay_m(&k, &p, 1.0 + lat_i as f64, el, 3600.0 * tow_i as f64);
                    let e_sc = el / std::f64::consts::PI;
                    let f = 1.0 + 16.0 * (0.53 - e_sc).powi(3);
                    // Never below the obliquity-scaled night constant, never above it
                    // plus the largest day-time amplitude.
                    assert!(d >= c * f * 5e-9 - 1e-9, "{d}");
                    assert!(d <= c * f * (5e-9 + amp_max) + 1e-9, "{d}");
                }
            }
        }
        // At night (local time 02:00 at λ = 0) the delay is exactly F · 5 ns · c.
        let p = Llh::from_degrees(0.0, 0.0, 0.0);
        let zenith = klobuchar_delay_m(&k, &p, 0.0, std::f64::consts::FRAC_PI_2, 7200.0);
        let f_zenith = 1.0 + 16.0 * 0.03f64.powi(3);
        assert!((zenith - c * 5e-9 * f_zenith).abs() < 1e-9, "{zenith}");
        // Obliquity factor at the horizon: 1 + 16 · 0.53³ = 3.382.
        let horizon = klobuchar_delay_m(&k, &p, 0.0, 0.0, 7200.0);
        assert!((horizon / zenith - 3.382_032 / f_zenith).abs() < 1e-5);
        // Below the horizon: clamped to the horizon value.
        assert_eq!(klobuchar_delay_m(&k, &p, 0.0, -0.2, 7200.0), horizon);
    }

    #[test]
    fn saastamoinen_zenith_delay_at_sea_level_is_about_2_4_m() {
        let p = Llh::from_degrees(45.0, 10.0, 0.0);
        let zenith = saastamoinen_delay_m(&p, std::f64::consts::FRAC_PI_2);
        assert!((2.3..=2.5).contains(&zenith), "{zenith}");
        // Against the independent Python evaluation (tests/data/atmosphere_reference.txt).
        assert!((zenith - 2.426_476_067_5).abs() < 1e-6, "{zenith}");
        let low = saastamoinen_delay_m(&p, 5f64.to_radians());
        assert!((low - 24.793_597_583_8).abs() < 1e-6, "{low}");
    }

    #[test]
    fn saastamoinen_grows_toward_the_horizon_and_falls_with_height() {
        let p = Llh::from_degrees(45.0, 10.0, 0.0);
        let mut previous = 0.0;
        for el_deg in (0..=90).rev() {
            let d = saastamoinen_delay_m(&p, (el_deg as f64).to_radians());
            assert!(d > previous, "not increasing at {el_deg}°");
            previous = d;
        }
        // Horizon value is finite and about 22.4 zenith delays.
        let zenith = saastamoinen_delay_m(&p, std::f64::consts::FRAC_PI_2);
        assert!(
            (previous / zenith - 22.38).abs() < 0.01,
            "{}",
            previous / zenith
        );
        // About 12 % less delay per 1000 m of height near the ground.
        let high = saastamoinen_delay_m(
            &Llh {
                height_m: 1000.0,
                ..p
            },
            1.0,
        );
        let low = saastamoinen_delay_m(&p, 1.0);
        assert!(high < low && high > 0.85 * low, "{high} {low}");
    }

    #[test]
    fn saastamoinen_is_zero_outside_its_height_range() {
        for h in [-1000.0, 11_001.0, 400_000.0, f64::NAN] {
            let p = Llh::from_degrees(45.0, 10.0, h);
            assert_eq!(saastamoinen_delay_m(&p, 0.5), 0.0, "height {h}");
        }
        let top = Llh::from_degrees(45.0, 10.0, TROPO_MODEL_MAX_HEIGHT_M);
        assert!(saastamoinen_delay_m(&top, 0.5) > 0.0);
    }

    #[test]
    fn cosecant_mapping_is_one_over_sine_with_a_floor() {
        let p = Llh::from_degrees(40.2, -105.1, 1560.0);
        let zenith = saastamoinen_delay_m(&p, std::f64::consts::FRAC_PI_2);
        let cosecant = TroposphereModel::Saastamoinen(TropoMapping::Cosecant);
        for el_deg in [5.0f64, 10.0, 30.0, 60.0, 90.0] {
            let el = el_deg.to_radians();
            let d = cosecant.delay_m(&p, el);
            assert!((d - zenith / el.sin()).abs() < 1e-9, "{el_deg}°: {d}");
            // Against Black & Eisner: equal at the zenith (to its 1.001 / sqrt(1.002001)
            // = 1.0000), larger toward the horizon.
            let be = saastamoinen_delay_m(&p, el);
            assert!(d >= be - 1e-6 * zenith, "{el_deg}°: {d} < {be}");
        }
        let floor = cosecant.delay_m(&p, COSECANT_MIN_ELEVATION_RAD);
        assert_eq!(cosecant.delay_m(&p, 0.0), floor);
        assert_eq!(cosecant.delay_m(&p, -0.3), floor);
        assert!(floor.is_finite() && floor > 50.0 * zenith);
        assert_eq!(TroposphereModel::Off.delay_m(&p, 0.2), 0.0);
        assert_eq!(
            TroposphereModel::default().delay_m(&p, 0.2),
            saastamoinen_delay_m(&p, 0.2)
        );
    }
}
