//! The C/N0 deficit: a satellite received well below its own recent C/N0 comes through
//! an obstruction (a canopy, a diffracting edge), and its errors grow and correlate at
//! once, epochs before [`super::error_correlation`]'s tests can see it in the residuals.
//!
//! Per satellite the reference is its recent unobstructed C/N0: the largest seen, decaying
//! by [`REFERENCE_DECAY_DB_PER_S`] (a setting satellite's C/N0 falls far slower; a canopy
//! drops it at once). The deficit Δ = reference − C/N0 beyond [`DEAD_BAND_DB`] sets a
//! floor under the channel's inflation, 10^(α Δ / 10) with α = [`DEFICIT_EXPONENT`]: the
//! SIGMA-Δ weighting (Brunner, Hartinger and Troller, GPS Solutions 1999), which weighs
//! diffracted signals by their C/N0 deficit against an unobstructed template. Here the
//! template is each satellite's own recent level, learnt online, since a receiver and
//! antenna of any make must be served without a calibration.
//!
//! Choices (measured on the default drive's seeds 1–3, the consumer hour and walk_0827;
//! docs/results.md, "The C/N0 deficit"):
//! - α = 2, SIGMA-Δ's; α = 1 (the thermal noise's own scaling) weighed the foliage's
//!   multipath too little (the default drive's open sky 0.87–0.92 inside its bounds,
//!   against 0.90–0.98), and walk_0827's filters less well (EKF 0.457 against 0.406 m).
//! - A dead band of 3 dB: without it the default drive's filters turned over-cautious
//!   (seed 3's open sky 0.59–0.73 inside, mean NEES 4–5) and walk_0827's eiakf fell to
//!   1.106 m, the reported C/N0 of a real receiver moving by a dB or two from epoch to
//!   epoch.
//! - The reference restarts after a gap longer than `adaptive.max_epoch_gap_s` (the
//!   satellite is seen anew) and after a filter reset.

use std::collections::BTreeMap;

use crate::gnss::SatId;

/// Exponent α of the deficit's weighting (see the module's choices).
pub const DEFICIT_EXPONENT: f64 = 2.0;

/// The deficit below which a C/N0 is taken as unobstructed (dB; see the module's choices).
pub const DEAD_BAND_DB: f64 = 3.0;

/// How fast the reference forgets its largest C/N0 (dB/s). Choice: 0.02 dB/s, 1.2 dB per
/// minute, over ten times a satellite's own change with elevation (some 15 dB from the
/// horizon to the zenith over hours), so that an 8-dB canopy stays seen for minutes.
pub const REFERENCE_DECAY_DB_PER_S: f64 = 0.02;

/// The satellites' C/N0 references.
#[derive(Debug, Clone, Default)]
pub struct Cn0Deficit {
    /// Per satellite: (time, reference C/N0 at that time, dB-Hz).
    references: BTreeMap<SatId, (f64, f64)>,
}

impl Cn0Deficit {
    /// The floor of `sat`'s inflation for a C/N0 of `cn0_dbhz` at `t_s` (1 without a
    /// reference no older than `max_gap_s`), at most `max_inflation`.
    pub fn floor(
        &self,
        sat: SatId,
        t_s: f64,
        cn0_dbhz: Option<f64>,
        max_gap_s: f64,
        max_inflation: f64,
    ) -> f64 {
        let (Some(cn0), Some(&(t, reference))) = (cn0_dbhz, self.references.get(&sat)) else {
            return 1.0;
        };
        if !cn0.is_finite() || t_s < t || t_s - t > max_gap_s {
            return 1.0;
        }
        let reference_now = reference - REFERENCE_DECAY_DB_PER_S * (t_s - t);
        let deficit_db = (reference_now - cn0 - DEAD_BAND_DB).max(0.0);
        10f64
            .powf(DEFICIT_EXPONENT * deficit_db / 10.0)
            .min(max_inflation)
    }

