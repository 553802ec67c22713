//! The scenario generator: a [`ScenarioSpec`] and a seed become a time-ordered stream of
//! simulated IMU samples, GNSS epochs, receiver-like fixes and truth, produced lazily (a
//! one-hour scenario at 1 kHz is never held in memory).
//!
//! Time: scenario time t starts at 0 with the trajectory; the GNSS epochs carry t as
//! `t_s` and the GPS time of week of `gnss.start_gps_s + t` in the constellation's
//! convention; where t lies in real time (stamps, GPS week) is the [`ScenarioClock`]'s.
//! The epochs are taken at true GPS time (the receiver clock bias appears in the
//! pseudo-ranges, not in the time tags).
//!
//! Order of events at equal times: Imu, Truth, Environment, Gnss, Fix, BaselineHeading —
//! so a consumer has the IMU up to an epoch before the epoch itself.

use std::collections::VecDeque;

use nalgebra::{Matrix3, Vector3};
use rand_chacha::rand_core::Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::earth::{earth_rate_enu_rad_s, ecef_to_llh, llh_to_ecef, rot_ecef_to_enu};
use crate::engine::{BaselineHeadingReading, CarrierSolution, GnssFix};
use crate::gnss::geometry::{elevation_azimuth, line_of_sight};
use crate::gnss::spp::{solve_spp, SigmaModel, SppConfig, SppSolution};
use crate::gnss::{GnssEpoch, SatId};
use crate::ins::ImuSample;
use crate::sim::carrier::CarrierTracks;
use crate::sim::constellation::{
    AtmosphereTruth, GpsConstellation, ObservationNoise, ReceiverTruth,
};
use crate::sim::environment::Environment;
use crate::sim::receiver_clock::{ReceiverClock, ReceiverClockState};
use crate::sim::sat_errors::{
    stream_rng, FoliageModels, SatContext, SatErrorGenerator, SatErrorTruth, StreamPurpose,
};
use crate::sim::scenario_clock::ScenarioClock;
use crate::sim::scenario_error::ScenarioError;
use crate::sim::scenario_spec::ScenarioSpec;
use crate::sim::{ImuErrorModel, Trajectory, TruthSample};

/// Floors of the σ model of the receiver-like fix (m, m/s). Choice: the fix weights the
/// satellites with the scenario's open-sky zenith σ (a receiver's nominal model), floored
/// so that a noise-free scenario still has finite weights.
const FIX_MIN_SIGMA_M: f64 = 0.01;
const FIX_MIN_SIGMA_MPS: f64 = 0.001;
/// Largest PDOP of a fix. Choice: receivers suppress fixes of poor geometry with a PDOP
/// mask (commonly 10–25); 10 keeps every fix's position σ within ten range σ. Without it a
/// four-satellite urban epoch with two satellites nearly in line gives "fixes" tens of
/// kilometres off.
const MAX_FIX_PDOP: f64 = 10.0;
/// Slack (in periods) when counting the samples of a stream, so that 400 s at 100 Hz gives
/// 40 001 samples despite rounding.
const COUNT_SLACK_PERIODS: f64 = 1e-6;

/// The truth behind one GNSS epoch, for scoring and tests.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssTruth {
    /// True receiver clock.
    pub clock: ReceiverClockState,
    /// True antenna position (ECEF, m).
    pub antenna_pos_ecef_m: Vector3<f64>,
    /// True antenna velocity (ECEF, m/s).
    pub antenna_vel_ecef_mps: Vector3<f64>,
    /// What was added to each satellite of the epoch, in the epoch's order.
    pub satellites: Vec<SatErrorTruth>,
}

