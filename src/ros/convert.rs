//! Wire messages -> core types, and ROS time <-> `f64` seconds.
//!
//! Conversions only: no filter math, and no frame rotation. In particular the IMU
//! vectors stay in the IMU's own frame (`header.frame_id`); the engine rotates them into
//! the body frame from the configured mounting.

use nalgebra::Vector3;

use super::msg::{GnssMeasurements, Imu, SatelliteMeasurement, Time};
use crate::gnss::{Constellation, GnssEpoch, Klobuchar, SatId, SatObservation};
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
/// - Choice: the pseudo-range and the satellite's position, velocity, clock bias and
///   drift are required (the core type cannot say "absent"): a non-finite value there
///   rejects the whole epoch with an error naming the satellite, rather than passing a
///   NaN into the filter.
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
    Ok(SatObservation {
        sat,
        pseudorange_m: check.required("pseudorange_m", m.pseudorange_m)?,
        pseudorange_rate_mps: check.optional("pseudorange_rate_mps", m.pseudorange_rate_mps)?,
        pseudorange_sigma_m: check.sigma("pseudorange_sigma_m", m.pseudorange_sigma_m)?,
        pseudorange_rate_sigma_mps: check
            .sigma("pseudorange_rate_sigma_mps", m.pseudorange_rate_sigma_mps)?,
        cn0_dbhz: check.optional("cn0_dbhz", f64::from(m.cn0_dbhz))?,
        sat_pos_ecef_m: Vector3::new(
            check.required("satellite_position_ecef_m.x", pos.x)?,
            check.required("satellite_position_ecef_m.y", pos.y)?,
            check.required("satellite_position_ecef_m.z", pos.z)?,
        ),
        sat_vel_ecef_mps: Vector3::new(
            check.required("satellite_velocity_ecef_mps.x", vel.x)?,
            check.required("satellite_velocity_ecef_mps.y", vel.y)?,
            check.required("satellite_velocity_ecef_mps.z", vel.z)?,
        ),
        sat_clock_bias_s: check.required("satellite_clock_bias_s", m.satellite_clock_bias_s)?,
        sat_clock_drift_s_s: check
            .required("satellite_clock_drift_s_s", m.satellite_clock_drift_s_s)?,
        iono_delay_m: check.optional("ionosphere_delay_m", m.ionosphere_delay_m)?,
        tropo_delay_m: check.optional("troposphere_delay_m", m.troposphere_delay_m)?,
    })
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

    /// A 1σ that is NaN when unknown (-> `None`), positive and finite otherwise.
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
