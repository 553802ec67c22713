//! One run of the engine over a stream of core inputs (a simulated scenario), with
//! scoring against the reference. Recorded bags go through the ROS adapter instead (see
//! [`super::bag_run`]); the tests drive simulated scenarios through this.

use crate::config::{Config, Coupling};
use crate::engine::{BaselineHeadingReading, Engine, GnssFix, Output};
use crate::eval::TruthTrack;
use crate::gnss::GnssEpoch;
use crate::ins::ImuSample;

use super::scoring::{Reference, Scorer, SessionReport};

/// One input of a session, in time order.
#[derive(Debug, Clone, PartialEq)]
pub enum SessionInput {
    Imu(ImuSample),
    Gnss(GnssEpoch),
    Fix(GnssFix),
    /// A forward speed of the wheels (m/s) with its 1-sigma (m/s; None: the configured).
    WheelSpeed {
        t_s: f64,
        speed_mps: f64,
        sigma_mps: Option<f64>,
    },
    /// A dual-antenna pair's baseline heading.
    BaselineHeading(BaselineHeadingReading),
    Reference(Reference),
}

/// Drives an [`Engine`] and scores its solutions.
pub struct Session {
    engine: Engine,
    scorer: Scorer,
}

impl Session {
    /// A session running `config`, scoring at most every `score_interval_s` (0: every
    /// match), against `track` when given, else against the streamed references.
    pub fn new(config: Config, score_interval_s: f64, track: Option<TruthTrack>) -> Self {
        Self {
            engine: Engine::new(config),
            scorer: Scorer::new(score_interval_s, track),
        }
    }

    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// Feeds one input; returns the engine's outputs (for writing). Measurements of the
    /// other coupling (fixes when tightly coupled, raw epochs when loosely) are not used.
    pub fn push(&mut self, input: SessionInput) -> Vec<Output> {
        let coupling = self.engine.config().filter.coupling;
        let result = match input {
            SessionInput::Imu(s) => self.engine.push_imu(&s),
            SessionInput::Gnss(e) if coupling == Coupling::Tight => self.engine.push_gnss(e),
            SessionInput::Fix(f) if coupling == Coupling::Loose => self.engine.push_fix(f),
            SessionInput::Gnss(_) | SessionInput::Fix(_) => return Vec::new(),
            SessionInput::WheelSpeed {
                t_s,
                speed_mps,
                sigma_mps,
            } => self.engine.push_wheel_speed(t_s, speed_mps, sigma_mps),
            SessionInput::BaselineHeading(h) => self.engine.push_baseline_heading(h),
            SessionInput::Reference(r) => {
                self.scorer.on_reference(r);
                return Vec::new();
            }
        };
        // A rejected input is counted by the engine (see `Engine::counters`).
        let outputs = result.unwrap_or_default();
        for o in &outputs {
            match o {
                Output::Solution(sol) => self.scorer.on_solution(sol.clone()),
                Output::Epoch(report) => self.scorer.on_epoch(report),
                Output::Status(_) => {}
            }
        }
        outputs
    }

    /// Ends the session.
    pub fn finish(self) -> SessionReport {
        self.scorer.finish()
    }
}
