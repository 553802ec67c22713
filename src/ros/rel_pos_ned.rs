//! A moving-base u-blox pair's `ublox_ubx_msgs/UBXNavRelPosNED` (ublox_dgnss's
//! `ubx_nav_rel_pos_ned`) -> the engine's baseline heading, and back for the simulator's
//! bags ([`message_of_reading`]).
//!
//! Only a message that says it holds a heading converts: relPosValid (in moving-base mode
//! the baseline is valid), relPosHeadingValid, isMoving (a static base's relative
//! position is a position, not an attitude) and a carrier-phase solution, float or fixed.
//! The rest — a float solution, an accuracy too poor or a baseline of the wrong length —
//! is the engine's to judge and count ([`BaselineHeadingReading`]).
//!
//! Choice: gnssFixOK, diffSoln and the extrapolation flags (refPosMiss, refObsMiss) are
//! not used: the baseline's validity and its accuracy are what the heading rests on, and
//! an extrapolated base shows in accHeading.

use super::convert::{time_to_seconds, ConvertError};
use super::msg::{CarrSoln, Header, Time, UbxNavRelPosNed};
use crate::engine::{BaselineHeadingReading, CarrierSolution};

/// Radians per 1e-5 degree (the heading's and its accuracy's unit).
const RAD_PER_1E5_DEG: f64 = std::f64::consts::PI / 180.0 * 1e-5;
/// Metres per cm and per 0.1 mm (the length's and its high-precision part's units).
const M_PER_CM: f64 = 1e-2;
const M_PER_0_1_MM: f64 = 1e-4;

impl TryFrom<&UbxNavRelPosNed> for BaselineHeadingReading {
    type Error = ConvertError;

    /// The stamp is `header.stamp` (the driver's host time of the frame, as for the
    /// other u-blox messages); the heading and its σ are relPosHeading and accHeading,
    /// the length relPosLength with its high-precision part.
    fn try_from(msg: &UbxNavRelPosNed) -> Result<Self, Self::Error> {
        let t_s = time_to_seconds(&msg.header.stamp)?;
        let refuse = |reason| Err(ConvertError::NoBaselineHeading { t_s, reason });
        let carrier = match msg.carr_soln.status {
            CarrSoln::PHASE_WITH_FIXED_AMBIGUITIES => CarrierSolution::Fixed,
            CarrSoln::PHASE_WITH_FLOATING_AMBIGUITIES => CarrierSolution::Float,
            _ => return refuse("no carrier-phase solution"),
        };
        if !msg.rel_pos_valid {
            return refuse("relPosValid not set");
        }
        if !msg.rel_pos_heading_valid {
            return refuse("relPosHeadingValid not set");
        }
        if !msg.is_moving {
            return refuse("not in moving-base mode");
        }
        Ok(Self {
            t_s,
            heading_rad: f64::from(msg.rel_pos_heading) * RAD_PER_1E5_DEG,
            sigma_rad: f64::from(msg.acc_heading) * RAD_PER_1E5_DEG,
            length_m: f64::from(msg.rel_pos_length) * M_PER_CM
                + f64::from(msg.rel_pos_hp_length) * M_PER_0_1_MM,
            carrier,
        })
    }
}

