//! The engine's side of the divergence monitor ([`super::divergence`]): each GNSS input's
//! independent position against the filter's prior, and the reset that follows a
//! divergence.

use nalgebra::Matrix3;

use super::adaptation::Adaptation;
use super::dispute::Hold;
use super::divergence::{Disagreement, DivergenceMonitor, GnssVelocityEnu};
use super::filter_state::FilterState;
use super::output::{EpochReport, SatRejection, Solution};
use super::update::{position_covariance, sigma_model, GnssFix};
use super::{initializer, Engine, Output, ResetReason};
use crate::config::{Config, Coupling};
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
    /// by the GNSS epoch `epoch`, tightly coupled, whose report is `report`); on
    /// divergence resets the filter and returns the reset.
    pub(super) fn monitor_gnss_epoch(
        &mut self,
        prior: &FilterState,
        epoch: &GnssEpoch,
        report: &EpochReport,
    ) -> Option<Output> {
        let disagreement = single_point_if_gated(epoch, report, prior, &self.config).map(|g| {
            Disagreement::of(
                prior,
                &g.position,
                &g.covariance_enu_m2,
                1.0,
                g.velocity.as_ref(),
                &self.config,
            )
        });
        self.monitor
            .check(report.t_s, disagreement.as_ref())
            .then(|| self.reset_diverged(report.t_s))
    }

    /// Resets the filter that the monitor found diverged at `t_s`, and returns the reset.
    pub(super) fn reset_diverged(&mut self, t_s: f64) -> Output {
        log::error!(
            "the filter diverged from GNSS at t = {t_s:.3} s (beyond {} σ for {} s): re-initializing",
            super::divergence::DISAGREE_SIGMA,
            super::divergence::MIN_SPAN_S
        );
        self.divergence_resets += 1;
        self.diverged_at_t_s = Some(t_s);
        // Nothing of the diverged state is kept (see Initializer::after_divergence).
        self.reset(t_s, ResetReason::DivergedFromGnss)
    }
}

/// The disagreement of `prior` with the receiver fix `fix` (loose coupling), under the
/// fix's covariance as the update will weigh it (`loose.fix_consistency`'s verdict on
/// the fixes before).
///
/// Choice: judged before the update, so that the fix that leaps is held already (see
/// [`super::dispute`]): taken as it was, it pulled the filter by the outlier bound's share
/// of the leap (akf_all, which inflates its covariance for it, 30 m vertically).
pub(super) fn fix_disagreement(
    prior: &FilterState,
    fix: &GnssFix,
    adaptation: &Adaptation,
    config: &Config,
) -> Disagreement {
    let velocity = fix.velocity_enu_mps.zip(fix.velocity_covariance_enu_m2_s2);
    Disagreement::of(
        prior,
        &fix.position,
        &position_covariance(fix, config),
        adaptation.fix[0].scale(),
        velocity.as_ref(),
        config,
    )
}

/// The solution of `state` as the engine publishes it: while the monitor holds a dispute
/// (a GNSS leap the IMU does not support: the GNSS or the filter is wrong, it cannot tell
/// which), its position covariance widened by the offset's outer product; while the fixes
/// are held back by the leap, by the covariance the held position is known to as well
/// (the filter takes each held fix as new, but the offset that moves them back is one);
/// while the noise judges (the filter's `adaptation`) find the measurements' claims too
/// small, its position and velocity covariances widened to at least what they found
/// beyond the claims ([`Adaptation::unclaimed_covariances`]).
///
/// Choice: at least, not added: a filter whose covariance already holds the excess (a
/// consumer IMU's, between epochs) needs no more. Added, the consumer-MEMS hour's tightly
/// coupled foliage, cautious already, went from 0.88 to 0.68 of its epochs inside the
/// 95 % bounds (ekf, seed 1, with the car); at least, 0.72, while the default drive's
/// foliage gains as much either way (docs/results.md).
pub(super) fn published_solution(
    state: &FilterState,
    monitor: &DivergenceMonitor,
    adaptation: &Adaptation,
    config: &Config,
) -> Solution {
    let mut solution = state.solution();
    let (position_enu_m2, velocity_enu_m2_s2) = adaptation.unclaimed_covariances();
    solution.widen_position_to_at_least(&position_enu_m2);
    solution.widen_velocity_to_at_least(&velocity_enu_m2_s2);
    if let Some(offset_enu_m) = monitor.dispute_offset_enu_m() {
        solution.widen_position_by(&offset_enu_m);
    }
    if let Some(Hold::MovedBack {
        covariance_enu_m2, ..
    }) = fix_hold(state.nav.t_s, monitor, config)
    {
        solution.widen_position_by_covariance(&covariance_enu_m2);
    }
    solution
}

/// The hold by a GNSS leap (see [`super::dispute`]) that applies at `t_s`: the monitor's,
/// loosely coupled, for at most `loose.leap_hold_s` after the leap (0: never).
pub(super) fn fix_hold(t_s: f64, monitor: &DivergenceMonitor, config: &Config) -> Option<Hold> {
    let hold_s = config.loose.leap_hold_s;
    let loose = config.filter.coupling == Coupling::Loose;
    monitor
        .hold()
        .filter(|h| loose && hold_s > 0.0 && t_s - h.since_t_s() <= hold_s)
}

/// A GNSS position independent of the filter, and its velocity when there is one.
struct IndependentGnss {
    position: Llh,
    covariance_enu_m2: Matrix3<f64>,
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
        velocity,
    })
}
