//! Wire messages -> core types, and ROS time <-> `f64` seconds.
//!
//! Conversions only: no filter math, and no frame rotation. In particular the IMU
//! vectors stay in the IMU's own frame (`header.frame_id`); the engine rotates them into
//! the body frame from the configured mounting.

use nalgebra::{Matrix3, Vector3};

use super::msg::{
    GnssMeasurements, Imu, NavSatFix, Odometry, SatelliteMeasurement, Time,
    TwistWithCovarianceStamped,
};
use crate::earth::Llh;
use crate::engine::GnssFix;
use crate::gnss::satellite_bounds::{
    MAX_ORBIT_RADIUS_M, MAX_SAT_CLOCK_BIAS_S, MAX_SAT_CLOCK_DRIFT_S_S, MAX_SAT_SPEED_MPS,
    MIN_ORBIT_RADIUS_M,
};
use crate::gnss::{CarrierPhase, Constellation, GnssEpoch, Klobuchar, SatId, SatObservation};
use crate::ins::ImuSample;

/// Nanoseconds in one second.
const NANOS_PER_SECOND: u32 = 1_000_000_000;
/// Length of a GPS week (s).
const SECONDS_PER_WEEK: f64 = 604_800.0;

/// Why a wire message could not become a core value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConvertError {
    /// A stamp whose nanoseconds are outside [0, 1e9).
    #[error("stamp {sec} s + {nanosec} ns is not a valid ROS time: nanosec must be below 1e9")]
    InvalidStamp {
        /// Seconds field of the stamp.
        sec: i32,
        /// Nanoseconds field of the stamp.
        nanosec: u32,
    },
    /// A time in seconds that no ROS stamp can hold.
    #[error("{t_s} s cannot be a ROS time: it must be finite and its seconds fit in an int32")]
    TimeOutOfRange {
        /// The rejected time (s).
        t_s: f64,
    },
    /// A GPS time of week that is not finite or not within one week.
    #[error("GNSS epoch at {t_s} s: GPS time of week {tow_s} s is outside [0, 604800)")]
    InvalidTimeOfWeek {
        /// Stamp of the epoch (s).
        t_s: f64,
        /// The rejected time of week (s).
        tow_s: f64,
    },
    /// A satellite whose constellation code is none of the message's constants.
    #[error("GNSS epoch at {t_s} s: satellite #{index} (PRN {prn}) has unknown constellation code {code}")]
    UnknownConstellation {
        /// Stamp of the epoch (s).
        t_s: f64,
        /// Position of the satellite in the message's list.
        index: usize,
        /// The rejected constellation code.
        code: u8,
        /// PRN of the satellite.
        prn: u16,
    },
    /// A satellite field whose value breaks the message's contract.
    #[error("GNSS epoch at {t_s} s, satellite {sat}: {field} = {value}, expected {expected}")]
    InvalidSatelliteField {
        /// Stamp of the epoch (s).
        t_s: f64,
        /// The satellite.
        sat: SatId,
        /// Name of the field in `SatelliteMeasurement.msg`.
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// What the contract allows.
        expected: &'static str,
    },
    /// An IMU vector with a NaN or infinite component.
    #[error("IMU sample at {t_s} s: {field} = {value:?} is not finite")]
    NonFiniteImu {
        /// Stamp of the sample (s).
        t_s: f64,
        /// Name of the field in `sensor_msgs/Imu`.
        field: &'static str,
        /// The rejected vector (x, y, z).
        value: [f64; 3],
    },
    /// A GNSS velocity with a NaN or infinite linear part or linear covariance.
    #[error("GNSS velocity at {t_s} s: {field} is not finite")]
    NonFiniteVelocity {
        /// Stamp of the velocity (s).
        t_s: f64,
        /// Name of the field in `geometry_msgs/TwistWithCovariance`.
        field: &'static str,
    },
    /// A wheel odometry whose forward speed is not finite, or whose variance of it is not
    /// finite or negative.
    #[error("wheel odometry at {t_s} s: {field} = {value}, expected {expected}")]
    InvalidWheelOdometry {
        /// Stamp of the odometry (s).
        t_s: f64,
        /// Name of the field in `nav_msgs/Odometry`.
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// What is allowed.
        expected: &'static str,
    },
    /// A UBXNavRelPosNED that gives no baseline heading (see
    /// [`crate::ros::rel_pos_ned`]).
    #[error("UBXNavRelPosNED at {t_s} s: {reason}")]
    NoBaselineHeading {
        /// Stamp of the message (s).
        t_s: f64,
        /// Which flag says so.
        reason: &'static str,
    },
    /// A NavSatFix whose status says the receiver has no solution.
    #[error("NavSatFix at {t_s} s: status {status}, no solution")]
    NoFix {
        /// Stamp of the fix (s).
        t_s: f64,
        /// `status.status` (below `STATUS_FIX`, 0).
        status: i8,
    },
}

/// A receiver fix from a NavSatFix with a solution (`status.status` ≥ 0). The position
/// covariance is taken as ENU (REP-145 and sensor_msgs); with `COVARIANCE_TYPE_UNKNOWN`
/// there is none and the configured σ applies. The velocity joins later (see
/// [`crate::ros::fix_velocity`]). Non-finite values pass: the engine rejects and counts
/// them.
impl TryFrom<&NavSatFix> for GnssFix {
    type Error = ConvertError;

    fn try_from(msg: &NavSatFix) -> Result<Self, Self::Error> {
        let t_s = time_to_seconds(&msg.header.stamp)?;
        if msg.status.status < 0 {
            return Err(ConvertError::NoFix {
                t_s,
                status: msg.status.status,
            });
        }
        let c = &msg.position_covariance;
        let covariance = (msg.position_covariance_type != NavSatFix::COVARIANCE_TYPE_UNKNOWN)
            .then(|| Matrix3::from_fn(|r, k| c[3 * r + k]));
        Ok(GnssFix {
            t_s,
            position: Llh::from_degrees(msg.latitude, msg.longitude, msg.altitude),
            position_covariance_enu_m2: covariance,
            velocity_enu_mps: None,
            velocity_covariance_enu_m2_s2: None,
        })
    }
}

