//! `gnss_ins simulate`: a scenario written as a rosbag2 MCAP bag.
//!
//! Time base: every stamp and log time is UTC (UNIX time, as ROS stamps are), scenario
//! time 0 at the scenario's real start ([`crate::sim::ScenarioClock`]: by default in
//! October 2025), and the GNSS epochs' `gps_week` and `gps_time_of_week_s` name the same
//! instant in GPS time (GPS − UTC = 18 s). [`Scenario::clock`] maps stamps back to
//! scenario time.
//!
//! Topics:
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
//!   (sensor_msgs/NavSatFix, once at the start);
//! - `/ground_truth/noise` our NoiseEstimates with the true σ² of every satellite's
//!   pseudo-range and rate in the `r_*` fields (filter_variant "truth");
//! - `/ground_truth/environment` diagnostic_msgs/DiagnosticArray, one status named
//!   "environment" whose message is the environment in force (open_sky, foliage, ...).

use std::path::Path;

use nalgebra::Vector3;

use crate::earth::Llh;
use crate::engine::Solution;
use crate::gnss::time_scale::DEFAULT_GPS_UTC_LEAP_S;
use crate::ins::error_state::StateMatrix;
use crate::ros::bag::{BagError, BagWriter};
use crate::ros::msg::{
    DiagnosticArray, DiagnosticStatus, GnssMeasurements, Header, Imu, NavSatFix, NavSatStatus,
    NoiseEstimates, Odometry, SatelliteNoise, TwistWithCovarianceStamped, UbxNavRelPosNed,
};
use crate::ros::outbound;
use crate::ros::rel_pos_ned::message_of_reading;
use crate::sim::constellation::GpsConstellation;
use crate::sim::scenario::{Scenario, SimEvent};
use crate::sim::{ScenarioClock, ScenarioError};

const NS_PER_S: i64 = 1_000_000_000;

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
    #[error("scenario time {t_s} s cannot be a ROS stamp or a bag's log time")]
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

/// The stamp and the log time (the same instant) of scenario time `t_s`.
fn stamp(clock: &ScenarioClock, t_s: f64) -> Result<(crate::ros::msg::Time, u64), SimulateError> {
    let error = || SimulateError::Time { t_s };
    let ns = clock.utc_ns(t_s);
    let stamp = crate::ros::msg::Time {
        sec: i32::try_from(ns.div_euclid(NS_PER_S)).map_err(|_| error())?,
        nanosec: u32::try_from(ns.rem_euclid(NS_PER_S)).map_err(|_| error())?,
    };
    let log_time_ns = u64::try_from(ns).map_err(|_| error())?;
    Ok((stamp, log_time_ns))
}

/// The time base of `scenario`'s bag in words: the UTC stamp of scenario time 0 and its
/// GPS week and time of week.
pub fn time_base(scenario: &Scenario) -> String {
    let clock = scenario.clock();
    let start_ns = clock.start_utc_ns();
    format!(
        "stamps and log times are UTC (ROS time): scenario time 0 is {}.{:09} s since 1970, \
         GPS week {} time of week {:.9} s (GPS - UTC = {} s)",
        start_ns.div_euclid(NS_PER_S),
        start_ns.rem_euclid(NS_PER_S),
        clock.gps_week(0.0),
        GpsConstellation::gps_time_of_week_s(scenario.gps_time_s(0.0)),
        DEFAULT_GPS_UTC_LEAP_S
    )
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
    simulate_with_progress(scenario, out, options, |_| {})
}

/// [`simulate_with`], calling `progress` with the fraction of the scenario's time written
/// at each reference sample.
pub fn simulate_with_progress(
    scenario: &Scenario,
    out: &Path,
    options: SimulateOptions,
    mut progress: impl FnMut(f64),
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
    let clock = scenario.clock();
    for event in scenario.events() {
        let event = event?;
        let t = event.t_s();
        let (st, ns) = stamp(&clock, t)?;
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
                progress(t / scenario.duration_s());
            }
            SimEvent::Environment { name, .. } => {
                bag.write(TRUTH_ENVIRONMENT_TOPIC, &environment(name, st), ns)?;
            }
            SimEvent::Gnss {
                epoch,
                truth_sigmas,
                ..
            } => {
                let week = clock.gps_week(t);
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
