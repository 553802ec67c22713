//! The engine's start-up steps: a GNSS measurement handed to the initializer, and to the
//! bank of heading hypotheses when the start's heading is too uncertain for one filter.

use nalgebra::Vector3;

use super::filter_state::{interpolate, FilterState};
use super::heading_bank::{self, HeadingBank};
use super::initializer::InitialState;
use super::update;
use super::{Engine, Measurement, Output, Phase, ResetReason, StatusEvent};
use crate::ins::ImuSample;

impl Engine {
    /// Tries to start from the GNSS measurement `m` (the sample after it is `next`); on
    /// success the filter runs, or the heading bank does.
    pub(super) fn try_start(&mut self, m: &Measurement, next: &ImuSample, out: &mut Vec<Output>) {
        let Phase::Initializing(init) = &mut self.phase else {
            return;
        };
        // The window of `next` (the first sample after the measurement), as when it
        // arrived in time, also after a roll-back.
        let recent = self.standstill.window_ending_at(next.t_s);
        let started = match m {
            Measurement::Gnss(e) => init.try_gnss(e, &self.config, &recent),
            Measurement::Fix(f) => init.try_fix(f, &self.config, &recent),
            Measurement::WheelSpeed(_) => None,
            Measurement::BaselineHeading(reading) => {
                init.note_antenna_heading(reading.start_heading(&self.config));
                None
            }
        };
        let Some(initial) = started else {
            return;
        };
        let t = m.t_s();
        let state = self.initial_filter_state(&initial, t, next);
        if initial.heading_sigma_rad > heading_bank::BANK_ABOVE_RAD {
            self.phase = Phase::Aligning(Box::new(HeadingBank::new(
                &state,
                initial.heading_sigma_rad,
                &self.config,
                &self.adaptation.fix,
            )));
            return;
        }
        self.start_running(state, initial.heading_from_motion, out);
    }

    /// The filter state of a start at `t` (between the buffered samples and `next`).
    fn initial_filter_state(
        &self,
        initial: &InitialState,
        t: f64,
        next: &ImuSample,
    ) -> FilterState {
        let before = self
            .imu
            .iter()
            .rev()
            .find(|s| s.t_s <= t)
            .copied()
            .unwrap_or(*next);
        FilterState {
            nav: initial.nav,
            gyro_bias_rad_s: initial.gyro_bias_rad_s,
            gyro_markov_rad_s: Vector3::zeros(),
            accel_bias_m_s2: initial.accel_bias_m_s2,
            clock_bias_m: initial.clock_bias_m,
            clock_drift_mps: initial.clock_drift_mps,
            wheel_scale_factor: self.config.wheel_odometry.scale_factor,
            gyro_scale_error: Vector3::zeros(),
            accel_scale_error: Vector3::zeros(),
            p: initial.p,
            prev_increment: None,
            last_imu: interpolate(&before, next, t),
            phase_anchor: None,
        }
    }

    fn start_running(
        &mut self,
        state: FilterState,
        heading_from_motion: bool,
        out: &mut Vec<Output>,
    ) {
        let t_s = state.nav.t_s;
        self.phase = Phase::Running(Box::new(state));
        self.diverged_at_t_s = None;
        // Reported once: a roll-back may start the filter again, at the same time or (the
        // late measurement completing an earlier start) before.
        if !self.start_reported {
            self.start_reported = true;
            out.push(Output::Status(StatusEvent::Initialized {
                t_s,
                heading_from_motion,
            }));
        }
    }

    /// Updates every hypothesis of the heading bank with `m`; a split of the running filter
    /// reports its best hypothesis' epoch (when `report`, as the running filter). Runs one
    /// filter again once the bank has decided.
    pub(super) fn update_bank(
        &mut self,
        m: &Measurement,
        next: &ImuSample,
        report: bool,
        out: &mut Vec<Output>,
    ) {
        let Phase::Aligning(bank) = &mut self.phase else {
            return;
        };
        let t = m.t_s();
        let epoch = bank.update(t, next, &self.process_noise, |state, adaptation, config| {
            let w = state.compensate(&state.last_imu).w_ib_b_rad_s;
            match m {
                Measurement::Gnss(e) => {
                    let mut model = update::Pseudoranges::new(e, &w, config);
                    update::apply(state, &mut model, adaptation, true)
                }
                Measurement::Fix(f) => {
                    let mut model = update::FixMeasurement::new(f, &w, config, state);
                    update::apply(state, &mut model, adaptation, true)
                }
                Measurement::WheelSpeed(reading) => {
                    let mut model = reading.model(config);
                    update::apply(state, &mut model, adaptation, false)
                }
                Measurement::BaselineHeading(reading) => {
                    let mut model = reading.model(config);
                    update::apply(state, &mut model, adaptation, false)
                }
            }
        });
        if bank.is_empty() {
            // A split was the running filter: its loss is a reset, said so.
            if bank.published().is_some() {
                let reset = self.reset(t, ResetReason::Diverged);
                out.push(reset);
            } else {
                self.phase = Phase::Initializing(Box::default());
            }
            return;
        }
        let gnss = matches!(m, Measurement::Gnss(_) | Measurement::Fix(_));
        if let Some(epoch) = epoch.filter(|_| report && gnss && bank.published().is_some()) {
            self.deweighted.count(&epoch);
            out.push(Output::Epoch(epoch));
        }
        if let Some(state) = bank.resolved(t) {
            // Choice: the filter runs on with the judges of the hypothesis it continues,
            // which weighed every fix while the bank ran; its own stopped at the split
            // (or, for a start, knew nothing).
            if let Some(best) = bank.best_adaptation() {
                self.adaptation.fix = best.fix.clone();
            }
            self.start_running(state, true, out);
        }
    }
}