/// A receiver's velocity (`gnss/velocity`), waiting to join the fix of its stamp.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssVelocity {
    /// Stamp (s).
    pub t_s: f64,
    /// `header.frame_id`.
    pub frame_id: String,
    /// Antenna velocity in ENU (m/s).
    pub velocity_enu_mps: Vector3<f64>,
    /// Its covariance ((m/s)²); None when the message gives none.
    pub covariance_enu_m2_s2: Option<Matrix3<f64>>,
}

impl TryFrom<&TwistWithCovarianceStamped> for GnssVelocity {
    type Error = ConvertError;

    /// Convention (REP-105 and the GNSS drivers, e.g. ublox_gps's `fix_velocity`): the
    /// twist's linear part is the antenna velocity along east, north, up; the angular part
    /// is ignored. Choice: a covariance whose linear block is all zero or starts with −1
    /// (sensor_msgs' "unknown") is none, and the configured σ applies.
    fn try_from(msg: &TwistWithCovarianceStamped) -> Result<Self, Self::Error> {
        let t_s = time_to_seconds(&msg.header.stamp)?;
        let v = &msg.twist.twist.linear;
        let velocity = Vector3::new(v.x, v.y, v.z);
        if !velocity.iter().all(|c| c.is_finite()) {
            return Err(ConvertError::NonFiniteVelocity {
                t_s,
                field: "twist.linear",
            });
        }
        let c = &msg.twist.covariance;
        let block = Matrix3::from_fn(|r, k| c[6 * r + k]);
        if !block.iter().all(|x| x.is_finite()) {
            return Err(ConvertError::NonFiniteVelocity {
                t_s,
                field: "covariance",
            });
        }
        let unknown = block.iter().all(|x| *x == 0.0) || block[(0, 0)] == -1.0;
        Ok(Self {
            t_s,
            frame_id: msg.header.frame_id.clone(),
            velocity_enu_mps: velocity,
            covariance_enu_m2_s2: (!unknown).then_some(block),
        })
    }
}

/// The base controller's forward speed (`wheel/odometry`).
#[derive(Debug, Clone, PartialEq)]
pub struct WheelOdometrySpeed {
    /// Stamp (s).
    pub t_s: f64,
    /// `child_frame_id`: the frame of the twist.
    pub child_frame_id: String,
    /// Forward speed (m/s).
    pub speed_mps: f64,
    /// Its 1-sigma (m/s); None when the message gives no variance.
    pub sigma_mps: Option<f64>,
}

impl TryFrom<&Odometry> for WheelOdometrySpeed {
    type Error = ConvertError;

    /// Convention (REP-105, nav_msgs/Odometry): the twist is in `child_frame_id`, the
    /// vehicle's base frame (x forward); `twist.twist.linear.x` is the forward speed and
    /// `twist.covariance[0]` its variance; the rest is ignored. Choice: a variance of 0
    /// is none (ros2_controllers' diff_drive_controller sends 0 unless configured), and
    /// the configured σ applies; nav_msgs has no "unknown" marker (sensor_msgs' −1), so
    /// a negative variance is a broken message.
    fn try_from(msg: &Odometry) -> Result<Self, Self::Error> {
        let t_s = time_to_seconds(&msg.header.stamp)?;
        let speed_mps = msg.twist.twist.linear.x;
        if !speed_mps.is_finite() {
            return Err(ConvertError::InvalidWheelOdometry {
                t_s,
                field: "twist.twist.linear.x",
                value: speed_mps,
                expected: "finite",
            });
        }
        let variance = msg.twist.covariance[0];
        if !(variance.is_finite() && variance >= 0.0) {
            return Err(ConvertError::InvalidWheelOdometry {
                t_s,
                field: "twist.covariance[0]",
                value: variance,
                expected: "finite and not negative",
            });
        }
        Ok(Self {
            t_s,
            child_frame_id: msg.child_frame_id.clone(),
            speed_mps,
            sigma_mps: (variance > 0.0).then(|| variance.sqrt()),
        })
    }
}

/// Seconds of a ROS stamp as `f64`: `sec + nanosec / 1e9`.
///
/// Math note: `sec` and `nanosec` are exact in `f64` and `nanosec / 1e9` is correctly
/// rounded, so the sum carries one rounding: the result is within half an ulp (plus a
/// negligible 1e-17 s) of the exact stamp. That is below 0.5 ns for stamps under 2^23 s
/// (97 days: simulation and bag-relative times), so those come back exactly through
/// [`seconds_to_time`]; for UNIX stamps of today (2^30..2^31 s) an `f64` resolves 238 ns
/// and the error is at most 119 ns. Multiplying a total of nanoseconds by 1e-9 instead
/// would add a second rounding of a 1.7e18 ns integer (256 ns apart in `f64`).
pub fn time_to_seconds(stamp: &Time) -> Result<f64, ConvertError> {
    if stamp.nanosec >= NANOS_PER_SECOND {
        return Err(ConvertError::InvalidStamp {
            sec: stamp.sec,
            nanosec: stamp.nanosec,
        });
    }
    Ok(f64::from(stamp.sec) + f64::from(stamp.nanosec) / f64::from(NANOS_PER_SECOND))
}