/// One simulated event.
#[derive(Debug, Clone, PartialEq)]
pub enum SimEvent {
    /// A corrupted IMU sample (REP-145, body FLU).
    Imu(ImuSample),
    /// The true state (IMU position) and the error-free IMU output.
    Truth(TruthSample),
    /// The environment in force at a GNSS epoch time (emitted at every epoch, outages
    /// included, just before the epoch).
    Environment {
        /// Scenario time (s).
        t_s: f64,
        /// Environment name ("open_sky", "foliage", "urban_canyon", "outage").
        name: &'static str,
        /// Index of its segment in the spec (None: open sky outside every segment).
        segment: Option<usize>,
    },
    /// A GNSS epoch (absent during outages).
    Gnss {
        /// The raw observations as a receiver would report them.
        epoch: GnssEpoch,
        /// Per satellite: (id, σ of the pseudo-range error in m, σ of the rate error in
        /// m/s) — the root-mean-square of everything the environment adds (see
        /// [`SatErrorTruth`]), excluding the receiver clock and the atmosphere-model
        /// mismatch.
        truth_sigmas: Vec<(SatId, f64, f64)>,
        /// The truth behind the epoch.
        truth: GnssTruth,
    },
    /// A receiver-like fix of the antenna: the single-point solution of the same epoch
    /// (none when it fails or its PDOP exceeds 10).
    Fix(GnssFix),
    /// The heading of the dual-antenna pair's baseline (with `dual_antenna` in the spec),
    /// a fixed carrier solution, at the epochs with a fix.
    BaselineHeading(BaselineHeadingReading),
}

impl SimEvent {
    /// Time of the event (s, scenario time).
    pub fn t_s(&self) -> f64 {
        match self {
            SimEvent::Imu(s) => s.t_s,
            SimEvent::Truth(s) => s.nav.t_s,
            SimEvent::Environment { t_s, .. } => *t_s,
            SimEvent::Gnss { epoch, .. } => epoch.t_s,
            SimEvent::Fix(f) => f.t_s,
            SimEvent::BaselineHeading(h) => h.t_s,
        }
    }
}

/// A validated scenario, ready to generate its events.
#[derive(Debug, Clone)]
pub struct Scenario {
    spec: ScenarioSpec,
    seed: u64,
    trajectory: Trajectory,
    constellation: GpsConstellation,
    atmosphere: AtmosphereTruth,
    lever_arm_b_m: Vector3<f64>,
    foliage: Vec<Option<FoliageModels>>,
    spp: SppConfig,
    /// The IMU error model at the start, seeded from the IMU stream.
    imu_model: ImuErrorModel,
}

impl Scenario {
    /// Validates `spec` and prepares the scenario; all randomness derives from `seed`.
    pub fn new(spec: ScenarioSpec, seed: u64) -> Result<Self, ScenarioError> {
        spec.validate()?;
        let trajectory = Trajectory::new(&spec.trajectory)?;
        let imu_seed = stream_rng(seed, StreamPurpose::Imu, None, 0).next_u64();
        let imu_model = ImuErrorModel::new(&spec.imu.errors, spec.imu.rate_hz, imu_seed)?;
        let foliage = spec
            .environments
            .iter()
            .map(|seg| match &seg.environment {
                Environment::Foliage(f) => FoliageModels::new(f),
                _ => None,
            })
            .collect();
        let g = &spec.gnss;
        let atmosphere = AtmosphereTruth {
            klobuchar: Some(g.atmosphere.klobuchar()),
            iono_scale: g.atmosphere.iono_truth_scale,
            tropo_scale: g.atmosphere.tropo_truth_scale,
            report_delays: g.atmosphere.report_delays,
        };
        let spp = SppConfig {
            elevation_mask_rad: g.elevation_mask_deg.to_radians(),
            sigma: SigmaModel {
                pseudorange_zenith_m: g
                    .thermal_noise
                    .pseudorange_sigma_zenith_m
                    .max(FIX_MIN_SIGMA_M),
                pseudorange_rate_zenith_mps: g
                    .thermal_noise
                    .pseudorange_rate_sigma_zenith_mps
                    .max(FIX_MIN_SIGMA_MPS),
                ..SigmaModel::default()
            },
            ..SppConfig::default()
        };
        Ok(Self {
            constellation: GpsConstellation::augmented(g.extra_satellites_per_plane),
            lever_arm_b_m: Vector3::from(g.antenna_lever_arm_m),
            atmosphere,
            trajectory,
            foliage,
            spp,
            imu_model,
            seed,
            spec,
        })
    }

    /// A built-in scenario (see [`ScenarioSpec::builtin_names`]) with `seed`.
    pub fn builtin(name: &str, seed: u64) -> Result<Self, ScenarioError> {
        Self::new(ScenarioSpec::builtin(name)?, seed)
    }