/// The UBXNavRelPosNED a moving-base pair would send for `reading`: the flags of a valid
/// moving-base heading, relPosHeading, accHeading and relPosLength (with its
/// high-precision part) rounded to their units.
///
/// Choice: the reading holds no tilt, so the components are those of a horizontal
/// baseline of that heading and length (relPosD 0); the filter reads only the heading,
/// its accuracy and the length.
pub fn message_of_reading(
    reading: &BaselineHeadingReading,
    stamp: Time,
    frame_id: &str,
) -> UbxNavRelPosNed {
    let units_1e5_deg = |rad: f64| (rad / RAD_PER_1E5_DEG).round();
    // cm and the remaining 0.1 mm, within ±99 as the receiver sends them.
    let split = |m: f64| {
        let cm = (m / M_PER_CM).trunc();
        (
            cm as i32,
            ((m - cm * M_PER_CM) / M_PER_0_1_MM).round() as i8,
        )
    };
    let (length, hp_length) = split(reading.length_m);
    let (n, hp_n) = split(reading.length_m * reading.heading_rad.cos());
    let (e, hp_e) = split(reading.length_m * reading.heading_rad.sin());
    UbxNavRelPosNed {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        version: 1,
        rel_pos_n: n,
        rel_pos_e: e,
        rel_pos_length: length,
        rel_pos_heading: units_1e5_deg(reading.heading_rad) as i32,
        rel_pos_hp_n: hp_n,
        rel_pos_hp_e: hp_e,
        rel_pos_hp_length: hp_length,
        acc_heading: units_1e5_deg(reading.sigma_rad) as u32,
        gnss_fix_ok: true,
        diff_soln: true,
        rel_pos_valid: true,
        carr_soln: CarrSoln {
            status: match reading.carrier {
                CarrierSolution::Fixed => CarrSoln::PHASE_WITH_FIXED_AMBIGUITIES,
                CarrierSolution::Float => CarrSoln::PHASE_WITH_FLOATING_AMBIGUITIES,
            },
        },
        is_moving: true,
        rel_pos_heading_valid: true,
        rel_pos_normalized: false,
        ..UbxNavRelPosNed::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::msg::Time;

    /// A fixed moving-base heading of 123.45678° ± 0.25°, baseline 1.2345 m.
    fn message() -> UbxNavRelPosNed {
        let mut msg = UbxNavRelPosNed::default();
        msg.header.stamp = Time {
            sec: 12,
            nanosec: 500_000_000,
        };
        msg.rel_pos_length = 123;
        msg.rel_pos_hp_length = 45;
        msg.rel_pos_heading = 12_345_678;
        msg.acc_heading = 25_000;
        msg.rel_pos_valid = true;
        msg.rel_pos_heading_valid = true;
        msg.is_moving = true;
        msg.carr_soln.status = CarrSoln::PHASE_WITH_FIXED_AMBIGUITIES;
        msg
    }

    #[test]
    fn a_fixed_moving_base_heading_converts_in_si_units() {
        let r = BaselineHeadingReading::try_from(&message()).unwrap();
        assert_eq!(r.t_s, 12.5);
        assert!((r.heading_rad.to_degrees() - 123.45678).abs() < 1e-9);
        assert!((r.sigma_rad.to_degrees() - 0.25).abs() < 1e-12);
        assert!((r.length_m - 1.2345).abs() < 1e-12);
        assert_eq!(r.carrier, CarrierSolution::Fixed);
        let mut float = message();
        float.carr_soln.status = CarrSoln::PHASE_WITH_FLOATING_AMBIGUITIES;
        let r = BaselineHeadingReading::try_from(&float).unwrap();
        assert_eq!(r.carrier, CarrierSolution::Float);
    }

    #[test]
    fn a_reading_survives_the_message_to_its_units() {
        let reading = BaselineHeadingReading {
            t_s: 12.5,
            heading_rad: 3.5,
            sigma_rad: 0.004,
            length_m: 1.23456,
            carrier: CarrierSolution::Float,
        };
        let stamp = Time {
            sec: 12,
            nanosec: 500_000_000,
        };
        let msg = message_of_reading(&reading, stamp, "gnss");
        assert_eq!(msg.header.frame_id, "gnss");
        let back = BaselineHeadingReading::try_from(&msg).unwrap();
        assert_eq!(back.t_s, 12.5);
        assert_eq!(back.carrier, CarrierSolution::Float);
        assert!((back.heading_rad - 3.5).abs() < RAD_PER_1E5_DEG);
        assert!((back.sigma_rad - 0.004).abs() < RAD_PER_1E5_DEG);
        assert!((back.length_m - 1.23456).abs() < M_PER_0_1_MM);
    }

    #[test]
    fn a_message_without_a_heading_does_not_convert() {
        let broken: [fn(&mut UbxNavRelPosNed); 5] = [
            |m| m.rel_pos_valid = false,
            |m| m.rel_pos_heading_valid = false,
            |m| m.is_moving = false,
            |m| m.carr_soln.status = CarrSoln::NO_CARRIER_RANGE_SOLUTION,
            |m| m.carr_soln.status = 7,
        ];
        for (i, breaks) in broken.iter().enumerate() {
            let mut msg = message();
            breaks(&mut msg);
            assert!(
                matches!(
                    BaselineHeadingReading::try_from(&msg),
                    Err(ConvertError::NoBaselineHeading { t_s, .. }) if t_s == 12.5
                ),
                "case {i}"
            );
        }
    }
}