/// The ROS stamp nearest to `t_s` seconds (ties of the nanosecond rounding away from 0).
///
/// Math note: the whole seconds are split off first, `fraction = t_s - floor(t_s)` is
/// exact (Sterbenz: `floor(t_s)` is within a factor 2 of `t_s` when |t_s| >= 1, and the
/// subtraction is trivial below), and only the fraction is scaled to nanoseconds, so the
/// result is the nearest nanosecond to the exact value of `t_s`. Converting back with
/// [`time_to_seconds`] returns `t_s` unchanged for |t_s| >= 2^23 s, where the `f64`
/// spacing exceeds 1 ns.
pub fn seconds_to_time(t_s: f64) -> Result<Time, ConvertError> {
    if !t_s.is_finite() {
        return Err(ConvertError::TimeOutOfRange { t_s });
    }
    let whole_s = t_s.floor();
    let fraction_s = t_s - whole_s;
    let nanos = (fraction_s * f64::from(NANOS_PER_SECOND)).round();
    // The rounding may reach a whole second (e.g. t_s = 0.9999999999).
    let (sec, nanos) = if nanos >= f64::from(NANOS_PER_SECOND) {
        (whole_s + 1.0, 0.0)
    } else {
        (whole_s, nanos)
    };
    if sec < f64::from(i32::MIN) || sec > f64::from(i32::MAX) {
        return Err(ConvertError::TimeOutOfRange { t_s });
    }
    // Both casts are exact: `sec` is an integer within i32, `nanos` an integer in [0, 1e9).
    Ok(Time {
        sec: sec as i32,
        nanosec: nanos as u32,
    })
}

/// Converts one epoch of raw measurements.
///
/// - `t_s` is `header.stamp` in seconds; the GPS time of week must lie in [0, 604800).
/// - NaN in an optional field (rate, sigmas, C/N0, atmospheric delays) becomes `None`;
///   an infinite value there, or a sigma that is not positive, is an error.
/// - Choice: the satellite's position, velocity, clock bias and drift are required (the
///   core type cannot say "absent"), and so is the pseudo-range unless the satellite
///   carries a carrier phase (a satellite kept for its phase alone, NaN range): a
///   non-finite value there rejects the whole epoch with an error naming the satellite,
///   rather than passing a NaN into the filter.
/// - The Klobuchar coefficients are kept only when all eight are finite (NaN = not
///   broadcast; a partial set is unusable).
/// - `gps_week` is not carried: the core needs only the time of week.
impl TryFrom<&GnssMeasurements> for GnssEpoch {
    type Error = ConvertError;

    fn try_from(msg: &GnssMeasurements) -> Result<Self, Self::Error> {
        let t_s = time_to_seconds(&msg.header.stamp)?;
        let tow_s = msg.gps_time_of_week_s;
        if !(0.0..SECONDS_PER_WEEK).contains(&tow_s) {
            return Err(ConvertError::InvalidTimeOfWeek { t_s, tow_s });
        }
        let satellites = msg
            .satellites
            .iter()
            .enumerate()
            .map(|(index, sat)| sat_observation(t_s, index, sat))
            .collect::<Result<Vec<_>, _>>()?;
        let all_finite = msg
            .klobuchar_alpha
            .iter()
            .chain(msg.klobuchar_beta.iter())
            .all(|c| c.is_finite());
        let klobuchar = all_finite.then_some(Klobuchar {
            alpha: msg.klobuchar_alpha,
            beta: msg.klobuchar_beta,
        });
        Ok(GnssEpoch {
            t_s,
            gps_time_of_week_s: tow_s,
            satellites,
            klobuchar,
        })
    }
}

/// Converts the satellite at `index` of an epoch stamped `t_s`.
fn sat_observation(
    t_s: f64,
    index: usize,
    m: &SatelliteMeasurement,
) -> Result<SatObservation, ConvertError> {
    let constellation =
        Constellation::from_code(m.constellation).ok_or(ConvertError::UnknownConstellation {
            t_s,
            index,
            code: m.constellation,
            prn: m.prn,
        })?;
    let sat = SatId {
        constellation,
        prn: m.prn,
    };
    let check = FieldCheck { t_s, sat };
    let pos = &m.satellite_position_ecef_m;
    let vel = &m.satellite_velocity_ecef_mps;
    let sat_pos_ecef_m = Vector3::new(
        check.required("satellite_position_ecef_m.x", pos.x)?,
        check.required("satellite_position_ecef_m.y", pos.y)?,
        check.required("satellite_position_ecef_m.z", pos.z)?,
    );
    let sat_vel_ecef_mps = Vector3::new(
        check.required("satellite_velocity_ecef_mps.x", vel.x)?,
        check.required("satellite_velocity_ecef_mps.y", vel.y)?,
        check.required("satellite_velocity_ecef_mps.z", vel.z)?,
    );
    let sat_clock_bias_s = check.required("satellite_clock_bias_s", m.satellite_clock_bias_s)?;
    let sat_clock_drift_s_s =
        check.required("satellite_clock_drift_s_s", m.satellite_clock_drift_s_s)?;
    // Choice: a satellite state no GNSS satellite has (gnss::satellite_bounds) rejects the
    // epoch like a non-finite one: a crafted or corrupted satellite velocity of 1e300 m/s
    // once put the start-up's velocity, and the whole run, 1,900 km off (attack suite).
    check.bounded(
        "|satellite_position_ecef_m|",
        sat_pos_ecef_m.norm(),
        MIN_ORBIT_RADIUS_M..=MAX_ORBIT_RADIUS_M,
        "a GNSS orbit radius, 2e7 to 5e7 m",
    )?;
    check.bounded(
        "|satellite_velocity_ecef_mps|",
        sat_vel_ecef_mps.norm(),
        0.0..=MAX_SAT_SPEED_MPS,
        "a GNSS satellite's speed, at most 1e4 m/s",
    )?;
    check.bounded(
        "|satellite_clock_bias_s|",
        sat_clock_bias_s.abs(),
        0.0..=MAX_SAT_CLOCK_BIAS_S,
        "at most 1 s",
    )?;
    check.bounded(
        "|satellite_clock_drift_s_s|",
        sat_clock_drift_s_s.abs(),
        0.0..=MAX_SAT_CLOCK_DRIFT_S_S,
        "at most 1e-6 s/s",
    )?;
    let carrier_phase = carrier_phase(&check, m)?;
    let pseudorange_m = if carrier_phase.is_some() {
        check.optional("pseudorange_m", m.pseudorange_m)?
    } else {
        Some(check.required("pseudorange_m", m.pseudorange_m)?)
    };
    Ok(SatObservation {
        sat,
        pseudorange_m,
        pseudorange_rate_mps: check.optional("pseudorange_rate_mps", m.pseudorange_rate_mps)?,
        pseudorange_sigma_m: check.sigma("pseudorange_sigma_m", m.pseudorange_sigma_m)?,
        pseudorange_rate_sigma_mps: check
            .sigma("pseudorange_rate_sigma_mps", m.pseudorange_rate_sigma_mps)?,
        cn0_dbhz: check.optional("cn0_dbhz", f64::from(m.cn0_dbhz))?,
        sat_pos_ecef_m,
        sat_vel_ecef_mps,
        sat_clock_bias_s,
        sat_clock_drift_s_s,
        iono_delay_m: check.optional("ionosphere_delay_m", m.ionosphere_delay_m)?,
        tropo_delay_m: check.optional("troposphere_delay_m", m.troposphere_delay_m)?,
        carrier_phase,
    })
}