    /// The spec.
    pub fn spec(&self) -> &ScenarioSpec {
        &self.spec
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The truth trajectory.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// The simulated constellation.
    pub fn constellation(&self) -> &GpsConstellation {
        &self.constellation
    }

    /// The atmosphere truth handed to the observation simulator.
    pub fn atmosphere(&self) -> &AtmosphereTruth {
        &self.atmosphere
    }

    /// Antenna lever arm, body FLU (m).
    pub fn lever_arm_b_m(&self) -> Vector3<f64> {
        self.lever_arm_b_m
    }

    /// Length of the scenario (s).
    pub fn duration_s(&self) -> f64 {
        self.trajectory.end_t_s()
    }

    /// GPS time (s since the constellation's reference epoch) of scenario time `t_s`.
    pub fn gps_time_s(&self, t_s: f64) -> f64 {
        self.spec.gnss.start_gps_s + t_s
    }

    /// Where the scenario lies in real time: stamps and GPS weeks of scenario times.
    pub fn clock(&self) -> ScenarioClock {
        ScenarioClock::new(&self.spec.gnss)
    }

    /// The environment at scenario time `t_s` and its segment index.
    pub fn environment_at(&self, t_s: f64) -> (Option<usize>, &Environment) {
        self.spec.environment_at(t_s)
    }

    /// The events, in time order (a fresh, identical stream on every call). Should the
    /// simulation fail at some epoch (which validation is meant to exclude), the stream
    /// yields that error once and ends.
    pub fn events(&self) -> ScenarioEvents<'_> {
        let count =
            |rate_hz: f64| (self.duration_s() * rate_hz + COUNT_SLACK_PERIODS).floor() as u64 + 1;
        ScenarioEvents {
            scenario: self,
            imu_model: self.imu_model.clone(),
            clock: ReceiverClock::new(&self.spec.gnss.receiver_clock),
            clock_rng: stream_rng(self.seed, StreamPurpose::ReceiverClock, None, 0),
            clock_t_s: 0.0,
            sat_errors: SatErrorGenerator::new(
                self.seed,
                self.spec.gnss.thermal_noise.clone(),
                self.foliage.clone(),
            ),
            carrier: CarrierTracks::new(self.seed),
            imu: Stream::new(self.spec.imu.rate_hz, count(self.spec.imu.rate_hz)),
            truth: Stream::new(self.spec.truth_rate_hz, count(self.spec.truth_rate_hz)),
            gnss: Stream::new(self.spec.gnss.rate_hz, count(self.spec.gnss.rate_hz)),
            pending: VecDeque::new(),
            failed: false,
        }
    }

    /// Truth at `t_s`, with the range errors of the trajectory mapped.
    fn truth_at(&self, t_s: f64) -> Result<TruthSample, ScenarioError> {
        Ok(self
            .trajectory
            .truth_at(t_s.min(self.trajectory.end_t_s()))?)
    }

