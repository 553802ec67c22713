//! Core types to ROS messages: the engine's outputs as nav_msgs/Odometry (REP-103/105: pose in a local ENU
//! frame at the datum, twist in the body frame), its TF (tf2_msgs/TFMessage),
//! sensor_msgs/NavSatFix and our NoiseEstimates (the covariance-diagnostic topic); and
//! simulated inputs as Imu,
//! GnssMeasurements, NavSatFix and the receiver velocity (for writing bags).

use nalgebra::{Matrix3, SMatrix};

use crate::earth::{self, Llh};
use crate::engine::{EpochReport, SatRejection, Solution};
use crate::gnss::Constellation;
use crate::ins::error_state::{DV, GYRO_BIAS, GYRO_GM};

use super::msg::{
    GnssMeasurements, Header, Imu, NavSatFix, NavSatStatus, NoiseEstimates, Odometry, Point, Pose,
    PoseWithCovariance, Quaternion, SatelliteMeasurement, SatelliteNoise, TFMessage, Time,
    Transform, TransformStamped, Twist, TwistWithCovariance, TwistWithCovarianceStamped, Vector3,
};

fn vector3(v: &nalgebra::Vector3<f64>) -> Vector3 {
    Vector3 {
        x: v[0],
        y: v[1],
        z: v[2],
    }
}

fn row_major_6(m: &SMatrix<f64, 6, 6>) -> [f64; 36] {
    std::array::from_fn(|k| m[(k / 6, k % 6)])
}

/// nav_msgs/Odometry of `solution`: pose of the body in the ENU frame `frame_id` whose
/// origin is `datum`; twist in the body frame `child_frame_id`.
///
/// Covariances: the pose's (E, N, U, rotations about E, N, U) from the filter; the twist's
/// linear part is the ENU velocity covariance rotated into the body; its angular part is
/// the covariance of the estimated gyro bias (the rate itself is measured).
pub fn odometry(
    solution: &Solution,
    datum: &Llh,
    stamp: Time,
    frame_id: &str,
    child_frame_id: &str,
) -> Odometry {
    let nav = &solution.nav;
    let position = earth::llh_to_enu(&nav.p, datum);
    let q = nav.q_nb.quaternion();
    let c_nb = nav.q_nb.inverse();
    let w_in = earth::earth_rate_enu_rad_s(nav.p.lat_rad)
        + earth::transport_rate_enu_rad_s(&nav.p, &nav.v_n);
    let angular = solution.angular_rate_b_rad_s - c_nb * w_in;
    let c = c_nb.to_rotation_matrix().into_inner();
    let p_v: Matrix3<f64> = solution.covariance.fixed_view::<3, 3>(DV, DV).into();
    let p_bias: Matrix3<f64> = solution
        .covariance
        .fixed_view::<3, 3>(GYRO_BIAS, GYRO_BIAS)
        .into_owned()
        + solution.covariance.fixed_view::<3, 3>(GYRO_GM, GYRO_GM);
    let mut twist_cov = SMatrix::<f64, 6, 6>::zeros();
    twist_cov
        .fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(c * p_v * c.transpose()));
    twist_cov.fixed_view_mut::<3, 3>(3, 3).copy_from(&p_bias);
    Odometry {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        child_frame_id: child_frame_id.to_owned(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Point {
                    x: position[0],
                    y: position[1],
                    z: position[2],
                },
                orientation: Quaternion {
                    x: q.i,
                    y: q.j,
                    z: q.k,
                    w: q.w,
                },
            },
            covariance: row_major_6(&solution.pose_covariance_enu()),
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: vector3(&(c_nb * nav.v_n)),
                angular: vector3(&angular),
            },
            covariance: row_major_6(&twist_cov),
        },
    }
}

/// The `/tf` message of an Odometry: the transform from its `header.frame_id` to its
/// `child_frame_id` at its stamp, translation its position and rotation its orientation
/// (the pose of the body in the map frame is exactly the map → body transform).
pub fn transform(odometry: &Odometry) -> TFMessage {
    let pose = &odometry.pose.pose;
    TFMessage {
        transforms: vec![TransformStamped {
            header: odometry.header.clone(),
            child_frame_id: odometry.child_frame_id.clone(),
            transform: Transform {
                translation: Vector3 {
                    x: pose.position.x,
                    y: pose.position.y,
                    z: pose.position.z,
                },
                rotation: pose.orientation,
            },
        }],
    }
}