/// The carrier phase of a satellite: None when `carrier_phase_cycles` is NaN (the other
/// carrier fields are then not read). A NaN wavelength, σ or lock time is unknown; an
/// infinite phase, a wavelength or σ that is not positive, or a negative lock time is an
/// error. Flag bits beyond the `CARRIER_*` constants are ignored.
fn carrier_phase(
    check: &FieldCheck,
    m: &SatelliteMeasurement,
) -> Result<Option<CarrierPhase>, ConvertError> {
    let Some(cycles) = check.optional("carrier_phase_cycles", m.carrier_phase_cycles)? else {
        return Ok(None);
    };
    let lock_time_s = check.optional("carrier_lock_time_s", m.carrier_lock_time_s)?;
    if lock_time_s.is_some_and(|t| t < 0.0) {
        return Err(check.error(
            "carrier_lock_time_s",
            m.carrier_lock_time_s,
            "a non-negative finite time or NaN (unknown)",
        ));
    }
    let flags = m.carrier_phase_flags;
    Ok(Some(CarrierPhase {
        cycles,
        wavelength_m: check.sigma("carrier_wavelength_m", m.carrier_wavelength_m)?,
        sigma_cycles: check.sigma("carrier_phase_sigma_cycles", m.carrier_phase_sigma_cycles)?,
        lock_time_s,
        loss_of_lock: flags & SatelliteMeasurement::CARRIER_LOSS_OF_LOCK != 0,
        half_cycle_unresolved: flags & SatelliteMeasurement::CARRIER_HALF_CYCLE_UNRESOLVED != 0,
    }))
}

/// Checks the fields of one satellite, naming it in the errors.
struct FieldCheck {
    t_s: f64,
    sat: SatId,
}

impl FieldCheck {
    /// The error for `field = value`, which should have been `expected`.
    fn error(&self, field: &'static str, value: f64, expected: &'static str) -> ConvertError {
        ConvertError::InvalidSatelliteField {
            t_s: self.t_s,
            sat: self.sat,
            field,
            value,
            expected,
        }
    }

    /// A value that must be present and finite.
    fn required(&self, field: &'static str, value: f64) -> Result<f64, ConvertError> {
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.error(field, value, "a finite number"))
        }
    }

    /// A value that is NaN when absent (-> `None`), finite otherwise.
    fn optional(&self, field: &'static str, value: f64) -> Result<Option<f64>, ConvertError> {
        if value.is_nan() {
            Ok(None)
        } else if value.is_finite() {
            Ok(Some(value))
        } else {
            Err(self.error(field, value, "a finite number or NaN (absent)"))
        }
    }

    /// A required value whose size must not exceed `limit` (`expected` says so).
    fn bounded(
        &self,
        field: &'static str,
        size: f64,
        limit: std::ops::RangeInclusive<f64>,
        expected: &'static str,
    ) -> Result<(), ConvertError> {
        if limit.contains(&size) {
            Ok(())
        } else {
            Err(self.error(field, size, expected))
        }
    }

    /// A 1σ (or another positive quantity such as a wavelength) that is NaN when unknown
    /// (-> `None`), positive and finite otherwise.
    fn sigma(&self, field: &'static str, value: f64) -> Result<Option<f64>, ConvertError> {
        if value.is_nan() {
            Ok(None)
        } else if value.is_finite() && value > 0.0 {
            Ok(Some(value))
        } else {
            Err(self.error(field, value, "a positive finite 1-sigma or NaN (unknown)"))
        }
    }
}

/// Converts a REP-145 IMU message: `angular_velocity` (rad/s) and `linear_acceleration`
/// (specific force, m/s²) taken as given, `t_s` from `header.stamp`. The orientation and
/// covariances are not used.
///
/// Choice: the vectors stay in the IMU frame `header.frame_id`; the engine rotates them
/// into the body frame from the configured mounting before mechanization.
impl TryFrom<&Imu> for ImuSample {
    type Error = ConvertError;