    /// The GNSS events of epoch `index` at `t_s` (after the environment event).
    fn gnss_events(
        &self,
        index: u64,
        t_s: f64,
        clock: ReceiverClockState,
        (sat_errors, carrier): (&mut SatErrorGenerator, &mut CarrierTracks),
        out: &mut VecDeque<SimEvent>,
    ) -> Result<(), ScenarioError> {
        let (segment, environment) = self.environment_at(t_s);
        out.push_back(SimEvent::Environment {
            t_s,
            name: environment.name(),
            segment,
        });
        if matches!(environment, Environment::Outage) {
            return Ok(());
        }
        let truth = self.truth_at(t_s)?;
        let nav = &truth.nav;
        let c_en = rot_ecef_to_enu(&nav.p);
        let c_bn = nav.q_nb.to_rotation_matrix().into_inner();
        // r_ant = r_imu + C_b^e l;  v_ant = v_imu + C_b^e (ω_eb^b × l), ω_eb^b = ω_ib^b − C_n^b ω_ie^n.
        let w_eb_b =
            truth.imu.w_ib_b_rad_s - c_bn.transpose() * earth_rate_enu_rad_s(nav.p.lat_rad);
        let antenna_pos = llh_to_ecef(&nav.p) + c_en.transpose() * (c_bn * self.lever_arm_b_m);
        let antenna_vel = c_en.transpose() * (nav.v_n + c_bn * w_eb_b.cross(&self.lever_arm_b_m));
        let antenna_llh =
            ecef_to_llh(&antenna_pos).ok_or(ScenarioError::AntennaPosition { t_s })?;
        let rx = ReceiverTruth {
            pos_ecef_m: antenna_pos,
            vel_ecef_mps: antenna_vel,
            clock_bias_m: clock.bias_m,
            clock_drift_mps: clock.drift_mps,
        };
        let mut epoch = self
            .constellation
            .simulate_epoch(
                self.gps_time_s(t_s),
                &rx,
                &self.atmosphere,
                self.spec.gnss.elevation_mask_deg.to_radians(),
                |_| ObservationNoise::default(),
            )
            .map_err(|source| ScenarioError::Simulation { t_s, source })?;
        epoch.t_s = t_s;
        // Course over ground from the body x axis (clockwise from north).
        let forward_n = c_bn * Vector3::x();
        let course_rad = forward_n[0].atan2(forward_n[1]);
        let mut satellites = Vec::with_capacity(epoch.satellites.len());
        let mut sat_truths = Vec::with_capacity(epoch.satellites.len());
        for mut obs in std::mem::take(&mut epoch.satellites) {
            let geometry = line_of_sight(
                obs.sat,
                &obs.sat_pos_ecef_m,
                &obs.sat_vel_ecef_mps,
                &antenna_pos,
                &antenna_vel,
            )
            .map_err(|source| ScenarioError::Geometry { t_s, source })?;
            let (elevation_rad, azimuth_rad) = elevation_azimuth(&antenna_llh, &geometry.los_ecef);
            let ctx = SatContext {
                sat: obs.sat,
                epoch_index: index,
                elevation_rad,
                azimuth_rad,
                course_rad,
                environment,
                segment,
            };
            if let Some(err) = sat_errors.draw(&ctx) {
                obs.pseudorange_m = obs.pseudorange_m.map(|p| p + err.pseudorange_error_m);
                obs.pseudorange_rate_mps = obs
                    .pseudorange_rate_mps
                    .map(|r| r + err.pseudorange_rate_error_mps);
                obs.cn0_dbhz = Some(err.cn0_dbhz);
                obs.carrier_phase = obs.carrier_phase.map(|phase| {
                    carrier.receive(obs.sat, index, t_s, phase, err.carrier_phase_error_m)
                });
                satellites.push(obs);
                sat_truths.push(err);
            }
        }
        epoch.satellites = satellites;
        let fix = solve_spp(&epoch, &self.spp)
            .ok()
            .filter(|sol| sol.dop.pdop <= MAX_FIX_PDOP)
            .map(|sol| fix_from_solution(t_s, &sol));
        out.push_back(SimEvent::Gnss {
            truth_sigmas: sat_truths
                .iter()
                .map(|s| (s.sat, s.pseudorange_sigma_m, s.pseudorange_rate_sigma_mps))
                .collect(),
            epoch,
            truth: GnssTruth {
                clock,
                antenna_pos_ecef_m: antenna_pos,
                antenna_vel_ecef_mps: antenna_vel,
                satellites: sat_truths,
            },
        });
        if let Some(fix) = fix {
            out.push_back(SimEvent::Fix(fix));
            if let Some(heading) = self.baseline_heading(index, t_s, &c_bn) {
                out.push_back(SimEvent::BaselineHeading(heading));
            }
        }
        Ok(())
    }

    /// The dual-antenna pair's heading at epoch `index` of a body whose attitude is
    /// `c_bn`: the true baseline's heading plus an error of the spec's σ (its own stream).
    fn baseline_heading(
        &self,
        index: u64,
        t_s: f64,
        c_bn: &Matrix3<f64>,
    ) -> Option<BaselineHeadingReading> {
        let d = self.spec.dual_antenna.as_ref()?;
        let baseline_b = Vector3::from(d.baseline_m);
        let u = c_bn * baseline_b;
        let sigma_rad = d.heading_sigma_deg.to_radians();
        let mut rng = stream_rng(self.seed, StreamPurpose::BaselineHeading, None, index);
        let error: f64 = StandardNormal.sample(&mut rng);
        Some(BaselineHeadingReading {
            t_s,
            heading_rad: (u[0].atan2(u[1]) + sigma_rad * error)
                .rem_euclid(2.0 * std::f64::consts::PI),
            sigma_rad,
            length_m: baseline_b.norm(),
            carrier: CarrierSolution::Fixed,
        })
    }
}

