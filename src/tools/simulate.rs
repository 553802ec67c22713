//! `gnss_ins simulate`: a scenario written as a rosbag2 MCAP bag.
//!
//! Topics (stamps and log times are scenario time, starting at 0):
//! - `/imu` sensor_msgs/Imu (REP-145, frame `imu_link`);
//! - `/gnss/measurements` our GnssMeasurements (frame `gnss_antenna`);
//! - `/gnss/fix` sensor_msgs/NavSatFix, a receiver-like single-point fix (loose coupling);
//! - only with [`SimulateOptions::velocity`]: `/gnss/velocity`
//!   geometry_msgs/TwistWithCovarianceStamped, the receiver's velocity of each fix that has
//!   one (ENU, in the fix's frame as GNSS drivers send it), stamped like its fix and written
//!   just after it;
//! - only for a scenario with a `dual_antenna`: `/ubx_nav_rel_pos_ned`
//!   ublox_ubx_msgs/UBXNavRelPosNED, the moving-base pair's heading at each fix (frame
//!   `gnss_moving_base`), written just after its fix;
//! - `/ground_truth` nav_msgs/Odometry of the true IMU position in the ENU frame `map`
//!   whose origin is the trajectory's start, written in `/ground_truth/datum`
//!   (sensor_msgs/NavSatFix, once at t = 0);
//! - `/ground_truth/noise` our NoiseEstimates with the true σ² of every satellite's
//!   pseudo-range and rate in the `r_*` fields (filter_variant "truth");
//! - `/ground_truth/environment` diagnostic_msgs/DiagnosticArray, one status named
//!   "environment" whose message is the environment in force (open_sky, foliage, ...).

use std::path::Path;

use nalgebra::Vector3;

use crate::earth::Llh;
use crate::engine::Solution;
use crate::ins::error_state::StateMatrix;
use crate::ros::bag::{BagError, BagWriter};
use crate::ros::convert::seconds_to_time;
use crate::ros::msg::{
    DiagnosticArray, DiagnosticStatus, GnssMeasurements, Header, Imu, NavSatFix, NavSatStatus,
    NoiseEstimates, Odometry, SatelliteNoise, TwistWithCovarianceStamped, UbxNavRelPosNed,
};
use crate::ros::outbound;
use crate::ros::rel_pos_ned::message_of_reading;
use crate::sim::constellation::REFERENCE_EPOCH_GPS_TOW_S;
use crate::sim::scenario::{Scenario, SimEvent};
use crate::sim::ScenarioError;

/// Topic names of simulated bags (and the defaults of `replay`).
pub const IMU_TOPIC: &str = "/imu";
pub const GNSS_TOPIC: &str = "/gnss/measurements";
pub const FIX_TOPIC: &str = "/gnss/fix";
pub const VELOCITY_TOPIC: &str = "/gnss/velocity";
/// ublox_dgnss's `ubx_nav_rel_pos_ned` in the root namespace.
pub const REL_POS_NED_TOPIC: &str = "/ubx_nav_rel_pos_ned";
pub const TRUTH_TOPIC: &str = "/ground_truth";
pub const TRUTH_DATUM_TOPIC: &str = "/ground_truth/datum";
pub const TRUTH_NOISE_TOPIC: &str = "/ground_truth/noise";
pub const TRUTH_ENVIRONMENT_TOPIC: &str = "/ground_truth/environment";

/// Why a simulation could not be written.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Bag(#[from] BagError),
    #[error("time {t_s} s cannot be a ROS stamp")]
    Time { t_s: f64 },
}

/// Counts of what was written.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SimulateSummary {
    pub imu: usize,
    pub gnss: usize,
    pub fixes: usize,
    /// Messages on `/gnss/velocity` (0 unless asked for).
    pub velocities: usize,
    /// Messages on `/ubx_nav_rel_pos_ned` (0 unless the scenario has a dual antenna).
    pub rel_pos_ned: usize,
    pub truth: usize,
}

/// What a simulated bag carries beyond the default topics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SimulateOptions {
    /// Also write the receiver's velocities on `/gnss/velocity`. Choice: opt-in, so bags
    /// written before (the committed test fixture among them) are written unchanged.
    pub velocity: bool,
}

fn stamp(t_s: f64) -> Result<crate::ros::msg::Time, SimulateError> {
    seconds_to_time(t_s).map_err(|_| SimulateError::Time { t_s })
}

fn log_time_ns(t_s: f64) -> u64 {
    (t_s * 1e9).round().max(0.0) as u64
}

/// Writes `scenario` to the bag at `out` with the default topics.
pub fn simulate(scenario: &Scenario, out: &Path) -> Result<SimulateSummary, SimulateError> {
    simulate_with(scenario, out, SimulateOptions::default())
}

