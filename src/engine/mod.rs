//! The engine: owns time, buffers the IMU, aligns GNSS measurements to their epoch,
//! initializes, propagates and updates the filter, and reports. It never reads a clock:
//! time comes in with the data, so replay is exact and deterministic. The live node,
//! offline replay and the tests all drive this one type.
//!
//! Time handling:
//! - IMU samples must arrive with strictly increasing stamps; a duplicate or an older one
//!   is rejected and counted. A gap longer than `engine.max_imu_gap_s` resets the filter
//!   (nothing can be integrated across it) and it starts again from the next position.
//! - A GNSS measurement at or after the last IMU sample waits until an IMU sample after
//!   it arrives; the state is then propagated to its exact time with an interpolated IMU
//!   sample, updated, and propagated on. Choice: a measurement stamped exactly at an IMU
//!   sample is applied after that sample (the solution of that sample is the propagated
//!   one), whichever of the two arrives first: over DDS the IMU and GNSS streams have no
//!   common order, and the result must not depend on it (the live node then equals the
//!   offline replay of the same data).
//! - A measurement older than the last IMU sample (late delivery) rolls the engine back to
//!   the last kept phase before it (the running filter, or the initializer during the
//!   start-up), applies it, and re-integrates the buffered IMU samples, so that the result
//!   is the one of an in-time delivery: only the solutions already published before it
//!   arrived lacked it. Solutions of a start found in the re-integration are published
//!   then. Each is counted (`late_measurements` on /diagnostics); one older than
//!   `engine.imu_buffer_s` is rejected and counted, and so is one more than
//!   `engine.imu_buffer_s` ahead of the IMU. No roll-back reaches into the heading bank (a
//!   bank is up to 36 filters, kept in no step): a late measurement older than the bank's
//!   end updates the bank, or the filter it started, as it is. A reset during a
//!   re-integration takes the samples after it as new ones.
//! - Every buffer is bounded by count as well as by time ([`MAX_BUFFERED_IMU_SAMPLES`],
//!   [`MAX_PENDING_MEASUREMENTS`]), so no input rate or stamp grows memory without bound.
//! - Wheel speeds (`wheel_odometry.*`, [`wheel_odometry`]) take the measurements' path
//!   (waiting, roll-back, duplicates by kind) while the filter runs; before, start-up has
//!   no use for them and they are rejected and counted.
//! - Dual-antenna headings (`dual_antenna.*`, [`dual_antenna`]) take the same path; before
//!   the start the initializer keeps the newest as the start's heading (a start at rest),
//!   while running each is a measurement, gated against the filter's heading.
//! - Start-up (`initializer`): levelled at rest, or aligned in motion from GNSS when
//!   the IMU's window is not at rest (a start or a restart mid-drive); a start whose
//!   heading is too uncertain for one filter runs a bank of heading hypotheses first
//!   ([`heading_bank`]), and nothing is published until it has decided. A running filter
//!   whose heading σ leaves the linear range while moving splits into such a bank, which
//!   publishes its moment-matched state (`heading_hypotheses`); the bank's steps are
//!   kept for no roll-back, and neither the motion constraints nor the divergence monitor
//!   run in it (each hypothesis is a plain EKF scored on the GNSS alone).
//! - IMU samples are screened first ([`imu_screen`]): one beyond the sensor's range or a
//!   lone spike is dropped and counted, and the strapdown step spans it.
//! - Each GNSS input seen for the first time feeds the divergence monitor ([`divergence`],
//!   [`recovery`]) with the prior's disagreement with an independent GNSS position; a
//!   sustained one is counted and resets the filter; unlike after an IMU gap nothing is
//!   kept: the start-up aligns again, with a wide gyro bias prior. While the GNSS and the
//!   filter disagree after a GNSS leap that the IMU does not support (a dispute), the
//!   solutions are published with their position covariance widened by the offset.
//!   While the noise judges find the measurements' claims too small (the fixes'
//!   `fix_consistency`, the ranges' `error_correlation`), it is at least what they found
//!   beyond the claims (the filter follows such errors, correlated over seconds, with
//!   typical innovations; [`range_excess`]).

mod adaptation;
pub mod adaptive_noise;
mod cn0_deficit;
mod constraints;
mod dispute;
pub mod divergence;
mod dual_antenna;
mod error_correlation;
mod filter_state;
pub(crate) mod fix_consistency;
mod fix_track;
pub mod gyrocompass;
pub mod heading_bank;
pub mod imu_screen;
mod initializer;
mod output;
mod phase_anchor;
pub mod q_scaling;
mod range_excess;
mod recovery;
mod rejection;
mod retune;
pub mod standstill;
mod start_up;
pub mod update;
mod wheel_odometry;

use std::collections::VecDeque;

use nalgebra::{Matrix3, Vector3};

use crate::config::{Config, Coupling};
use crate::filter::process_model::{ClockNoise, ImuScaleNoise, ProcessNoise};
use crate::gnss::GnssEpoch;
use crate::ins::ImuSample;