    fn try_from(imu: &Imu) -> Result<Self, Self::Error> {
        let t_s = time_to_seconds(&imu.header.stamp)?;
        let finite = |field: &'static str, v: &super::msg::Vector3| {
            let value = [v.x, v.y, v.z];
            if value.iter().all(|c| c.is_finite()) {
                Ok(Vector3::from(value))
            } else {
                Err(ConvertError::NonFiniteImu { t_s, field, value })
            }
        };
        Ok(ImuSample {
            t_s,
            w_ib_b_rad_s: finite("angular_velocity", &imu.angular_velocity)?,
            f_ib_b_m_s2: finite("linear_acceleration", &imu.linear_acceleration)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::ros::msg::{Header, NavSatStatus, Point, SatelliteMeasurement};

    /// `(m, e)` with `v = m * 2^e` exactly, for a normal positive `v`.
    fn decompose(v: f64) -> (i128, i32) {
        let bits = v.to_bits();
        let mantissa = (bits & ((1 << 52) - 1)) | (1 << 52);
        let exponent = ((bits >> 52) & 0x7ff) as i32 - 1075;
        (i128::from(mantissa), exponent)
    }

    /// `m * 1e9 - total_ns * 2^-e`: the error of `v` against `total_ns` nanoseconds,
    /// in units of 2^e ns, computed exactly in integers (needs -52 <= e <= 0).
    fn scaled_error(v: f64, total_ns: i128) -> (i128, i32) {
        let (m, e) = decompose(v);
        assert!((-52..=0).contains(&e), "test helper needs 1 <= v < 2^53");
        (m * 1_000_000_000 - (total_ns << -e), e)
    }

    fn total_ns(t: &Time) -> i128 {
        i128::from(t.sec) * 1_000_000_000 + i128::from(t.nanosec)
    }

    #[test]
    fn stamp_to_seconds_is_correctly_rounded() {
        // Reference: Python float(Fraction(1700000123456789012, 10**9)).
        let t = Time {
            sec: 1_700_000_123,
            nanosec: 456_789_012,
        };
        assert_eq!(
            time_to_seconds(&t).unwrap(),
            f64::from_bits(0x41d9_54fc_5edd_3c08)
        );
        let negative = Time {
            sec: -4,
            nanosec: 250_000_000,
        };
        assert_eq!(time_to_seconds(&negative).unwrap(), -3.75);
    }

    #[test]
    fn seconds_to_stamp_is_the_nearest_nanosecond() {
        // t = 1700000123.456789016723...: the f64 nearest to 1700000123.456789012.
        // Reference: Python round((Fraction(t) - 1700000123) * 10**9) = 456789017, where
        // the naive int(t * 1e9) is 25 ns off (456788992).
        let t = seconds_to_time(1_700_000_123.456_789).unwrap();
        assert_eq!(
            t,
            Time {
                sec: 1_700_000_123,
                nanosec: 456_789_017
            }
        );
        let t = seconds_to_time(12_345.000_000_001).unwrap();
        assert_eq!((t.sec, t.nanosec), (12_345, 1));
        let t = seconds_to_time(-1.25).unwrap();
        assert_eq!((t.sec, t.nanosec), (-2, 750_000_000));
        // Rounds up to a whole second: the carry goes into `sec`.
        let t = seconds_to_time(0.999_999_999_9).unwrap();
        assert_eq!((t.sec, t.nanosec), (1, 0));
        let t = seconds_to_time(-1e-20).unwrap();
        assert_eq!((t.sec, t.nanosec), (0, 0));
    }

    #[test]
    fn times_outside_the_stamp_range_are_errors() {
        assert_eq!(
            seconds_to_time(f64::from(i32::MIN)).unwrap(),
            Time {
                sec: i32::MIN,
                nanosec: 0
            }
        );
        for t_s in [2_147_483_648.0, -2_147_483_649.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                seconds_to_time(t_s),
                Err(ConvertError::TimeOutOfRange { .. })
            ));
        }
        let bad = Time {
            sec: 1,
            nanosec: 1_000_000_000,
        };
        assert_eq!(
            time_to_seconds(&bad),
            Err(ConvertError::InvalidStamp {
                sec: 1,
                nanosec: 1_000_000_000
            })
        );
    }

    proptest! {
        /// Error of `time_to_seconds` <= half an ulp + 2^-54 s, checked exactly.
        #[test]
        fn time_to_seconds_error_is_within_half_an_ulp(sec in 1..i32::MAX, nanosec in 0..1_000_000_000u32) {
            let t = Time { sec, nanosec };
            let (diff, e) = scaled_error(time_to_seconds(&t).unwrap(), total_ns(&t));
            // |diff| / (1e9 * 2^-e) s <= 2^(e-1) s + 2^-54 s.
            let bound = 500_000_000 + ((1_000_000_000_i128 << -e) >> 54) + 1;
            prop_assert!(diff.abs() <= bound, "diff {diff} > {bound}");
        }

        /// `seconds_to_time` gives the nanosecond nearest to the exact value of `t_s`.
        #[test]
        fn seconds_to_time_is_the_nearest_nanosecond(t_s in 1.0..2_147_483_647.0_f64) {
            let t = seconds_to_time(t_s).unwrap();
            let (diff, e) = scaled_error(t_s, total_ns(&t));
            // |diff| * 2^e ns <= 0.5 ns, plus the rounding of fraction * 1e9.
            let bound = (1_i128 << (-e - 1)) + ((1_i128 << -e) >> 20);
            prop_assert!(diff.abs() <= bound, "diff {diff} > {bound}");
        }

        /// Below 2^23 s an f64 resolves the nanosecond: stamps survive the round trip.
        #[test]
        fn short_stamps_survive_the_round_trip(sec in -(1 << 23)..(1 << 23), nanosec in 0..1_000_000_000u32) {
            let t = Time { sec, nanosec };
            prop_assert_eq!(seconds_to_time(time_to_seconds(&t).unwrap()).unwrap(), t);
        }

        /// From 2^23 s on, the f64 spacing exceeds 1 ns: f64 times survive the round trip.
        #[test]
        fn long_times_survive_the_round_trip(t_s in 8_388_608.0..2_147_483_647.0_f64) {
            prop_assert_eq!(time_to_seconds(&seconds_to_time(t_s).unwrap()).unwrap(), t_s);
        }
    }