/// Writes `scenario` to the bag at `out` with the topics `options` ask for.
pub fn simulate_with(
    scenario: &Scenario,
    out: &Path,
    options: SimulateOptions,
) -> Result<SimulateSummary, SimulateError> {
    let mut bag = BagWriter::create(out)?;
    bag.add_topic::<Imu>(IMU_TOPIC)?;
    bag.add_topic::<GnssMeasurements>(GNSS_TOPIC)?;
    bag.add_topic::<NavSatFix>(FIX_TOPIC)?;
    if options.velocity {
        bag.add_topic::<TwistWithCovarianceStamped>(VELOCITY_TOPIC)?;
    }
    if scenario.spec().dual_antenna.is_some() {
        bag.add_topic::<UbxNavRelPosNed>(REL_POS_NED_TOPIC)?;
    }
    bag.add_topic::<Odometry>(TRUTH_TOPIC)?;
    bag.add_topic::<NavSatFix>(TRUTH_DATUM_TOPIC)?;
    bag.add_topic::<NoiseEstimates>(TRUTH_NOISE_TOPIC)?;
    bag.add_topic::<DiagnosticArray>(TRUTH_ENVIRONMENT_TOPIC)?;
    let mut summary = SimulateSummary::default();
    let mut datum: Option<Llh> = None;
    for event in scenario.events() {
        let event = event?;
        let t = event.t_s();
        let st = stamp(t)?;
        let ns = log_time_ns(t);
        match event {
            SimEvent::Imu(s) => {
                bag.write(IMU_TOPIC, &outbound::imu(&s, st, "imu_link"), ns)?;
                summary.imu += 1;
            }
            SimEvent::Truth(truth) => {
                let origin = *datum.get_or_insert(truth.nav.p);
                if summary.truth == 0 {
                    bag.write(TRUTH_DATUM_TOPIC, &datum_fix(&origin, st), ns)?;
                }
                let solution = Solution {
                    nav: truth.nav,
                    covariance: StateMatrix::zeros(),
                    gyro_bias_rad_s: Vector3::zeros(),
                    accel_bias_m_s2: Vector3::zeros(),
                    clock_bias_m: 0.0,
                    clock_drift_mps: 0.0,
                    angular_rate_b_rad_s: truth.imu.w_ib_b_rad_s,
                };
                let odom = outbound::odometry(&solution, &origin, st, "map", "base_link");
                bag.write(TRUTH_TOPIC, &odom, ns)?;
                summary.truth += 1;
            }
            SimEvent::Environment { name, .. } => {
                bag.write(TRUTH_ENVIRONMENT_TOPIC, &environment(name, st), ns)?;
            }
            SimEvent::Gnss {
                epoch,
                truth_sigmas,
                ..
            } => {
                let gps_s = REFERENCE_EPOCH_GPS_TOW_S + scenario.gps_time_s(t);
                // The constellation's reference epoch lies in GPS week 703 (1993-07-01).
                let week = 703 + (gps_s / 604_800.0).floor().max(0.0) as u16;
                let msg = outbound::gnss_measurements(&epoch, week, st, "gnss_antenna");
                bag.write(GNSS_TOPIC, &msg, ns)?;
                bag.write(TRUTH_NOISE_TOPIC, &truth_noise(&truth_sigmas, st), ns)?;
                summary.gnss += 1;
            }
            SimEvent::Fix(fix) => {
                bag.write(
                    FIX_TOPIC,
                    &outbound::receiver_fix(&fix, st, "gnss_antenna"),
                    ns,
                )?;
                summary.fixes += 1;
                let velocity = options
                    .velocity
                    .then(|| outbound::receiver_velocity(&fix, st, "gnss_antenna"))
                    .flatten();
                if let Some(v) = velocity {
                    bag.write(VELOCITY_TOPIC, &v, ns)?;
                    summary.velocities += 1;
                }
            }
            SimEvent::BaselineHeading(heading) => {
                let msg = message_of_reading(&heading, st, "gnss_moving_base");
                bag.write(REL_POS_NED_TOPIC, &msg, ns)?;
                summary.rel_pos_ned += 1;
            }
        }
    }
    bag.finish()?;
    Ok(summary)
}

fn datum_fix(p: &Llh, stamp: crate::ros::msg::Time) -> NavSatFix {
    NavSatFix {
        header: Header {
            stamp,
            frame_id: "map".to_owned(),
        },
        status: NavSatStatus {
            status: NavSatStatus::STATUS_FIX,
            service: NavSatStatus::SERVICE_GPS,
        },
        latitude: p.lat_rad.to_degrees(),
        longitude: p.lon_rad.to_degrees(),
        altitude: p.height_m,
        position_covariance: [0.0; 9],
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_KNOWN,
    }
}

fn environment(name: &str, stamp: crate::ros::msg::Time) -> DiagnosticArray {
    DiagnosticArray {
        header: Header {
            stamp,
            frame_id: String::new(),
        },
        status: vec![DiagnosticStatus {
            level: DiagnosticStatus::OK,
            name: "environment".to_owned(),
            message: name.to_owned(),
            hardware_id: String::new(),
            values: Vec::new(),
        }],
    }
}

fn truth_noise(
    sigmas: &[(crate::gnss::SatId, f64, f64)],
    stamp: crate::ros::msg::Time,
) -> NoiseEstimates {
    let nan = f64::NAN;
    NoiseEstimates {
        header: Header {
            stamp,
            frame_id: String::new(),
        },
        filter_variant: "truth".to_owned(),
        satellites: sigmas
            .iter()
            .map(|(sat, range_sigma_m, rate_sigma_mps)| SatelliteNoise {
                constellation: sat.constellation.code(),
                prn: sat.prn,
                elevation_deg: nan,
                used: false,
                rejection_reason: SatelliteNoise::REJECTION_NONE,
                innovation_pseudorange_m: nan,
                innovation_pseudorange_rate_mps: nan,
                normalized_innovation_pseudorange: nan,
                normalized_innovation_pseudorange_rate: nan,
                r_pseudorange_m2: range_sigma_m * range_sigma_m,
                r_pseudorange_rate_m2_s2: rate_sigma_mps * rate_sigma_mps,
                kde_credibility: nan,
                gaussian: true,
                ar_order: 0,
                robust_weight: nan,
            })
            .collect(),
        adaptive_factor: nan,
        mahalanobis_d2: nan,
        chi2_threshold: nan,
        q_scale: nan,
        nis: nan,
    }
}