/// The receiver-like fix of a single-point solution: its covariances rotated to ENU at the
/// solution, velocity when it was solvable.
fn fix_from_solution(t_s: f64, sol: &SppSolution) -> GnssFix {
    let c_en = rot_ecef_to_enu(&sol.pos_llh);
    let rotate = |p: Matrix3<f64>| c_en * p * c_en.transpose();
    let pos_cov: Matrix3<f64> = sol.covariance.fixed_view::<3, 3>(0, 0).into_owned();
    let velocity = sol.velocity.as_ref().ok();
    GnssFix {
        t_s,
        position: sol.pos_llh,
        position_covariance_enu_m2: Some(rotate(pos_cov)),
        velocity_enu_mps: velocity.map(|v| v.vel_enu_mps),
        velocity_covariance_enu_m2_s2: velocity
            .map(|v| rotate(v.covariance.fixed_view::<3, 3>(0, 0).into_owned())),
    }
}

/// A fixed-rate stream of sample times t_k = k / rate, k < count.
#[derive(Debug, Clone, Copy)]
struct Stream {
    rate_hz: f64,
    next: u64,
    count: u64,
}

impl Stream {
    fn new(rate_hz: f64, count: u64) -> Self {
        Self {
            rate_hz,
            next: 0,
            count,
        }
    }

    /// Time of the next sample, if any.
    fn peek_t_s(&self) -> Option<f64> {
        (self.next < self.count).then(|| self.next as f64 / self.rate_hz)
    }
}

/// Which stream produces the next event (in the tie-break order at equal times).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Source {
    Imu,
    Truth,
    Gnss,
}

/// The lazy event stream of a scenario; see [`Scenario::events`]. Yields `Err` once and
/// then ends if the simulation fails.
#[derive(Debug, Clone)]
pub struct ScenarioEvents<'a> {
    scenario: &'a Scenario,
    imu_model: ImuErrorModel,
    clock: ReceiverClock,
    clock_rng: rand_chacha::ChaCha8Rng,
    clock_t_s: f64,
    sat_errors: SatErrorGenerator,
    carrier: CarrierTracks,
    imu: Stream,
    truth: Stream,
    gnss: Stream,
    pending: VecDeque<SimEvent>,
    failed: bool,
}

impl ScenarioEvents<'_> {
    fn produce(&mut self, source: Source, t_s: f64) -> Result<(), ScenarioError> {
        match source {
            Source::Imu => {
                self.imu.next += 1;
                let truth = self.scenario.truth_at(t_s)?;
                let sample = self.imu_model.corrupt(&truth.imu);
                self.pending.push_back(SimEvent::Imu(sample));
            }
            Source::Truth => {
                self.truth.next += 1;
                let truth = self.scenario.truth_at(t_s)?;
                self.pending.push_back(SimEvent::Truth(truth));
            }
            Source::Gnss => {
                let index = self.gnss.next;
                self.gnss.next += 1;
                self.clock
                    .advance(t_s - self.clock_t_s, &mut self.clock_rng);
                self.clock_t_s = t_s;
                self.scenario.gnss_events(
                    index,
                    t_s,
                    self.clock.state(),
                    (&mut self.sat_errors, &mut self.carrier),
                    &mut self.pending,
                )?;
            }
        }
        Ok(())
    }
}

impl Iterator for ScenarioEvents<'_> {
    type Item = Result<SimEvent, ScenarioError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(event) = self.pending.pop_front() {
                return Some(Ok(event));
            }
            if self.failed {
                return None;
            }
            let candidates = [
                (self.imu.peek_t_s(), Source::Imu),
                (self.truth.peek_t_s(), Source::Truth),
                (self.gnss.peek_t_s(), Source::Gnss),
            ];
            let (t_s, source) = candidates
                .into_iter()
                .filter_map(|(t, s)| t.map(|t| (t, s)))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))?;
            if let Err(e) = self.produce(source, t_s) {
                self.failed = true;
                self.pending.clear();
                return Some(Err(e));
            }
        }
    }
}