    fn gps_satellite() -> SatelliteMeasurement {
        SatelliteMeasurement {
            constellation: SatelliteMeasurement::GPS,
            prn: 5,
            pseudorange_m: 21_456_789.125,
            pseudorange_rate_mps: -345.5,
            pseudorange_sigma_m: 2.5,
            pseudorange_rate_sigma_mps: 0.125,
            cn0_dbhz: 45.25,
            satellite_position_ecef_m: Point {
                x: 15_600_000.5,
                y: -7_540_000.25,
                z: 20_140_000.75,
            },
            satellite_velocity_ecef_mps: crate::ros::msg::Vector3 {
                x: -1_200.5,
                y: 2_300.25,
                z: 850.125,
            },
            satellite_clock_bias_s: 1.234e-4,
            satellite_clock_drift_s_s: -5.6e-12,
            ionosphere_delay_m: f64::NAN,
            troposphere_delay_m: f64::NAN,
            carrier_phase_cycles: 112_755_213.375,
            carrier_wavelength_m: 0.190_293_672_798,
            carrier_phase_sigma_cycles: 0.012,
            carrier_lock_time_s: 12.5,
            carrier_phase_flags: SatelliteMeasurement::CARRIER_HALF_CYCLE_UNRESOLVED | 0x80,
        }
    }

    fn epoch_msg() -> GnssMeasurements {
        GnssMeasurements {
            header: Header {
                stamp: Time {
                    sec: 1000,
                    nanosec: 500_000_000,
                },
                frame_id: "gnss".to_string(),
            },
            gps_week: 2288,
            gps_time_of_week_s: 1000.5,
            satellites: vec![gps_satellite(), gps_satellite()],
            klobuchar_alpha: [1e-8, 2e-8, -6e-8, -6e-8],
            klobuchar_beta: [9e4, 0.0, -2e5, -6e4],
        }
    }

    fn field_error(msg: &GnssMeasurements) -> (String, &'static str) {
        match GnssEpoch::try_from(msg) {
            Err(ConvertError::InvalidSatelliteField { sat, field, .. }) => (sat.to_string(), field),
            other => panic!("expected InvalidSatelliteField, got {other:?}"),
        }
    }

    #[test]
    fn a_clean_epoch_converts() {
        let epoch = GnssEpoch::try_from(&epoch_msg()).unwrap();
        assert_eq!(epoch.t_s, 1000.5);
        assert_eq!(epoch.satellites.len(), 2);
        let sat = &epoch.satellites[0];
        assert_eq!(sat.sat.to_string(), "G05");
        assert_eq!(sat.pseudorange_rate_sigma_mps, Some(0.125));
        assert_eq!(sat.iono_delay_m, None);
        assert_eq!(sat.sat_clock_drift_s_s, -5.6e-12);
        assert_eq!(epoch.klobuchar.unwrap().beta[2], -2e5);
    }

    #[test]
    fn unknown_constellation_names_the_satellite() {
        let mut msg = epoch_msg();
        msg.satellites[1].constellation = 9;
        msg.satellites[1].prn = 33;
        let err = GnssEpoch::try_from(&msg).unwrap_err();
        assert_eq!(
            err,
            ConvertError::UnknownConstellation {
                t_s: 1000.5,
                index: 1,
                code: 9,
                prn: 33
            }
        );
        assert!(err.to_string().contains("PRN 33"));
    }

    #[test]
    fn a_satellite_with_a_phase_may_come_without_a_range() {
        let mut msg = epoch_msg();
        msg.satellites[1].pseudorange_m = f64::NAN;
        msg.satellites[1].pseudorange_sigma_m = f64::NAN;
        let epoch = GnssEpoch::try_from(&msg).unwrap();
        let sat = &epoch.satellites[1];
        assert_eq!((sat.pseudorange_m, sat.pseudorange_sigma_m), (None, None));
        assert_eq!(sat.carrier_phase.unwrap().cycles, 112_755_213.375);
        assert_eq!(epoch.satellites[0].pseudorange_m, Some(21_456_789.125));
        // Infinity is never "absent".
        msg.satellites[1].pseudorange_m = f64::INFINITY;
        assert_eq!(field_error(&msg).1, "pseudorange_m");
    }

    #[test]
    fn non_finite_required_fields_name_the_satellite() {
        let mut msg = epoch_msg();
        msg.satellites[1].constellation = SatelliteMeasurement::GALILEO;
        msg.satellites[1].prn = 12;
        msg.satellites[1].pseudorange_m = f64::NAN;
        msg.satellites[1].carrier_phase_cycles = f64::NAN;
        assert_eq!(field_error(&msg), ("E12".to_string(), "pseudorange_m"));
        let err = GnssEpoch::try_from(&msg).unwrap_err().to_string();
        assert!(
            err.contains("E12") && err.contains("pseudorange_m"),
            "{err}"
        );

        let mut msg = epoch_msg();
        msg.satellites[0].satellite_position_ecef_m.y = f64::INFINITY;
        assert_eq!(
            field_error(&msg),
            ("G05".to_string(), "satellite_position_ecef_m.y")
        );
        let mut msg = epoch_msg();
        msg.satellites[0].satellite_clock_bias_s = f64::NAN;
        assert_eq!(
            field_error(&msg),
            ("G05".to_string(), "satellite_clock_bias_s")
        );
    }

    #[test]
    fn a_satellite_state_no_gnss_satellite_has_names_the_field() {
        type Corruption = fn(&mut SatelliteMeasurement);
        let cases: [(Corruption, &str); 5] = [
            (
                // On the ground.
                |s| {
                    s.satellite_position_ecef_m = Point {
                        x: 6.4e6,
                        y: 0.0,
                        z: 0.0,
                    }
                },
                "|satellite_position_ecef_m|",
            ),
            (
                |s| s.satellite_position_ecef_m.z = 1e300,
                "|satellite_position_ecef_m|",
            ),
            (
                |s| s.satellite_velocity_ecef_mps.z = 1e300,
                "|satellite_velocity_ecef_mps|",
            ),
            (
                |s| s.satellite_clock_bias_s = -2.0,
                "|satellite_clock_bias_s|",
            ),
            (
                |s| s.satellite_clock_drift_s_s = 1e-3,
                "|satellite_clock_drift_s_s|",
            ),
        ];
        for (corrupt, field) in cases {
            let mut msg = epoch_msg();
            corrupt(&mut msg.satellites[1]);
            assert_eq!(field_error(&msg), ("G05".to_string(), field));
        }
    }