use constraints::Constraints;
pub use dispute::Hold;
use divergence::DivergenceMonitor;
use heading_bank::HeadingBank;
use imu_screen::{ImuScreen, Screened};
use standstill::StandstillDetector;
use wheel_odometry::WheelSpeedReading;

pub use adaptation::Adaptation;
pub use constraints::ConstraintUpdates;
pub use dual_antenna::{BaselineHeadingReading, CarrierSolution};
pub use filter_state::{interpolate, FilterState};
pub use initializer::{InitPhase, Initializer};
pub use output::{
    Deweighted, EpochReport, MeasurementKind, Output, PhaseRejection, ResetReason, SatRejection,
    SatReport, Solution, StatusEvent,
};
pub use rejection::{InputRejected, RejectionCounters, RejectionReason};
pub use retune::{NotRuntimeTunable, RUNTIME_PARAMETERS};
pub use update::GnssFix;

/// Most IMU samples buffered, and steps kept after them, whatever `engine.imu_buffer_s`
/// says.
///
/// Choice: 10,000: 10 s of a 1 kHz IMU, the default 2 s of a 5 kHz one. Samples stamped
/// microseconds apart (a flood, a broken clock) would otherwise fill the time window with
/// millions of states; with the bound the buffers hold at most some 6 MB (a stored state
/// is about 6 KB, most of it the covariance, one every [`STATE_EVERY_STEPS`]; during the
/// start-up a kept initializer holds up to 5 s of fixes, some 12 KB at 10 Hz, so 12 MB).
/// Where it binds, a late measurement reaches back less far than `engine.imu_buffer_s`
/// (rejected as too old, counted).
pub const MAX_BUFFERED_IMU_SAMPLES: usize = 10_000;

/// The phase (the filter state, or the initializer) is kept for roll-backs after every
/// this many IMU steps.
///
/// Choice: 10. A roll-back restarts from the last kept state at or before the late
/// measurement and re-integrates the samples after it, which it does anyway for the
/// samples after the measurement: keeping one state in ten costs a roll-back at most nine
/// more samples (a few tens of microseconds), and saves copying a state (about 6 KB) on
/// every sample, a tenth of the engine's time at 200 Hz. The re-integrated states are the
/// ones first computed (the same steps on the same samples), except where an adaptive
/// scheme has learned since, as for the samples after the measurement. The reach back
/// shortens by up to nine samples: a measurement older than the oldest kept state is
/// refused as too old.
pub const STATE_EVERY_STEPS: usize = 10;

/// Most measurements waiting for the IMU to pass their time.
///
/// Choice: 100, 10 s of a 10 Hz receiver: a measurement waits only until the IMU passes
/// its stamp, which is at most `engine.imu_buffer_s` ahead (a later one is rejected), so
/// only a stream without IMU fills the queue; the oldest then leaves, counted.
pub const MAX_PENDING_MEASUREMENTS: usize = 100;

/// The sizes of the engine's buffers (see [`Engine::buffered`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Buffered {
    /// IMU samples kept for roll-backs.
    pub imu_samples: usize,
    /// Steps kept after them (the measurements applied in each).
    pub steps: usize,
    /// Phases kept with the steps (one every [`STATE_EVERY_STEPS`]).
    pub states: usize,
    /// Measurements waiting for the IMU.
    pub measurements: usize,
    /// IMU samples in the standstill detector's window.
    pub standstill_samples: usize,
}

/// A measurement waiting for its time.
#[derive(Debug, Clone, PartialEq)]
enum Measurement {
    Gnss(GnssEpoch),
    Fix(GnssFix),
    WheelSpeed(WheelSpeedReading),
    BaselineHeading(BaselineHeadingReading),
}

impl Measurement {
    fn t_s(&self) -> f64 {
        match self {
            Self::Gnss(e) => e.t_s,
            Self::Fix(f) => f.t_s,
            Self::WheelSpeed(w) => w.t_s,
            Self::BaselineHeading(h) => h.t_s,
        }
    }

