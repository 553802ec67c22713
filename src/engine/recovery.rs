//! The engine's side of the divergence monitor ([`super::divergence`]): each GNSS input's
//! independent position against the filter's prior, and the reset that follows a
//! divergence.

use nalgebra::Matrix3;

use super::divergence::{Disagreement, DivergenceMonitor, GnssVelocityEnu};
use super::filter_state::FilterState;
use super::output::{EpochReport, SatRejection, Solution};
use super::update::{position_covariance, sigma_model};
use super::{initializer, Engine, Measurement, Output, ResetReason};
use crate::config::Config;
use crate::earth::{self, Llh};
use crate::gnss::spp::{self, SppConfig};
use crate::gnss::GnssEpoch;

/// Share of an epoch's judged pseudo-ranges the gate must have refused before the
/// single-point solution is computed to judge the filter (tight coupling).
///
/// Choice: one half. A filter off by far more than its σ has nearly every pseudo-range
/// gated out (the classic divergence signature: good data rejected against a wrong state);
/// on the other epochs the monitor costs a few comparisons and no least squares.
pub const SPP_ABOVE_GATED_SHARE: f64 = 0.5;

impl Engine {
    /// Feeds the monitor with the disagreement of `prior` (the filter before the update
    /// by `m`, whose report is `report`); on divergence resets the filter and returns
    /// the reset.
    pub(super) fn monitor_divergence(
        &mut self,
        prior: &FilterState,
        m: &Measurement,
        report: &EpochReport,
    ) -> Option<Output> {
        let gnss = match m {
            Measurement::Fix(f) => Some(IndependentGnss {
                position: f.position,
                covariance_enu_m2: position_covariance(f, &self.config),
                weight_scale: report.fix_scales.first().copied().unwrap_or(1.0),
                velocity: f.velocity_enu_mps.zip(f.velocity_covariance_enu_m2_s2),
            }),
            Measurement::Gnss(e) => single_point_if_gated(e, report, prior, &self.config),
            Measurement::WheelSpeed(_) | Measurement::BaselineHeading(_) => None,
        };
        let disagreement = gnss.map(|g| {
            Disagreement::of(
                prior,
                &g.position,
                &g.covariance_enu_m2,
                g.weight_scale,
                g.velocity.as_ref(),
                &self.config,
            )
        });
        if !self.monitor.check(report.t_s, disagreement.as_ref()) {
            return None;
        }
        let t_s = report.t_s;
        log::error!(
            "the filter diverged from GNSS at t = {t_s:.3} s (beyond {} σ for {} s): re-initializing",
            super::divergence::DISAGREE_SIGMA,
            super::divergence::MIN_SPAN_S
        );
        self.divergence_resets += 1;
        self.diverged_at_t_s = Some(t_s);
        // Nothing of the diverged state is kept (see Initializer::after_divergence).
        Some(self.reset(t_s, ResetReason::DivergedFromGnss))
    }
}

/// The solution of `state` as the engine publishes it: while the monitor holds a dispute
/// (a GNSS leap the IMU does not support: the GNSS or the filter is wrong, it cannot tell
/// which), its position covariance widened by the offset's outer product.
pub(super) fn published_solution(state: &FilterState, monitor: &DivergenceMonitor) -> Solution {
    let mut solution = state.solution();
    if let Some(offset_enu_m) = monitor.dispute_offset_enu_m() {
        solution.widen_position_by(&offset_enu_m);
    }
    solution
}

/// A GNSS position independent of the filter, and its velocity when there is one.
struct IndependentGnss {
    position: Llh,
    covariance_enu_m2: Matrix3<f64>,
    /// The factor the update weighed `covariance_enu_m2` with (1: as claimed).
    weight_scale: f64,
    velocity: Option<GnssVelocityEnu>,
}

/// The single-point solution of `epoch` (position, velocity and their ENU covariances)
/// when the gate refused at least [`SPP_ABOVE_GATED_SHARE`] of its judged pseudo-ranges;
/// None otherwise or when it has no solution with `init.min_satellites`.
fn single_point_if_gated(
    epoch: &GnssEpoch,
    report: &EpochReport,
    prior: &FilterState,
    config: &Config,
) -> Option<IndependentGnss> {
    let gated = |r: &Option<SatRejection>| {
        matches!(
            r,
            Some(SatRejection::InnovationGate | SatRejection::Mahalanobis)
        )
    };
    let judged = report
        .satellites
        .iter()
        .filter(|s| s.used_pseudorange || gated(&s.rejection))
        .count();
    let refused = report
        .satellites
        .iter()
        .filter(|s| gated(&s.rejection))
        .count();
    if judged == 0 || (refused as f64) < SPP_ABOVE_GATED_SHARE * judged as f64 {
        return None;
    }
    let spp_config = SppConfig {
        elevation_mask_rad: config.gnss.elevation_mask_rad,
        sigma: sigma_model(config),
        initial_position_ecef_m: Some(earth::llh_to_ecef(&prior.nav.p)),
        ..SppConfig::default()
    };
    let epoch = initializer::filter_constellations(epoch, config);
    let sol = spp::solve_spp(&epoch, &spp_config).ok()?;
    if sol.num_used < config.init.min_satellites {
        return None;
    }
    let rot = earth::rot_ecef_to_enu(&sol.pos_llh);
    let to_enu = |cov_ecef: Matrix3<f64>| rot * cov_ecef * rot.transpose();
    let velocity = sol.velocity.as_ref().ok().map(|v| {
        let cov_ecef: Matrix3<f64> = v.covariance.fixed_view::<3, 3>(0, 0).into();
        (v.vel_enu_mps, to_enu(cov_ecef))
    });
    Some(IndependentGnss {
        position: sol.pos_llh,
        covariance_enu_m2: to_enu(sol.covariance.fixed_view::<3, 3>(0, 0).into()),
        weight_scale: 1.0,
        velocity,
    })
}
