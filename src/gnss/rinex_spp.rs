//! Single-point positioning of every epoch of a RINEX observation file with the
//! ephemerides of a RINEX navigation file: [`crate::gnss::rinex_obs`] builds the epochs,
//! [`crate::gnss::spp::solve_spp`] solves them.
//!
//! [`RinexSppOptions::rtklib_single`] reproduces RTKLIB 2.4.3 `rnx2rtkp` single-point
//! mode with broadcast ionosphere and Saastamoinen troposphere (see the reference
//! fixture `tests/data/rnx2rtkp_walk_1730/`), which is what those settings are:
//! - GPS only (`pos1-navsys = 1`), L1 C/A code, elevation mask 10°;
//! - Klobuchar with the navigation file's coefficients, or, when it has none, the fixed
//!   set RTKLIB falls back to ([`RTKLIB_DEFAULT_KLOBUCHAR`]);
//! - Saastamoinen with the 1 / sin E mapping ([`TropoMapping::Cosecant`]);
//! - no outlier exclusion (RAIM FDE off);
//! - each epoch starts from the previous epoch's solution, as RTKLIB's does.
//!
//! The weighting is left at ours ([`crate::gnss::spp::SigmaModel`]), not RTKLIB's
//! (variance 0.3² (1 + 1 / sin E) m² plus ephemeris, ionosphere and troposphere terms):
//! with four satellites, as walk_1730 has, the solution is exactly determined and the
//! weights do not enter it.

use nalgebra::Vector3;

use crate::gnss::atmosphere::{TropoMapping, TroposphereModel};
use crate::gnss::ephemeris::{EphemerisStore, GpsTime};
use crate::gnss::epoch_build::EpochStats;
use crate::gnss::rinex_nav::RinexNav;
use crate::gnss::rinex_obs::{build_rinex_epoch, RinexObs};
use crate::gnss::spp::{solve_spp, SppConfig, SppError, SppSolution};
use crate::gnss::{Constellation, Klobuchar};

/// The Klobuchar coefficients RTKLIB 2.4.3 uses when the navigation data carries none
/// (`ionmodel()` in rtkcmn.c, dated 2004-01-01 there): α in s, s/sc, s/sc², s/sc³;
/// β in s, s/sc, s/sc², s/sc³.
pub const RTKLIB_DEFAULT_KLOBUCHAR: Klobuchar = Klobuchar {
    alpha: [0.1118e-07, -0.7451e-08, -0.5961e-07, 0.1192e-06],
    beta: [0.1167e+06, -0.2294e+06, -0.1311e+06, 0.1049e+07],
};

/// The ionospheric model of the solutions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ionosphere {
    /// No ionospheric delay.
    Off,
    /// Klobuchar with the navigation file's coefficients, else with `fallback` (else
    /// none).
    Broadcast { fallback: Option<Klobuchar> },
}

/// Settings of [`solve_rinex_spp`].
#[derive(Debug, Clone, PartialEq)]
pub struct RinexSppOptions {
    /// Solver settings (mask, troposphere, weights, outlier test).
    pub spp: SppConfig,
    /// Constellations used; empty: all that have a usable signal and ephemeris.
    pub constellations: Vec<Constellation>,
    /// Ionospheric model.
    pub ionosphere: Ionosphere,
    /// Start each epoch from the previous epoch's solution (else from
    /// `spp.initial_position_ecef_m`).
    pub start_from_previous: bool,
}

impl RinexSppOptions {
    /// RTKLIB 2.4.3 `rnx2rtkp` single-point settings (see the module notes) with
    /// ionosphere and troposphere models as given.
    pub fn rtklib_single(ionosphere: Ionosphere, troposphere: TroposphereModel) -> Self {
        Self {
            spp: SppConfig {
                elevation_mask_rad: 10f64.to_radians(),
                outlier_threshold: None,
                troposphere,
                ..SppConfig::default()
            },
            constellations: vec![Constellation::Gps],
            ionosphere,
            start_from_previous: true,
        }
    }

    /// [`Self::rtklib_single`] with broadcast Klobuchar (RTKLIB's fallback coefficients)
    /// and Saastamoinen with the cosecant mapping: `rnx2rtkp` with
    /// `pos1-ionoopt = brdc`, `pos1-tropopt = saas`.
    pub fn rtklib_single_brdc_saas() -> Self {
        Self::rtklib_single(
            Ionosphere::Broadcast {
                fallback: Some(RTKLIB_DEFAULT_KLOBUCHAR),
            },
            TroposphereModel::Saastamoinen(TropoMapping::Cosecant),
        )
    }
}

/// One epoch's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct RinexSppEpoch {
    /// Receive time (GPST, receiver clock).
    pub time: GpsTime,
    /// How the epoch was built from the file.
    pub stats: EpochStats,
    /// Satellites of the chosen constellations offered to the solver.
    pub candidates: usize,
    /// The solution, or why there is none.
    pub solution: Result<SppSolution, SppError>,
}

/// Solves every observation epoch of `obs` with the ephemerides of `nav`.
pub fn solve_rinex_spp(
    obs: &RinexObs,
    nav: &RinexNav,
    options: &RinexSppOptions,
) -> Vec<RinexSppEpoch> {
    solve_rinex_spp_with_progress(obs, nav, options, |_| {})
}

/// [`solve_rinex_spp`], calling `progress` with the fraction of the epochs solved.
pub fn solve_rinex_spp_with_progress(
    obs: &RinexObs,
    nav: &RinexNav,
    options: &RinexSppOptions,
    mut progress: impl FnMut(f64),
) -> Vec<RinexSppEpoch> {
    let mut store = EphemerisStore::new();
    for eph in &nav.ephemerides {
        store.insert(*eph);
    }
    let klobuchar = match options.ionosphere {
        Ionosphere::Off => None,
        Ionosphere::Broadcast { fallback } => nav.klobuchar.or(fallback),
    };
    let mut previous: Option<Vector3<f64>> = None;
    let mut out = Vec::with_capacity(obs.epochs.len());
    for (k, epoch) in obs.epochs.iter().enumerate() {
        progress(k as f64 / obs.epochs.len() as f64);
        let mut built = build_rinex_epoch(epoch, &store, klobuchar);
        if !options.constellations.is_empty() {
            built
                .epoch
                .satellites
                .retain(|s| options.constellations.contains(&s.sat.constellation));
        }
        let mut config = options.spp;
        if options.start_from_previous && previous.is_some() {
            config.initial_position_ecef_m = previous;
        }
        let solution = solve_spp(&built.epoch, &config);
        if let Ok(s) = &solution {
            previous = Some(s.pos_ecef_m);
        }
        out.push(RinexSppEpoch {
            time: built.receive_time,
            stats: built.stats,
            candidates: built.epoch.satellites.len(),
            solution,
        });
    }
    out
}