/// The transform `header.frame_id` → `child_frame_id` that places the child at `pose` in
/// the parent frame.
pub fn transform_stamped(
    header: Header,
    child_frame_id: &str,
    pose: &nalgebra::Isometry3<f64>,
) -> TransformStamped {
    let q = pose.rotation.quaternion();
    TransformStamped {
        header,
        child_frame_id: child_frame_id.to_owned(),
        transform: Transform {
            translation: vector3(&pose.translation.vector),
            rotation: Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            },
        },
    }
}

/// sensor_msgs/NavSatFix of the body position, with the filter's ENU covariance (known);
/// `service` holds the bits of the constellations the filter used ([`service_of`]).
pub fn nav_sat_fix(solution: &Solution, stamp: Time, frame_id: &str, service: u16) -> NavSatFix {
    let p = &solution.nav.p;
    let cov = solution.position_covariance_enu_m2();
    NavSatFix {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        status: NavSatStatus {
            status: NavSatStatus::STATUS_FIX,
            service,
        },
        latitude: p.lat_rad.to_degrees(),
        longitude: p.lon_rad.to_degrees(),
        altitude: p.height_m,
        position_covariance: std::array::from_fn(|k| cov[(k / 3, k % 3)]),
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_KNOWN,
    }
}

/// sensor_msgs/NavSatFix saying the filter has no position at `stamp` (a solution it
/// could not publish: a value not finite, a negative variance).
///
/// Choice: `STATUS_NO_FIX`, the position NaN (no number is a confident wrong answer; the
/// message's own convention for an unknown altitude) and covariance type `UNKNOWN`.
pub fn no_fix(stamp: Time, frame_id: &str) -> NavSatFix {
    NavSatFix {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        status: NavSatStatus {
            status: NavSatStatus::STATUS_NO_FIX,
            service: NavSatStatus::SERVICE_UNKNOWN,
        },
        latitude: f64::NAN,
        longitude: f64::NAN,
        altitude: f64::NAN,
        position_covariance: [0.0; 9],
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_UNKNOWN,
    }
}

/// The `NavSatStatus` service bits of the constellations in `used`.
///
/// Choice: QZSS and SBAS have no bit of their own in `NavSatStatus` (GPS, GLONASS, COMPASS
/// for BeiDou, GALILEO) and add none rather than claim GPS.
pub fn service_of(used: impl IntoIterator<Item = Constellation>) -> u16 {
    used.into_iter()
        .fold(NavSatStatus::SERVICE_UNKNOWN, |bits, c| {
            bits | match c {
                Constellation::Gps => NavSatStatus::SERVICE_GPS,
                Constellation::Glonass => NavSatStatus::SERVICE_GLONASS,
                Constellation::Galileo => NavSatStatus::SERVICE_GALILEO,
                Constellation::Beidou => NavSatStatus::SERVICE_COMPASS,
                Constellation::Qzss | Constellation::Sbas => NavSatStatus::SERVICE_UNKNOWN,
            }
        })
}

fn rejection_code(reason: Option<SatRejection>) -> u8 {
    match reason {
        None => SatelliteNoise::REJECTION_NONE,
        Some(SatRejection::ElevationMask) => SatelliteNoise::REJECTION_ELEVATION_MASK,
        Some(SatRejection::Cn0Mask) => SatelliteNoise::REJECTION_CN0_MASK,
        Some(SatRejection::InnovationGate) => SatelliteNoise::REJECTION_INNOVATION_GATE,
        Some(SatRejection::NotANumber) => SatelliteNoise::REJECTION_NOT_A_NUMBER,
        Some(SatRejection::NoSatelliteState) => SatelliteNoise::REJECTION_NO_EPHEMERIS_STATE,
        Some(SatRejection::Mahalanobis) => SatelliteNoise::REJECTION_MAHALANOBIS,
        Some(SatRejection::ConstellationDisabled) => {
            SatelliteNoise::REJECTION_CONSTELLATION_DISABLED
        }
    }
}