    #[test]
    fn optional_fields_take_nan_but_not_infinity_or_bad_sigmas() {
        let mut msg = epoch_msg();
        msg.satellites[0].troposphere_delay_m = f64::NEG_INFINITY;
        assert_eq!(field_error(&msg).1, "troposphere_delay_m");
        let mut msg = epoch_msg();
        msg.satellites[0].cn0_dbhz = f32::INFINITY;
        assert_eq!(field_error(&msg).1, "cn0_dbhz");
        for sigma in [0.0, -1.0, f64::INFINITY] {
            let mut msg = epoch_msg();
            msg.satellites[0].pseudorange_sigma_m = sigma;
            assert_eq!(field_error(&msg).1, "pseudorange_sigma_m");
        }
        let mut msg = epoch_msg();
        msg.satellites[0].pseudorange_rate_mps = f64::NAN;
        msg.satellites[0].cn0_dbhz = f32::NAN;
        let sat = &GnssEpoch::try_from(&msg).unwrap().satellites[0];
        assert_eq!((sat.pseudorange_rate_mps, sat.cn0_dbhz), (None, None));
    }

    #[test]
    fn carrier_phase_converts_with_its_flags_and_unknowns() {
        let sat = &GnssEpoch::try_from(&epoch_msg()).unwrap().satellites[0];
        let phase = sat.carrier_phase.unwrap();
        assert_eq!(phase.cycles, 112_755_213.375);
        assert_eq!(phase.wavelength_m, Some(0.190_293_672_798));
        assert_eq!(phase.sigma_cycles, Some(0.012));
        assert_eq!(phase.lock_time_s, Some(12.5));
        assert!(!phase.loss_of_lock && phase.half_cycle_unresolved);

        let mut msg = epoch_msg();
        let m = &mut msg.satellites[0];
        m.carrier_wavelength_m = f64::NAN;
        m.carrier_phase_sigma_cycles = f64::NAN;
        m.carrier_lock_time_s = f64::NAN;
        m.carrier_phase_flags = SatelliteMeasurement::CARRIER_LOSS_OF_LOCK;
        let phase = GnssEpoch::try_from(&msg).unwrap().satellites[0]
            .carrier_phase
            .unwrap();
        assert_eq!(
            (phase.wavelength_m, phase.sigma_cycles, phase.lock_time_s),
            (None, None, None)
        );
        assert!(phase.loss_of_lock && !phase.half_cycle_unresolved);

        // No phase: the other carrier fields are not read.
        let mut msg = epoch_msg();
        msg.satellites[0].carrier_phase_cycles = f64::NAN;
        msg.satellites[0].carrier_wavelength_m = -1.0;
        assert_eq!(
            GnssEpoch::try_from(&msg).unwrap().satellites[0].carrier_phase,
            None
        );
    }

    #[test]
    fn malformed_carrier_fields_name_the_field() {
        type Spoil = fn(&mut SatelliteMeasurement);
        let cases: [(Spoil, &str); 4] = [
            (
                |m| m.carrier_phase_cycles = f64::INFINITY,
                "carrier_phase_cycles",
            ),
            (|m| m.carrier_wavelength_m = 0.0, "carrier_wavelength_m"),
            (
                |m| m.carrier_phase_sigma_cycles = -0.01,
                "carrier_phase_sigma_cycles",
            ),
            (|m| m.carrier_lock_time_s = -1.0, "carrier_lock_time_s"),
        ];
        for (spoil, field) in cases {
            let mut msg = epoch_msg();
            spoil(&mut msg.satellites[0]);
            assert_eq!(field_error(&msg), ("G05".to_string(), field));
        }
    }

    #[test]
    fn klobuchar_needs_all_eight_coefficients() {
        let mut msg = epoch_msg();
        msg.klobuchar_beta[3] = f64::NAN;
        assert_eq!(GnssEpoch::try_from(&msg).unwrap().klobuchar, None);
    }

    #[test]
    fn time_of_week_outside_a_week_is_an_error() {
        for tow_s in [-0.5, 604_800.0, f64::NAN] {
            let mut msg = epoch_msg();
            msg.gps_time_of_week_s = tow_s;
            assert!(matches!(
                GnssEpoch::try_from(&msg),
                Err(ConvertError::InvalidTimeOfWeek { .. })
            ));
        }
        let mut msg = epoch_msg();
        msg.header.stamp.nanosec = 1_000_000_000;
        assert!(matches!(
            GnssEpoch::try_from(&msg),
            Err(ConvertError::InvalidStamp { .. })
        ));
    }

    fn imu_msg() -> Imu {
        let mut imu = Imu::default();
        imu.header.stamp = Time {
            sec: 12,
            nanosec: 250_000_000,
        };
        imu.angular_velocity.z = 0.5;
        imu.linear_acceleration.z = 9.81;
        imu
    }

    #[test]
    fn imu_vectors_pass_unchanged() {
        let sample = ImuSample::try_from(&imu_msg()).unwrap();
        assert_eq!(sample.t_s, 12.25);
        assert_eq!(sample.w_ib_b_rad_s, Vector3::new(0.0, 0.0, 0.5));
        assert_eq!(sample.f_ib_b_m_s2, Vector3::new(0.0, 0.0, 9.81));
    }

