//! Human units <-> SI, done once at load time (forward) and for the echo (backward): the
//! conversions the parameter table names.
//!
//! Forward conversion is always `human * FACTOR`; the backward conversion picks the human
//! value whose forward conversion gives back the very same SI bits, so echoing a loaded
//! configuration and loading the echo reproduces the configuration exactly.

use nalgebra::{UnitQuaternion, Vector3};

use super::file_value::ConstellationName;
use crate::earth::Llh;
use crate::gnss::Constellation;

/// Standard gravity (m/s²) defining the unit g (and µg) of accelerometer data sheets.
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;
/// 1 degree in radians.
pub const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// 1 deg/h in rad/s.
pub const RAD_S_PER_DEG_H: f64 = RAD_PER_DEG / 3600.0;
/// 1 deg/√h in rad/√s (√h = 60 √s).
pub const RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H: f64 = RAD_PER_DEG / 60.0;
/// 1 µg in m/s²; also 1 µg/√Hz in m/s²/√Hz = m/s/√s (1/√Hz = √s).
pub const M_S2_PER_UG: f64 = STANDARD_GRAVITY_M_S2 * 1e-6;

/// The human value `h` with `h * factor == si`, when one exists next to `si / factor`.
///
/// Math note: fl(fl(h·k)/k) lies within two units in the last place of h, so when `si`
/// came from a forward conversion, one of the five neighbours of `si / factor` tried here
/// converts forward to exactly `si`. For other `si` the plain quotient is returned.
/// Choice: when several neighbours convert to `si`, the one with the shortest decimal
/// form is returned (15 deg stays 15, not 14.999999999999998), since the human value a
/// person typed is the short one.
pub fn si_to_human(si: f64, factor: f64) -> f64 {
    let quotient = si / factor;
    if !quotient.is_finite() || quotient == 0.0 {
        return quotient;
    }
    let bits = quotient.to_bits();
    [0_i64, 1, -1, 2, -2]
        .into_iter()
        .map(|step| f64::from_bits(bits.wrapping_add_signed(step)))
        .filter(|candidate| candidate * factor == si)
        .min_by_key(|candidate| candidate.to_string().len())
        .unwrap_or(quotient)
}

/// Rotation from roll, pitch, yaw (rad) as R = Rz(yaw) · Ry(pitch) · Rx(roll).
fn rotation_from_rpy(rpy_deg: &[f64; 3]) -> UnitQuaternion<f64> {
    let [roll, pitch, yaw] = rpy_deg.map(|deg| deg * RAD_PER_DEG);
    // nalgebra applies roll about x first, then pitch about y, then yaw about z.
    UnitQuaternion::from_euler_angles(roll, pitch, yaw)
}

/// Roll, pitch, yaw (deg) of `q`, rounded to 1e-12 deg.
///
/// Choice: the Euler angles recomputed from a quaternion carry rounding of about 1e-14 deg
/// (20 comes back as 19.999999999999996). Rounding to 1e-12 deg (2e-14 rad, far below any
/// mounting knowledge) gives back the angles as they were written, so the echo reads as
/// the file did and loading it reproduces the same quaternion.
fn rpy_deg_from_rotation(q: &UnitQuaternion<f64>) -> [f64; 3] {
    const STEPS_PER_DEG: f64 = 1e12;
    let (roll, pitch, yaw) = q.euler_angles();
    // `+ 0.0` turns a -0.0 into 0.0 so the echo of the identity reads [0.0, 0.0, 0.0].
    [roll, pitch, yaw].map(|rad| (rad / RAD_PER_DEG * STEPS_PER_DEG).round() / STEPS_PER_DEG + 0.0)
}

/// How a parameter's value in the file (human units) becomes the configuration's (SI),
/// and back for the echo: the backward conversion gives the value whose forward
/// conversion reproduces the SI bits, so an echo loads back to the same configuration.
pub trait Convert<Human, Si> {
    /// File value to SI.
    fn to_si(&self, human: &Human) -> Si;
    /// SI to file value.
    fn to_human(&self, si: &Si) -> Human;
}

/// What the manual says about a conversion (`1 deg = 0.017453 rad`), empty for none.
pub trait ConversionText {
    /// The conversion of one `unit` of the file.
    fn text(&self, unit: &str) -> String;
}

/// No conversion: the file value is the SI value.
pub struct Same;

impl<T: Clone> Convert<T, T> for Same {
    fn to_si(&self, human: &T) -> T {
        human.clone()
    }
    fn to_human(&self, si: &T) -> T {
        si.clone()
    }
}

impl ConversionText for Same {
    fn text(&self, _: &str) -> String {
        String::new()
    }
}

/// SI = file value × `factor`, in `si_unit`.
pub struct Scale {
    pub si_unit: &'static str,
    pub factor: f64,
}

impl Scale {
    /// The conversion to `si_unit` by `factor`.
    pub const fn to(si_unit: &'static str, factor: f64) -> Self {
        Self { si_unit, factor }
    }
}

impl Convert<f64, f64> for Scale {
    fn to_si(&self, human: &f64) -> f64 {
        human * self.factor
    }
    fn to_human(&self, si: &f64) -> f64 {
        si_to_human(*si, self.factor)
    }
}

impl Convert<Option<f64>, Option<f64>> for Scale {
    fn to_si(&self, human: &Option<f64>) -> Option<f64> {
        human.map(|h| h * self.factor)
    }
    fn to_human(&self, si: &Option<f64>) -> Option<f64> {
        si.map(|s| si_to_human(s, self.factor))
    }
}

impl ConversionText for Scale {
    fn text(&self, unit: &str) -> String {
        format!("1 {unit} = {} {}", significant(self.factor), self.si_unit)
    }
}