    /// Whether `other` is of the same kind and time (a duplicate).
    fn duplicates(&self, other: &Measurement) -> bool {
        self.t_s() == other.t_s() && std::mem::discriminant(self) == std::mem::discriminant(other)
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Pending {
    measurement: Measurement,
    /// Already reported once (re-applied after a roll-back): report it silently.
    reported: bool,
}

/// One IMU step: the measurements applied in it and, every [`STATE_EVERY_STEPS`], the
/// phase after it.
#[derive(Debug, Clone)]
struct Step {
    /// Time of the IMU sample the step ended at (s).
    t_s: f64,
    kept: Kept,
    /// The measurements applied, each with whether it was reported (applied to the
    /// running filter, which reported it).
    applied: Vec<Pending>,
}

/// What a step keeps for roll-backs.
#[derive(Debug, Clone)]
enum Kept {
    Nothing,
    /// The phase after the step: the initializer, or the running filter.
    Phase(Phase),
    /// A step of the heading bank: no roll-back reaches behind it.
    Bank,
}

/// Where a late measurement goes.
enum LateTarget {
    /// Roll back to the phase kept in this step.
    Step(usize),
    /// A heading bank ran since its stamp: to what runs now, as it is.
    AsItIs,
    /// Older than every kept phase.
    TooOld,
}

#[derive(Debug, Clone)]
enum Phase {
    Initializing(Box<Initializer>),
    /// Resolving a coarse heading with a bank of hypotheses.
    Aligning(Box<HeadingBank>),
    Running(Box<FilterState>),
}

/// The navigation engine. See the module documentation.
#[derive(Debug, Clone)]
pub struct Engine {
    config: Config,
    process_noise: ProcessNoise,
    phase: Phase,
    /// Raw body-frame IMU samples of the last `imu_buffer_s`.
    imu: VecDeque<ImuSample>,
    /// The steps to each of the buffered IMU samples (while running).
    history: VecDeque<Step>,
    pending: Vec<Pending>,
    last_output_t_s: f64,
    counters: RejectionCounters,
    /// Re-integrating after a roll-back: the constraint updates are not counted again.
    replaying: bool,
    /// Noise strategy, update scheme and Q scaling of the variant.
    ///
    /// Choice: the learned Q scale lives here, not in the stored states, so states
    /// re-integrated after a roll-back use the scale of now; the estimators learn only from
    /// measurements seen for the first time.
    adaptation: Adaptation,
    /// The IMU samples' screen (range and spikes).
    screen: ImuScreen,
    /// The recent body-frame samples, for the start-up's tests of rest and motion.
    standstill: StandstillDetector,
    /// The constraints of the vehicle's motion (`constraints.*`).
    constraints: Constraints,
    /// The filter against independent GNSS positions.
    monitor: DivergenceMonitor,
    /// Resets after a divergence so far.
    divergence_resets: u64,
    /// Measurements applied after the IMU had passed their stamp, so far.
    late_measurements: u64,
    deweighted: Deweighted,
    /// The start since the last reset was reported.
    start_reported: bool,
    /// Time of the last divergence while the filter has not started again since.
    diverged_at_t_s: Option<f64>,
}

impl Engine {
    pub fn new(config: Config) -> Self {
        let process_noise = process_noise(&config);
        Self {
            adaptation: Adaptation::new(&config),
            standstill: StandstillDetector::new(config.engine.imu_buffer_s),
            config,
            process_noise,
            phase: Phase::Initializing(Box::default()),
            imu: VecDeque::new(),
            history: VecDeque::new(),
            pending: Vec::new(),
            last_output_t_s: f64::NEG_INFINITY,
            counters: RejectionCounters::default(),
            replaying: false,
            screen: ImuScreen::default(),
            constraints: Constraints::default(),
            monitor: DivergenceMonitor::default(),
            divergence_resets: 0,
            late_measurements: 0,
            start_reported: false,
            deweighted: Deweighted::default(),
            diverged_at_t_s: None,
        }
    }

    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Inputs rejected so far, by reason.
    pub fn counters(&self) -> &RejectionCounters {
        &self.counters
    }

    /// The constraint updates applied so far (ZUPT, ZARU, NHC).
    pub fn constraint_updates(&self) -> ConstraintUpdates {
        self.constraints.updates()
    }

    /// The measurements deweighted so far: fix outliers, fix claims scaled, pseudo-ranges
    /// and rates inflated for correlated errors.
    pub fn deweighted(&self) -> Deweighted {
        self.deweighted
    }

    /// Resets after a divergence from GNSS so far.
    pub fn divergence_resets(&self) -> u64 {
        self.divergence_resets
    }

    /// Measurements that arrived after the IMU had passed their stamp and were applied by
    /// a roll-back (or, while the heading bank runs, to the bank as it was), so far: the
    /// solutions published in between lacked them.
    pub fn late_measurements(&self) -> u64 {
        self.late_measurements
    }

    /// Time of the divergence the engine is recovering from: set by a divergence reset,
    /// None again once the filter runs.
    pub fn diverged_at_t_s(&self) -> Option<f64> {
        self.diverged_at_t_s
    }

    /// The running filter state (of a split heading, the one it publishes), or None while
    /// initializing.
    pub fn state(&self) -> Option<&FilterState> {
        match &self.phase {
            Phase::Running(s) => Some(s),
            Phase::Aligning(bank) => bank.published(),
            Phase::Initializing(_) => None,
        }
    }

    /// The solution of the published state as published: with its position covariance
    /// widened while the divergence monitor holds a dispute (see
    /// [`Engine::gnss_dispute_offset_enu_m`]) and while the noise judges find the claims
    /// too small (see `recovery::published_solution`). None before the start.
    pub fn published_solution(&self) -> Option<Solution> {
        let state = self.state()?;
        Some(recovery::published_solution(
            state,
            &self.monitor,
            self.published_adaptation(),
            &self.config,
        ))
    }

    /// What the noise judges find beyond the measurements' claims now, the floor of the
    /// published covariances (ENU): the position's (m²) and the velocity's ((m/s)²); zero
    /// while they find none.
    pub fn unclaimed_covariances(&self) -> (Matrix3<f64>, Matrix3<f64>) {
        self.published_adaptation().unclaimed_covariances()
    }

    /// The adaptation whose judges the published solution reflects: while a heading bank
    /// runs, its best hypothesis'.
    fn published_adaptation(&self) -> &Adaptation {
        match &self.phase {
            Phase::Aligning(bank) => bank.best_adaptation().unwrap_or(&self.adaptation),
            _ => &self.adaptation,
        }
    }

    /// The GNSS position less the filter's (ENU, m) while the GNSS and the filter disagree
    /// after a GNSS leap that the IMU does not support ([`divergence`]): one of them is
    /// wrong, and the published covariance is widened by it.
    pub fn gnss_dispute_offset_enu_m(&self) -> Option<Vector3<f64>> {
        self.monitor.dispute_offset_enu_m()
    }

    /// How the fixes of the current dispute are held back now, loosely coupled with
    /// `loose.leap_hold_s` ([`dispute`]); None while they are taken as they are.
    pub fn fix_hold(&self) -> Option<Hold> {
        recovery::fix_hold(self.last_imu_t_s()?, &self.monitor, &self.config)
    }

    /// The heading hypotheses of a split of the running filter (see [`heading_bank`]), 0
    /// while one filter runs or before the start.
    pub fn heading_hypotheses(&self) -> usize {
        match &self.phase {
            Phase::Aligning(bank) if bank.published().is_some() => bank.len(),
            _ => 0,
        }
    }

    /// The start-up phase, or None once running.
    pub fn init_phase(&self) -> Option<InitPhase> {
        match &self.phase {
            Phase::Initializing(init) => Some(init.phase()),
            Phase::Aligning(bank) if bank.published().is_none() => Some(InitPhase::AligningHeading),
            Phase::Aligning(_) | Phase::Running(_) => None,
        }
    }

    /// The sizes of the buffers, each bounded ([`MAX_BUFFERED_IMU_SAMPLES`],
    /// [`MAX_PENDING_MEASUREMENTS`], [`standstill::MAX_WINDOW_SAMPLES`]).
    pub fn buffered(&self) -> Buffered {
        Buffered {
            imu_samples: self.imu.len(),
            steps: self.history.len(),
            states: (self.history.iter())
                .filter(|s| matches!(s.kept, Kept::Phase(_)))
                .count(),
            measurements: self.pending.len(),
            standstill_samples: self.standstill.sample_count(),
        }
    }

    /// Time of the last accepted IMU sample.
    pub fn last_imu_t_s(&self) -> Option<f64> {
        self.imu.back().map(|s| s.t_s)
    }

    /// The factor on the configured process noise Q in use (1 without `filter.q_scaling`).
    pub fn q_scale(&self) -> f64 {
        self.adaptation.q.scale()
    }

    /// The configured filter variant's name.
    pub fn variant_name(&self) -> &'static str {
        self.config.filter.variant.as_str()
    }

    /// Forgets everything (as after a time jump backwards) and starts again; the attitude
    /// learned so far is kept when the filter was running, unless it diverged (see
    /// [`Initializer::after_divergence`]).
    pub fn reset(&mut self, t_s: f64, reason: ResetReason) -> Output {
        let init = match self.state() {
            Some(_) if reason == ResetReason::DivergedFromGnss => {
                Box::new(Initializer::after_divergence())
            }
            Some(s) => Box::new(Initializer::with_attitude(
                s.nav.q_nb,
                s.gyro_bias_rad_s + s.gyro_markov_rad_s,
                s.last_imu.t_s,
            )),
            None => Box::default(),
        };
        self.phase = Phase::Initializing(init);
        // Choice: after a divergence from GNSS the fix judges keep their verdicts on the
        // receiver's claims: a restart changes the filter, not the receiver, and the
        // judges learn again only over their window, during which a restart in foliage
        // took the receiver's claims (velocities metres per second off at 0.1 m/s) for
        // the truth, and its tilt and vertical gyro bias took the rest (docs/results.md,
        // "What that row was"). The other resets forget them: a time jump back or another
        // IMU may be another recording, and after an IMU gap or a non-finite state keeping
        // them was not measured.
        let fix_judges =
            (reason == ResetReason::DivergedFromGnss).then(|| self.adaptation.fix.clone());
        self.adaptation.reset();
        if let Some(fix_judges) = fix_judges {
            self.adaptation.fix = fix_judges;
        }
        self.monitor.clear();
        self.imu.clear();
        self.history.clear();
        self.pending.clear();
        self.constraints.clear();
        self.standstill.clear();
        self.last_output_t_s = f64::NEG_INFINITY;
        self.start_reported = false;
        Output::Status(StatusEvent::Reset { t_s, reason })
    }

    /// Feeds one IMU sample in the IMU's own axes.
    pub fn push_imu(&mut self, sample: &ImuSample) -> Result<Vec<Output>, InputRejected> {
        let body = ImuSample {
            t_s: sample.t_s,
            w_ib_b_rad_s: self.config.mounting.imu_to_body * sample.w_ib_b_rad_s,
            f_ib_b_m_s2: self.config.mounting.imu_to_body * sample.f_ib_b_m_s2,
        };
        if !body.is_finite() {
            return Err(self
                .counters
                .reject(RejectionReason::ImuNotFinite, sample.t_s));
        }
        let mut out = Vec::new();
        if let Some(last) = self.imu.back() {
            let dt = body.t_s - last.t_s;
            if dt == 0.0 {
                return Err(self
                    .counters
                    .reject(RejectionReason::ImuDuplicate, body.t_s));
            }
            if dt < 0.0 {
                return Err(self
                    .counters
                    .reject(RejectionReason::ImuOutOfOrder, body.t_s));
            }
        }
        match self.screen.screen(sample, &self.config.imu) {
            Screened::Kept => {}
            Screened::OutOfRange => {
                return Err(self
                    .counters
                    .reject(RejectionReason::ImuOutOfRange, body.t_s))
            }
            Screened::Spike => {
                return Err(self
                    .counters
                    .reject(RejectionReason::ImuInconsistent, body.t_s))
            }
        }
        if let Some(last) = self.imu.back() {
            if body.t_s - last.t_s > self.config.engine.max_imu_gap_s {
                self.counters.reject(RejectionReason::ImuGap, body.t_s);
                out.push(self.reset(body.t_s, ResetReason::ImuGap));
            }
        }
        self.take_body_sample(body, &mut out);
        Ok(out)
    }

    /// Buffers the screened body-frame sample `body` and processes everything up to it.
    fn take_body_sample(&mut self, body: ImuSample, out: &mut Vec<Output>) {
        self.standstill.push(&body);
        self.constraints
            .push_window(body.t_s, &self.standstill, &self.config);
        self.imu.push_back(body);
        let horizon = body.t_s - self.config.engine.imu_buffer_s;
        while self.imu.len() > MAX_BUFFERED_IMU_SAMPLES
            || self.imu.front().is_some_and(|s| s.t_s < horizon) && self.imu.len() > 2
        {
            self.imu.pop_front();
        }
        if let Some(oldest) = self.imu.front() {
            self.constraints.forget_before(oldest.t_s);
        }
        // Room for the step to this sample.
        let stale = self.history.iter().take_while(|s| s.t_s < horizon).count();
        let over = (self.history.len() + 1).saturating_sub(MAX_BUFFERED_IMU_SAMPLES);
        self.history.drain(..stale.max(over));
        self.advance(&body, out);
    }

    /// Feeds one GNSS epoch (tightly coupled).
    pub fn push_gnss(&mut self, epoch: GnssEpoch) -> Result<Vec<Output>, InputRejected> {
        if !epoch.t_s.is_finite() || !epoch.gps_time_of_week_s.is_finite() {
            return Err(self
                .counters
                .reject(RejectionReason::GnssNotFinite, epoch.t_s));
        }
        if epoch.satellites.is_empty() {
            return Err(self
                .counters
                .reject(RejectionReason::GnssNoSatellites, epoch.t_s));
        }
        if self.config.filter.coupling != Coupling::Tight {
            return Err(self
                .counters
                .reject(RejectionReason::WrongCoupling, epoch.t_s));
        }
        self.push_measurement(Measurement::Gnss(epoch))
    }

    /// Feeds one receiver fix (loosely coupled).
    pub fn push_fix(&mut self, fix: GnssFix) -> Result<Vec<Output>, InputRejected> {
        if !fix.is_finite() {
            return Err(self.counters.reject(RejectionReason::FixNotFinite, fix.t_s));
        }
        if self.config.filter.coupling != Coupling::Loose {
            return Err(self
                .counters
                .reject(RejectionReason::WrongCoupling, fix.t_s));
        }
        self.push_measurement(Measurement::Fix(fix))
    }

    /// Feeds one forward speed of the base controller's wheels (m/s along the body x axis,
    /// negative when reversing) with its 1-sigma (m/s; None: `wheel_odometry.sigma_mps`),
    /// when `wheel_odometry.enabled` and the filter runs.
    pub fn push_wheel_speed(
        &mut self,
        t_s: f64,
        speed_mps: f64,
        sigma_mps: Option<f64>,
    ) -> Result<Vec<Output>, InputRejected> {
        let reading = WheelSpeedReading {
            t_s,
            speed_mps,
            sigma_mps,
        };
        if !reading.is_valid() {
            return Err(self
                .counters
                .reject(RejectionReason::WheelSpeedInvalid, t_s));
        }
        if !self.config.wheel_odometry.enabled {
            return Err(self.counters.reject(RejectionReason::WheelOdometryOff, t_s));
        }
        if self.state().is_none() {
            return Err(self
                .counters
                .reject(RejectionReason::WheelSpeedBeforeStart, t_s));
        }
        self.push_measurement(Measurement::WheelSpeed(reading))
    }

    /// Feeds one heading of a dual-antenna pair's baseline, when `dual_antenna.enabled`
    /// and it passes the screening of [`BaselineHeadingReading`]; before the start it
    /// becomes the start's heading.
    pub fn push_baseline_heading(
        &mut self,
        reading: BaselineHeadingReading,
    ) -> Result<Vec<Output>, InputRejected> {
        if let Err(reason) = reading.screen(&self.config) {
            return Err(self.counters.reject(reason, reading.t_s));
        }
        self.push_measurement(Measurement::BaselineHeading(reading))
    }

    fn push_measurement(&mut self, m: Measurement) -> Result<Vec<Output>, InputRejected> {
        let t = m.t_s();
        let Some(last_t) = self.last_imu_t_s() else {
            // Nothing to align it with yet: it waits for the IMU.
            self.enqueue(m, false);
            return Ok(Vec::new());
        };
        if self.pending.iter().any(|p| p.measurement.duplicates(&m))
            || self
                .history
                .iter()
                .any(|s| s.applied.iter().any(|a| a.measurement.duplicates(&m)))
        {
            return Err(self
                .counters
                .reject(RejectionReason::MeasurementDuplicate, t));
        }
        if t > last_t + self.config.engine.imu_buffer_s {
            // Choice: a measurement may wait for the IMU as long as a late one may reach
            // back; one further ahead (a bad stamp) would wait, and hold memory, forever.
            return Err(self.counters.reject(RejectionReason::MeasurementTooNew, t));
        }
        if t >= last_t {
            self.enqueue(m, false);
            return Ok(Vec::new());
        }
        let oldest = self.imu.front().map_or(last_t, |s| s.t_s);
        if t < oldest {
            return Err(self.counters.reject(RejectionReason::MeasurementTooOld, t));
        }
        let mut out = Vec::new();
        match self.late_target(t) {
            LateTarget::Step(k) => {
                self.late_measurements += 1;
                self.enqueue(m, false);
                let undone: Vec<Step> = self.history.drain(k + 1..).collect();
                for step in undone {
                    for a in step.applied {
                        self.enqueue(a.measurement, a.reported);
                    }
                }
                let kept = &self.history[k];
                let from_t_s = kept.t_s;
                if let Kept::Phase(phase) = &kept.kept {
                    self.phase = phase.clone();
                }
                self.replay_after(from_t_s, &mut out);
            }
            LateTarget::AsItIs => {
                // Choice: re-running a bank is up to 36 filters over the buffer; the
                // measurement is taken as it is now, as a late one without a roll-back
                // would be.
                self.late_measurements += 1;
                let newest = *self.imu.back().expect("an IMU sample, as last_t");
                let p = Pending {
                    measurement: m,
                    reported: false,
                };
                let reported = self.apply_measurement(&p, &newest, &mut out);
                if let Some(step) = self.history.back_mut() {
                    step.applied.push(Pending {
                        measurement: p.measurement,
                        reported,
                    });
                }
            }
            LateTarget::TooOld => {
                return Err(self.counters.reject(RejectionReason::MeasurementTooOld, t));
            }
        }
        Ok(out)
    }

    fn enqueue(&mut self, measurement: Measurement, reported: bool) {
        if self.pending.len() >= MAX_PENDING_MEASUREMENTS {
            let oldest = self.pending.remove(0).measurement.t_s();
            self.counters
                .reject(RejectionReason::MeasurementQueueFull, oldest);
        }
        let t = measurement.t_s();
        let at = self.pending.partition_point(|p| p.measurement.t_s() <= t);
        self.pending.insert(
            at,
            Pending {
                measurement,
                reported,
            },
        );
    }

    /// Where a late measurement at `t_s` goes: the last step at or before it that kept a
    /// phase, unless a heading bank ran since.
    fn late_target(&self, t_s: f64) -> LateTarget {
        for (k, step) in self.history.iter().enumerate().rev() {
            match step.kept {
                Kept::Bank => return LateTarget::AsItIs,
                Kept::Phase(_) if step.t_s <= t_s => return LateTarget::Step(k),
                Kept::Phase(_) | Kept::Nothing => {}
            }
        }
        LateTarget::TooOld
    }

    /// Re-integrates the buffered IMU samples after `from_t_s` (the restored phase's
    /// time), applying the pending measurements on the way. A reset on the way (which
    /// empties the buffers) ends the re-integration: the samples after it are taken as
    /// new ones, as they were when they arrived after it.
    fn replay_after(&mut self, from_t_s: f64, out: &mut Vec<Output>) {
        let samples: Vec<ImuSample> = self
            .imu
            .iter()
            .filter(|s| s.t_s > from_t_s)
            .copied()
            .collect();
        self.replaying = true;
        let mut done = samples.len();
        for (k, s) in samples.iter().enumerate() {
            self.advance(s, out);
            if self.imu.is_empty() {
                done = k + 1;
                break;
            }
        }
        self.replaying = false;
        for s in &samples[done..] {
            self.take_body_sample(*s, out);
        }
    }

    /// Processes everything up to the body-frame sample `s` (already buffered).
    fn advance(&mut self, s: &ImuSample, out: &mut Vec<Output>) {
        let mut applied = Vec::new();
        while self
            .pending
            .first()
            .is_some_and(|p| p.measurement.t_s() < s.t_s)
        {
            let p = self.pending.remove(0);
            let reported = self.apply_measurement(&p, s, out);
            applied.push(Pending {
                measurement: p.measurement,
                reported,
            });
        }
        match &mut self.phase {
            Phase::Initializing(init) => init.push_imu(s, &self.config),
            Phase::Aligning(bank) => {
                if bank.last_imu_t_s() < s.t_s {
                    if let Err(e) = bank.propagate(s, &self.process_noise) {
                        log::warn!(
                            "IMU step of the heading bank to t = {:.6} s failed: {e}",
                            s.t_s
                        );
                        self.counters.reject(RejectionReason::ImuStepFailed, s.t_s);
                        let reset = self.reset(s.t_s, ResetReason::Diverged);
                        out.push(reset);
                        return;
                    }
                }
                if let Some(published) = bank.published() {
                    let t_s = published.last_imu.t_s;
                    if output_due(self.config.output.rate_hz, &mut self.last_output_t_s, t_s) {
                        let solution = recovery::published_solution(
                            published,
                            &self.monitor,
                            bank.best_adaptation().unwrap_or(&self.adaptation),
                            &self.config,
                        );
                        out.push(Output::Solution(Box::new(solution)));
                    }
                }
            }
            Phase::Running(state) => {
                if state.last_imu.t_s < s.t_s {
                    let prev_t_s = state.last_imu.t_s;
                    let noise = self.process_noise.scaled(self.adaptation.q.scale());
                    if let Err(e) = state.propagate(s, &noise) {
                        log::warn!("IMU step to t = {:.6} s failed: {e}", s.t_s);
                        self.counters.reject(RejectionReason::ImuStepFailed, s.t_s);
                        let reset = self.reset(s.t_s, ResetReason::Diverged);
                        out.push(reset);
                        return;
                    }
                    let count = !self.replaying;
                    let applied = self.constraints.apply(
                        state,
                        prev_t_s,
                        &self.config,
                        &mut self.adaptation,
                        count,
                    );
                    if let Err(e) = applied {
                        log::warn!("constraint update at t = {:.6} s failed: {e}", s.t_s);
                        self.counters.reject(RejectionReason::UpdateFailed, s.t_s);
                    }
                }
                // A re-integration after a roll-back publishes only what was not yet
                // published: the solutions of a start it found.
                let t_s = state.last_imu.t_s;
                if output_due(self.config.output.rate_hz, &mut self.last_output_t_s, t_s) {
                    let solution = recovery::published_solution(
                        state,
                        &self.monitor,
                        &self.adaptation,
                        &self.config,
                    );
                    out.push(Output::Solution(Box::new(solution)));
                }
                let moving = state.nav.v_n.xy().norm() >= self.config.init.heading_min_speed_mps;
                if let Some(bank) = moving
                    .then(|| HeadingBank::split(state, &self.config, &self.adaptation.fix))
                    .flatten()
                {
                    self.phase = Phase::Aligning(Box::new(bank));
                }
            }
        }
        let due = (self.history.iter().rev())
            .take(STATE_EVERY_STEPS - 1)
            .all(|s| matches!(s.kept, Kept::Nothing));
        let kept = match &self.phase {
            Phase::Aligning(_) => Kept::Bank,
            phase if due => Kept::Phase(phase.clone()),
            _ => Kept::Nothing,
        };
        self.history.push_back(Step {
            t_s: s.t_s,
            kept,
            applied,
        });
    }

    /// Propagates to the measurement's time (running) or tries to start (initializing),
    /// then applies it; returns whether it is reported now (the running filter took it).
    fn apply_measurement(&mut self, p: &Pending, next: &ImuSample, out: &mut Vec<Output>) -> bool {
        let t = p.measurement.t_s();
        let report = !p.reported;
        let reported = p.reported || self.state().is_some();
        if let Measurement::Fix(f) = &p.measurement {
            self.constraints.note_fix(f);
        }
        match &mut self.phase {
            Phase::Initializing(_) => self.try_start(&p.measurement, next, out),
            Phase::Aligning(_) => self.update_bank(&p.measurement, next, report, out),
            Phase::Running(state) => {
                if state.last_imu.t_s < t {
                    let at_t = interpolate(&state.last_imu, next, t);
                    let noise = self.process_noise.scaled(self.adaptation.q.scale());
                    if let Err(e) = state.propagate(&at_t, &noise) {
                        log::warn!("IMU step to the measurement at t = {t:.6} s failed: {e}");
                        self.counters.reject(RejectionReason::ImuStepFailed, t);
                        return p.reported;
                    }
                }
                let w = state.compensate(&state.last_imu).w_ib_b_rad_s;
                let before = state.as_ref().clone();
                // A fix is judged before its update (see recovery::fix_disagreement).
                let (fix_diverged, hold) = match &p.measurement {
                    Measurement::Fix(f) => {
                        let diverged = report.then(|| {
                            let d = recovery::fix_disagreement(
                                &before,
                                f,
                                &self.adaptation,
                                &self.config,
                            );
                            self.monitor.check(t, Some(&d))
                        });
                        (diverged, recovery::fix_hold(t, &self.monitor, &self.config))
                    }
                    _ => (None, None),
                };
                let adaptation = &mut self.adaptation;
                let result = match &p.measurement {
                    Measurement::Gnss(e) => {
                        let noise = self.process_noise.scaled(adaptation.q.scale());
                        update::apply_gnss_epoch(
                            state,
                            e,
                            &w,
                            &self.config,
                            &noise,
                            adaptation,
                            report,
                        )
                    }
                    Measurement::Fix(f) => match &hold {
                        Some(Hold::LeftOut { .. }) => Ok(update::fix_left_out(f.t_s, adaptation)),
                        _ => {
                            let model = update::FixMeasurement::new(f, &w, &self.config, state);
                            let mut model = match hold {
                                Some(Hold::MovedBack {
                                    offset_enu_m,
                                    covariance_enu_m2,
                                    ..
                                }) => model.held_back(&offset_enu_m, &covariance_enu_m2),
                                _ => model,
                            };
                            update::apply(state, &mut model, adaptation, report)
                        }
                    },
                    // Choice: the noise strategies and the process-noise scaling do not
                    // learn from a wheel speed (as from the motion constraints): its σ is
                    // the base controller's or the configured one, and the estimators stay
                    // those of the GNSS measurements they were made for.
                    Measurement::WheelSpeed(reading) => {
                        let mut model = reading.model(&self.config);
                        update::apply(state, &mut model, adaptation, false)
                    }
                    // Choice: nor from a baseline heading, for the same reasons.
                    Measurement::BaselineHeading(reading) => {
                        let mut model = reading.model(&self.config);
                        update::apply(state, &mut model, adaptation, false)
                    }
                };
                let gnss = matches!(p.measurement, Measurement::Gnss(_) | Measurement::Fix(_));
                match result {
                    Ok(epoch) if state.is_finite() => {
                        // The baseline heading's model leaves out a heading beyond its
                        // gate: no rows, counted once.
                        if report
                            && epoch.measurements_used == 0
                            && matches!(p.measurement, Measurement::BaselineHeading(_))
                        {
                            self.counters
                                .reject(RejectionReason::BaselineHeadingGated, t);
                        }
                        if report {
                            self.deweighted.count(&epoch);
                        }
                        // A wheel speed or a baseline heading is no GNSS input to
                        // monitor, and gives no report (as the motion constraints).
                        if report && gnss {
                            let reset = match (&p.measurement, fix_diverged) {
                                (Measurement::Gnss(e), _) => {
                                    self.monitor_gnss_epoch(&before, e, &epoch)
                                }
                                (_, diverged) => {
                                    diverged.unwrap_or(false).then(|| self.reset_diverged(t))
                                }
                            };
                            out.push(Output::Epoch(epoch));
                            out.extend(reset);
                        }
                    }
                    Ok(_) | Err(_) => {
                        if let Err(e) = &result {
                            log::warn!("update at t = {t:.3} s failed: {e}");
                        }
                        **state = before;
                        self.counters.reject(RejectionReason::UpdateFailed, t);
                    }
                }
            }
        }
        reported
    }
}

/// Whether a solution at `t_s` is due at `rate_hz` (0: every IMU sample) after the last one
/// at `last_output_t_s`, which it then becomes; never one at or before it (published
/// already, or passed over).
fn output_due(rate_hz: f64, last_output_t_s: &mut f64, t_s: f64) -> bool {
    if t_s <= *last_output_t_s || rate_hz > 0.0 && t_s - *last_output_t_s < 1.0 / rate_hz - 1e-9 {
        return false;
    }
    *last_output_t_s = t_s;
    true
}

/// The process noise of the configuration.
pub fn process_noise(config: &Config) -> ProcessNoise {
    ProcessNoise {
        gyro_arw_rad_per_sqrt_s: config.imu.gyro_arw_rad_per_sqrt_s,
        gyro_markov_sigma_rad_s: config.imu.gyro_markov_sigma_rad_s,
        gyro_markov_time_s: config.imu.gyro_markov_time_s,
        accel_vrw_m_s_per_sqrt_s: config.imu.accel_vrw_m_s_per_sqrt_s,
        accel_bias_sigma_m_s2: config.imu.accel_bias_sigma_m_s2,
        accel_markov_time_s: config.imu.accel_markov_time_s,
        // Choice: loosely coupled, nothing measures the receiver clock, so its states are
        // inert (as the optional states when off): the covariance propagates on 18
        // states instead of 20, and the other states' numbers are the same to the bit.
        clock: (config.filter.coupling == Coupling::Tight).then_some(ClockNoise {
            bias_noise_m_per_sqrt_s: config.clock.bias_noise_m_per_sqrt_s,
            drift_noise_m_s_per_sqrt_s: config.clock.drift_noise_m_s_per_sqrt_s,
            drift_time_s: config.clock.drift_time_s,
        }),
        wheel_scale_noise_per_sqrt_s: if config.wheel_odometry.scale_factor_state {
            config.wheel_odometry.scale_factor_noise_per_sqrt_s
        } else {
            0.0
        },
        imu_scale: config.imu.scale_factor_states.then_some(ImuScaleNoise {
            gyro_sigma: config.imu.gyro_scale_factor_sigma,
            accel_sigma: config.imu.accel_scale_factor_sigma,
            time_s: config.imu.scale_factor_time_s,
        }),
    }
}