    /// Takes `sat`'s C/N0 at `t_s` into its reference (once per epoch: a later call at
    /// the same time changes nothing).
    pub fn push(&mut self, sat: SatId, t_s: f64, cn0_dbhz: Option<f64>, max_gap_s: f64) {
        let Some(cn0) = cn0_dbhz.filter(|c| c.is_finite()) else {
            return;
        };
        let entry = self.references.entry(sat).or_insert((t_s, cn0));
        let (t, reference) = *entry;
        if t_s - t > max_gap_s {
            *entry = (t_s, cn0);
        } else if t_s > t {
            *entry = (
                t_s,
                (reference - REFERENCE_DECAY_DB_PER_S * (t_s - t)).max(cn0),
            );
        }
    }

    /// Forgets the satellites not seen since `t_s − max_gap_s`.
    pub fn forget_older_than(&mut self, t_s: f64, max_gap_s: f64) {
        self.references.retain(|_, (t, _)| t_s - *t <= max_gap_s);
    }

    /// Forgets every satellite.
    pub fn clear(&mut self) {
        self.references.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::Constellation;

    const GAP_S: f64 = 2.0;
    const CAP: f64 = 25.0;

    fn sat() -> SatId {
        SatId {
            constellation: Constellation::Gps,
            prn: 7,
        }
    }

    /// A satellite at 45 dB-Hz for a minute, then `drop_db` lower at t = 60 s: the
    /// floor at 60 s.
    fn floor_after_a_drop(drop_db: f64) -> f64 {
        let mut deficit = Cn0Deficit::default();
        for k in 0..60 {
            deficit.push(sat(), k as f64, Some(45.0), GAP_S);
        }
        deficit.floor(sat(), 60.0, Some(45.0 - drop_db), GAP_S, CAP)
    }

    #[test]
    fn a_drop_within_the_dead_band_weighs_nothing() {
        assert_eq!(floor_after_a_drop(0.0), 1.0);
        assert_eq!(floor_after_a_drop(2.9), 1.0);
    }

    #[test]
    fn a_canopy_drop_is_weighed_at_once_as_sigma_delta_has_it() {
        // 8 dB below a reference that decayed 0.02 dB over the last second: 4.98 dB
        // beyond the dead band, 10^(2 · 4.98 / 10).
        let floor = floor_after_a_drop(8.0);
        assert!((floor - 10f64.powf(0.996)).abs() < 1e-9, "{floor}");
        assert_eq!(floor_after_a_drop(30.0), CAP);
    }

    #[test]
    fn the_reference_follows_a_slow_fall_and_forgets_a_long_canopy() {
        let mut deficit = Cn0Deficit::default();
        // Setting slowly: 0.005 dB/s, a quarter of the decay, is no deficit.
        for k in 0..600 {
            deficit.push(sat(), k as f64, Some(45.0 - 0.005 * k as f64), GAP_S);
        }
        assert_eq!(deficit.floor(sat(), 600.0, Some(42.0), GAP_S, CAP), 1.0);
        // Under a canopy 8 dB down for ten minutes the reference decays onto it.
        for k in 600..1200 {
            deficit.push(sat(), k as f64, Some(34.0), GAP_S);
        }
        assert_eq!(deficit.floor(sat(), 1200.0, Some(34.0), GAP_S, CAP), 1.0);
    }

    #[test]
    fn a_gap_or_a_missing_c_n0_gives_no_floor() {
        let mut deficit = Cn0Deficit::default();
        deficit.push(sat(), 0.0, Some(45.0), GAP_S);
        assert_eq!(deficit.floor(sat(), 5.0, Some(30.0), GAP_S, CAP), 1.0);
        assert_eq!(deficit.floor(sat(), 1.0, None, GAP_S, CAP), 1.0);
        assert_eq!(deficit.floor(sat(), 1.0, Some(f64::NAN), GAP_S, CAP), 1.0);
        deficit.push(sat(), 5.0, Some(30.0), GAP_S);
        assert_eq!(deficit.floor(sat(), 6.0, Some(30.0), GAP_S, CAP), 1.0);
    }
}