/// `[roll, pitch, yaw]` in degrees to the rotation R = Rz(yaw) · Ry(pitch) · Rx(roll).
pub struct RpyDegToRotation;

impl Convert<[f64; 3], UnitQuaternion<f64>> for RpyDegToRotation {
    fn to_si(&self, human: &[f64; 3]) -> UnitQuaternion<f64> {
        rotation_from_rpy(human)
    }
    fn to_human(&self, si: &UnitQuaternion<f64>) -> [f64; 3] {
        rpy_deg_from_rotation(si)
    }
}

impl ConversionText for RpyDegToRotation {
    fn text(&self, _: &str) -> String {
        "the rotation R = Rz(yaw) Ry(pitch) Rx(roll)".to_owned()
    }
}

/// Three components to a vector of the same unit.
pub struct ToVector;

impl Convert<[f64; 3], Vector3<f64>> for ToVector {
    fn to_si(&self, human: &[f64; 3]) -> Vector3<f64> {
        Vector3::from(*human)
    }
    fn to_human(&self, si: &Vector3<f64>) -> [f64; 3] {
        (*si).into()
    }
}

impl ConversionText for ToVector {
    fn text(&self, _: &str) -> String {
        String::new()
    }
}

/// `[lat_deg, lon_deg, height_m]` to a geodetic position in radians and metres.
pub struct LlhDegToPosition;

impl Convert<Option<[f64; 3]>, Option<Llh>> for LlhDegToPosition {
    fn to_si(&self, human: &Option<[f64; 3]>) -> Option<Llh> {
        human.map(|[lat_deg, lon_deg, height_m]| {
            Llh::new(lat_deg * RAD_PER_DEG, lon_deg * RAD_PER_DEG, height_m)
        })
    }
    fn to_human(&self, si: &Option<Llh>) -> Option<[f64; 3]> {
        let deg = |rad: f64| si_to_human(rad, RAD_PER_DEG);
        si.map(|p| [deg(p.lat_rad), deg(p.lon_rad), p.height_m])
    }
}

impl ConversionText for LlhDegToPosition {
    fn text(&self, _: &str) -> String {
        format!(
            "latitude and longitude: 1 deg = {} rad",
            significant(RAD_PER_DEG)
        )
    }
}

/// Constellation names to the GNSS layer's constellations.
pub struct ByName;

impl Convert<Vec<ConstellationName>, Vec<Constellation>> for ByName {
    fn to_si(&self, human: &Vec<ConstellationName>) -> Vec<Constellation> {
        human.iter().map(|&c| c.into()).collect()
    }
    fn to_human(&self, si: &Vec<Constellation>) -> Vec<ConstellationName> {
        si.iter().map(|&c| c.into()).collect()
    }
}

impl ConversionText for ByName {
    fn text(&self, _: &str) -> String {
        String::new()
    }
}

/// `x` with five significant digits: `2.9089e-4`, `0.017453`.
fn significant(x: f64) -> String {
    let text = format!("{x:.4e}");
    match text.split_once('e') {
        Some((mantissa, "0")) => mantissa.to_owned(),
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_factors_match_hand_computed_values() {
        // 1 deg/h = π/180/3600 rad/s = 4.84813681e-6 rad/s.
        assert!((RAD_S_PER_DEG_H - 4.848_136_811_095_36e-6).abs() < 1e-18);
        // 1 deg/√h = π/180/60 rad/√s = 2.90888209e-4 rad/√s.
        assert!((RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H - 2.908_882_086_657_216e-4).abs() < 1e-17);
        // 1 µg = 9.80665e-6 m/s².
        assert!((M_S2_PER_UG - 9.806_65e-6).abs() < 1e-20);
        assert!((RAD_PER_DEG - 0.017_453_292_519_943_295).abs() < 1e-18);
    }

    #[test]
    fn si_to_human_inverts_the_forward_conversion_bit_exactly() {
        let factors = [
            RAD_PER_DEG,
            RAD_S_PER_DEG_H,
            RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
            M_S2_PER_UG,
        ];
        let mut human = 1e-3_f64;
        while human < 1e5 {
            for factor in factors {
                for h in [human, -human] {
                    let si = h * factor;
                    let back = si_to_human(si, factor);
                    assert_eq!(back * factor, si, "h = {h}, factor = {factor}");
                }
            }
            human *= 1.0137;
        }
        assert_eq!(si_to_human(0.0, RAD_PER_DEG), 0.0);
    }

    #[test]
    fn si_to_human_gives_back_the_short_value_typed() {
        for h in [15.0, 12.5, 10.0, 0.3, 95.0] {
            assert_eq!(si_to_human(h * RAD_PER_DEG, RAD_PER_DEG), h);
        }
    }

    #[test]
    fn rotation_follows_z_y_x_order() {
        let rpy_deg = [10.0, -20.0, 30.0];
        let q = rotation_from_rpy(&rpy_deg);
        let [r, p, y] = rpy_deg.map(f64::to_radians);
        let rx = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), r);
        let ry = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), p);
        let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), y);
        let expected = rz * ry * rx;
        let diff = q.to_rotation_matrix().matrix() - expected.matrix();
        assert!(diff.amax() < 1e-15, "{diff}");
        assert_eq!(rpy_deg_from_rotation(&q), rpy_deg);
        let odd = [1.0 / 3.0, -89.0 / 7.0, 179.0 - 1.0 / 9.0];
        let back = rpy_deg_from_rotation(&rotation_from_rpy(&odd));
        for (a, b) in back.iter().zip(odd) {
            assert!((a - b).abs() < 1e-12, "{back:?}");
        }
    }
}