/// Our NoiseEstimates message of one epoch report.
pub fn noise_estimates(report: &EpochReport, stamp: Time, frame_id: &str) -> NoiseEstimates {
    NoiseEstimates {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        filter_variant: report.variant.to_owned(),
        satellites: report
            .satellites
            .iter()
            .map(|s| SatelliteNoise {
                constellation: s.sat.constellation.code(),
                prn: s.sat.prn,
                elevation_deg: s.elevation_rad.to_degrees(),
                used: s.used_pseudorange || s.used_rate,
                rejection_reason: rejection_code(s.rejection),
                innovation_pseudorange_m: s.innovation_pseudorange_m,
                innovation_pseudorange_rate_mps: s.innovation_rate_mps,
                normalized_innovation_pseudorange: s.normalized_innovation_pseudorange,
                normalized_innovation_pseudorange_rate: s.normalized_innovation_rate,
                r_pseudorange_m2: s.r_pseudorange_m2,
                r_pseudorange_rate_m2_s2: s.r_rate_m2_s2,
                kde_credibility: s.kde_credibility,
                gaussian: s.gaussian.unwrap_or(true),
                ar_order: s.ar_order.unwrap_or(0),
                robust_weight: s.robust_weight,
            })
            .collect(),
        adaptive_factor: report.adaptive_factor,
        mahalanobis_d2: report.mahalanobis_d2,
        chi2_threshold: report.chi2_threshold,
        q_scale: report.q_scale,
        nis: report.nis,
    }
}

/// sensor_msgs/Imu of a sample (REP-145; orientation unknown: `covariance[0] = −1`).
pub fn imu(sample: &crate::ins::ImuSample, stamp: Time, frame_id: &str) -> Imu {
    let mut orientation_covariance = [0.0; 9];
    orientation_covariance[0] = -1.0;
    Imu {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        orientation: Quaternion::default(),
        orientation_covariance,
        angular_velocity: vector3(&sample.w_ib_b_rad_s),
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: vector3(&sample.f_ib_b_m_s2),
        linear_acceleration_covariance: [0.0; 9],
    }
}

/// Our GnssMeasurements message of an epoch (absent values as NaN).
pub fn gnss_measurements(
    epoch: &crate::gnss::GnssEpoch,
    gps_week: u16,
    stamp: Time,
    frame_id: &str,
) -> GnssMeasurements {
    let nan = f64::NAN;
    GnssMeasurements {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        gps_week,
        gps_time_of_week_s: epoch.gps_time_of_week_s,
        satellites: epoch
            .satellites
            .iter()
            .map(|s| SatelliteMeasurement {
                constellation: s.sat.constellation.code(),
                prn: s.sat.prn,
                pseudorange_m: s.pseudorange_m.unwrap_or(nan),
                pseudorange_rate_mps: s.pseudorange_rate_mps.unwrap_or(nan),
                pseudorange_sigma_m: s.pseudorange_sigma_m.unwrap_or(nan),
                pseudorange_rate_sigma_mps: s.pseudorange_rate_sigma_mps.unwrap_or(nan),
                cn0_dbhz: s.cn0_dbhz.map_or(f32::NAN, |c| c as f32),
                satellite_position_ecef_m: Point {
                    x: s.sat_pos_ecef_m[0],
                    y: s.sat_pos_ecef_m[1],
                    z: s.sat_pos_ecef_m[2],
                },
                satellite_velocity_ecef_mps: vector3(&s.sat_vel_ecef_mps),
                satellite_clock_bias_s: s.sat_clock_bias_s,
                satellite_clock_drift_s_s: s.sat_clock_drift_s_s,
                ionosphere_delay_m: s.iono_delay_m.unwrap_or(nan),
                troposphere_delay_m: s.tropo_delay_m.unwrap_or(nan),
                carrier_phase_cycles: s.carrier_phase.map_or(nan, |c| c.cycles),
                carrier_wavelength_m: s.carrier_phase.and_then(|c| c.wavelength_m).unwrap_or(nan),
                carrier_phase_sigma_cycles: s
                    .carrier_phase
                    .and_then(|c| c.sigma_cycles)
                    .unwrap_or(nan),
                carrier_lock_time_s: s.carrier_phase.and_then(|c| c.lock_time_s).unwrap_or(nan),
                carrier_phase_flags: s.carrier_phase.map_or(0, carrier_phase_flags),
            })
            .collect(),
        klobuchar_alpha: epoch.klobuchar.map_or([nan; 4], |k| k.alpha),
        klobuchar_beta: epoch.klobuchar.map_or([nan; 4], |k| k.beta),
    }
}

/// The `CARRIER_*` bits of a carrier phase.
fn carrier_phase_flags(c: crate::gnss::CarrierPhase) -> u8 {
    let bit = |set: bool, value: u8| if set { value } else { 0 };
    bit(c.loss_of_lock, SatelliteMeasurement::CARRIER_LOSS_OF_LOCK)
        | bit(
            c.half_cycle_unresolved,
            SatelliteMeasurement::CARRIER_HALF_CYCLE_UNRESOLVED,
        )
}