    #[test]
    fn non_finite_imu_vectors_are_errors() {
        let mut imu = imu_msg();
        imu.angular_velocity.y = f64::NAN;
        assert!(matches!(
            ImuSample::try_from(&imu),
            Err(ConvertError::NonFiniteImu { field: "angular_velocity", t_s, .. }) if t_s == 12.25
        ));
        let mut imu = imu_msg();
        imu.linear_acceleration.x = f64::NEG_INFINITY;
        assert!(matches!(
            ImuSample::try_from(&imu),
            Err(ConvertError::NonFiniteImu {
                field: "linear_acceleration",
                ..
            })
        ));
    }

    #[test]
    fn gnss_velocity_is_the_linear_twist_in_enu() {
        let mut msg = TwistWithCovarianceStamped::default();
        msg.header.stamp = Time {
            sec: 7,
            nanosec: 250_000_000,
        };
        msg.header.frame_id = "map".to_owned();
        msg.twist.twist.linear.x = 1.5;
        msg.twist.twist.linear.y = -2.0;
        msg.twist.twist.angular.z = 9.0;
        let v = GnssVelocity::try_from(&msg).unwrap();
        assert_eq!(v.t_s, 7.25);
        assert_eq!(v.frame_id, "map");
        assert_eq!(v.velocity_enu_mps, Vector3::new(1.5, -2.0, 0.0));
        assert_eq!(v.covariance_enu_m2_s2, None, "all-zero covariance: unknown");
        msg.twist.covariance[0] = 0.04;
        msg.twist.covariance[7] = 0.09;
        msg.twist.covariance[14] = 0.16;
        msg.twist.covariance[21] = 5.0; // angular: ignored
        let c = GnssVelocity::try_from(&msg)
            .unwrap()
            .covariance_enu_m2_s2
            .unwrap();
        assert_eq!(c, Matrix3::from_diagonal(&Vector3::new(0.04, 0.09, 0.16)));
        msg.twist.covariance[0] = -1.0;
        assert_eq!(
            GnssVelocity::try_from(&msg).unwrap().covariance_enu_m2_s2,
            None
        );
        msg.twist.covariance[8] = f64::NAN;
        assert!(matches!(
            GnssVelocity::try_from(&msg),
            Err(ConvertError::NonFiniteVelocity {
                field: "covariance",
                ..
            })
        ));
        msg.twist.covariance[8] = 0.0;
        msg.twist.twist.linear.z = f64::INFINITY;
        assert!(matches!(
            GnssVelocity::try_from(&msg),
            Err(ConvertError::NonFiniteVelocity {
                field: "twist.linear",
                ..
            })
        ));
    }

    #[test]
    fn wheel_speed_is_the_forward_twist_of_the_odometry() {
        let mut msg = Odometry::default();
        msg.header.stamp = Time {
            sec: 3,
            nanosec: 500_000_000,
        };
        msg.header.frame_id = "odom".to_owned();
        msg.child_frame_id = "base_link".to_owned();
        msg.twist.twist.linear.x = -1.25;
        msg.twist.twist.linear.y = 4.0; // lateral: ignored
        let w = WheelOdometrySpeed::try_from(&msg).unwrap();
        assert_eq!(
            w,
            WheelOdometrySpeed {
                t_s: 3.5,
                child_frame_id: "base_link".to_owned(),
                speed_mps: -1.25,
                sigma_mps: None,
            }
        );
        msg.twist.covariance[0] = 0.0004;
        msg.twist.covariance[7] = 9.0; // lateral: ignored
        let sigma = WheelOdometrySpeed::try_from(&msg).unwrap().sigma_mps;
        assert_eq!(sigma, Some(0.02));
        for (variance, speed) in [
            (-1.0, 1.0),
            (f64::NAN, 1.0),
            (f64::INFINITY, 1.0),
            (0.0004, f64::NAN),
            (0.0004, f64::NEG_INFINITY),
        ] {
            msg.twist.covariance[0] = variance;
            msg.twist.twist.linear.x = speed;
            assert!(
                matches!(
                    WheelOdometrySpeed::try_from(&msg),
                    Err(ConvertError::InvalidWheelOdometry { t_s, .. }) if t_s == 3.5
                ),
                "variance {variance}, speed {speed}"
            );
        }
    }

    #[test]
    fn receiver_fix_from_a_nav_sat_fix_with_a_solution() {
        let mut msg = NavSatFix::default();
        msg.header.stamp = Time {
            sec: 12,
            nanosec: 500_000_000,
        };
        (msg.latitude, msg.longitude, msg.altitude) = (39.1, 117.2, 10.0);
        msg.position_covariance = [4.0, 0.5, 0.0, 0.5, 9.0, 0.0, 0.0, 0.0, 16.0];
        msg.position_covariance_type = NavSatFix::COVARIANCE_TYPE_KNOWN;
        let fix = GnssFix::try_from(&msg).unwrap();
        assert_eq!(fix.t_s, 12.5);
        assert_eq!(fix.position, Llh::from_degrees(39.1, 117.2, 10.0));
        let c = fix.position_covariance_enu_m2.unwrap();
        assert_eq!(
            (c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(2, 2)]),
            (4.0, 0.5, 0.5, 16.0)
        );
        assert_eq!(fix.velocity_enu_mps, None, "the velocity joins later");
        msg.position_covariance_type = NavSatFix::COVARIANCE_TYPE_UNKNOWN;
        assert_eq!(
            GnssFix::try_from(&msg).unwrap().position_covariance_enu_m2,
            None
        );
        msg.status.status = NavSatStatus::STATUS_NO_FIX;
        assert_eq!(
            GnssFix::try_from(&msg),
            Err(ConvertError::NoFix {
                t_s: 12.5,
                status: -1
            })
        );
        msg.header.stamp.nanosec = 1_000_000_000;
        assert!(matches!(
            GnssFix::try_from(&msg),
            Err(ConvertError::InvalidStamp { .. })
        ));
    }
}