/// sensor_msgs/NavSatFix of a receiver fix (ENU covariance, known or the diagonal given).
pub fn receiver_fix(fix: &crate::engine::GnssFix, stamp: Time, frame_id: &str) -> NavSatFix {
    let (cov, kind) = match fix.position_covariance_enu_m2 {
        Some(c) => (
            std::array::from_fn(|k| c[(k / 3, k % 3)]),
            NavSatFix::COVARIANCE_TYPE_KNOWN,
        ),
        None => ([0.0; 9], NavSatFix::COVARIANCE_TYPE_UNKNOWN),
    };
    NavSatFix {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        status: NavSatStatus {
            status: NavSatStatus::STATUS_FIX,
            service: NavSatStatus::SERVICE_GPS,
        },
        latitude: fix.position.lat_rad.to_degrees(),
        longitude: fix.position.lon_rad.to_degrees(),
        altitude: fix.position.height_m,
        position_covariance: cov,
        position_covariance_type: kind,
    }
}

/// The receiver velocity of `fix` as `gnss/velocity` carries it (None when the fix has
/// none): the ENU velocity as the twist's linear part, its covariance (when the fix has
/// one) as the linear block, stamped like the fix. The angular part is unknown: zero, its
/// covariance block −1 on the diagonal (the reader ignores it).
pub fn receiver_velocity(
    fix: &crate::engine::GnssFix,
    stamp: Time,
    frame_id: &str,
) -> Option<TwistWithCovarianceStamped> {
    let v = fix.velocity_enu_mps?;
    let mut covariance = [0.0; 36];
    if let Some(c) = fix.velocity_covariance_enu_m2_s2 {
        for r in 0..3 {
            for k in 0..3 {
                covariance[6 * r + k] = c[(r, k)];
            }
        }
    }
    for k in 3..6 {
        covariance[6 * k + k] = -1.0;
    }
    Some(TwistWithCovarianceStamped {
        header: Header {
            stamp,
            frame_id: frame_id.to_owned(),
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: vector3(&v),
                angular: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                },
            },
            covariance,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ins::error_state::{StateMatrix, DP};
    use crate::ins::NavState;
    use nalgebra::UnitQuaternion;

    fn solution() -> (Solution, Llh) {
        let datum = Llh::from_degrees(40.0, -105.0, 1600.0);
        let p = earth::enu_to_llh(&nalgebra::Vector3::new(10.0, -3.0, 1.0), &datum).unwrap();
        let mut covariance = StateMatrix::identity() * 1e-4;
        let (north, _) = earth::metres_per_radian(&p);
        covariance[(DP, DP)] = 4.0 / (north * north);
        let sol = Solution {
            nav: NavState {
                t_s: 12.5,
                p,
                v_n: nalgebra::Vector3::new(0.0, 5.0, 0.0),
                // Facing north (ENU yaw 90°).
                q_nb: UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            },
            covariance,
            gyro_bias_rad_s: nalgebra::Vector3::zeros(),
            accel_bias_m_s2: nalgebra::Vector3::zeros(),
            clock_bias_m: 0.0,
            clock_drift_mps: 0.0,
            angular_rate_b_rad_s: nalgebra::Vector3::new(0.0, 0.0, 0.1),
        };
        (sol, datum)
    }

    #[test]
    fn odometry_pose_is_enu_at_the_datum_and_twist_is_in_the_body() {
        let (sol, datum) = solution();
        let stamp = Time {
            sec: 12,
            nanosec: 500_000_000,
        };
        let odom = odometry(&sol, &datum, stamp, "map", "base_link");
        let p = &odom.pose.pose.position;
        assert!((p.x - 10.0).abs() < 1e-6 && (p.y + 3.0).abs() < 1e-6 && (p.z - 1.0).abs() < 1e-6);
        let o = &odom.pose.pose.orientation;
        let half = std::f64::consts::FRAC_PI_4;
        assert!((o.z - half.sin()).abs() < 1e-12 && (o.w - half.cos()).abs() < 1e-12);
        // Moving north while facing north: forward (body x) at 5 m/s.
        let v = &odom.twist.twist.linear;
        assert!((v.x - 5.0).abs() < 1e-9 && v.y.abs() < 1e-9 && v.z.abs() < 1e-9);
        // Yaw rate less the earth and transport rates (a few 1e-5 rad/s).
        assert!((odom.twist.twist.angular.z - 0.1).abs() < 1e-4);
        // Pose covariance: the north variance (row 1, column 1) from δL.
        assert!((odom.pose.covariance[7] - 4.0).abs() < 1e-9);
        assert_eq!(odom.header.frame_id, "map");
        assert_eq!(odom.child_frame_id, "base_link");
    }

    #[test]
    fn nav_sat_fix_carries_degrees_and_the_enu_covariance() {
        let (sol, _) = solution();
        let fix = nav_sat_fix(&sol, Time::default(), "base_link", 9);
        assert!((fix.latitude - sol.nav.p.lat_rad.to_degrees()).abs() < 1e-12);
        assert_eq!(fix.status.status, NavSatStatus::STATUS_FIX);
        assert_eq!(fix.status.service, 9);
        assert!((fix.position_covariance[4] - 4.0).abs() < 1e-9);
        assert_eq!(
            fix.position_covariance_type,
            NavSatFix::COVARIANCE_TYPE_KNOWN
        );
    }

    #[test]
    fn service_bits_name_the_constellations_used() {
        use Constellation::*;
        assert_eq!(service_of([]), NavSatStatus::SERVICE_UNKNOWN);
        assert_eq!(service_of([Gps, Gps, Qzss]), NavSatStatus::SERVICE_GPS);
        assert_eq!(
            service_of([Galileo, Beidou, Glonass, Sbas]),
            NavSatStatus::SERVICE_GALILEO
                | NavSatStatus::SERVICE_COMPASS
                | NavSatStatus::SERVICE_GLONASS
        );
        let none = no_fix(Time::default(), "base_link");
        assert_eq!(none.status.status, NavSatStatus::STATUS_NO_FIX);
        assert!(none.latitude.is_nan() && none.altitude.is_nan());
        assert_eq!(
            none.position_covariance_type,
            NavSatFix::COVARIANCE_TYPE_UNKNOWN
        );
    }

    #[test]
    fn transform_is_the_odometry_pose_between_its_frames() {
        let (sol, datum) = solution();
        let stamp = Time {
            sec: 12,
            nanosec: 500_000_000,
        };
        let odom = odometry(&sol, &datum, stamp, "world", "imu_link");
        let tf = transform(&odom);
        assert_eq!(tf.transforms.len(), 1);
        let t = &tf.transforms[0];
        assert_eq!(t.header.stamp, stamp);
        assert_eq!(t.header.frame_id, "world");
        assert_eq!(t.child_frame_id, "imu_link");
        let p = &t.transform.translation;
        assert!((p.x - 10.0).abs() < 1e-6 && (p.y + 3.0).abs() < 1e-6 && (p.z - 1.0).abs() < 1e-6);
        let o = &odom.pose.pose.position;
        assert_eq!([p.x, p.y, p.z], [o.x, o.y, o.z]);
        // Rotation: body x (forward) points north in the map, as the solution faces north.
        let r = &t.transform.rotation;
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            r.w, r.x, r.y, r.z,
        ));
        let forward = q * nalgebra::Vector3::x();
        assert!(
            (forward - nalgebra::Vector3::y()).norm() < 1e-12,
            "{forward}"
        );
    }

    #[test]
    fn receiver_velocity_reads_back_as_the_fixs_velocity() {
        let mut fix = crate::engine::GnssFix {
            t_s: 3.5,
            position: Llh::from_degrees(40.0, -105.0, 1600.0),
            position_covariance_enu_m2: None,
            velocity_enu_mps: None,
            velocity_covariance_enu_m2_s2: None,
        };
        let stamp = Time {
            sec: 3,
            nanosec: 500_000_000,
        };
        assert!(receiver_velocity(&fix, stamp, "gnss").is_none());
        let c = Matrix3::new(0.01, 0.001, 0.0, 0.001, 0.02, 0.0, 0.0, 0.0, 0.04);
        fix.velocity_enu_mps = Some(nalgebra::Vector3::new(1.5, -0.5, 0.1));
        fix.velocity_covariance_enu_m2_s2 = Some(c);
        let msg = receiver_velocity(&fix, stamp, "gnss").unwrap();
        assert_eq!(msg.header.frame_id, "gnss");
        let v = crate::ros::convert::GnssVelocity::try_from(&msg).unwrap();
        assert_eq!(v.t_s, 3.5);
        assert_eq!(Some(v.velocity_enu_mps), fix.velocity_enu_mps);
        assert_eq!(v.covariance_enu_m2_s2, Some(c));
    }
}
