//! The receiver side of the simulated carrier phase: each continuous track of a satellite
//! (received at consecutive GNSS epochs) carries one integer ambiguity, drawn when the
//! track starts, a lock time counted from its start and the loss-of-lock flag at its first
//! epoch, as a receiver reports them.

use std::collections::btree_map::Entry;
use std::collections::BTreeMap;

use rand::RngExt;

use crate::gnss::{CarrierPhase, SatId};
use crate::sim::sat_errors::{stream_rng, StreamPurpose};

/// Largest |ambiguity| drawn (cycles): any integer does, and a receiver's initial phase is
/// arbitrary.
const MAX_AMBIGUITY_CYCLES: f64 = 1.0e5;

#[derive(Debug, Clone, Copy)]
struct Track {
    start_t_s: f64,
    last_epoch: u64,
    ambiguity_cycles: f64,
}

/// The carrier-phase tracks of the satellites.
#[derive(Debug, Clone)]
pub struct CarrierTracks {
    seed: u64,
    tracks: BTreeMap<SatId, Track>,
}

impl CarrierTracks {
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            tracks: BTreeMap::new(),
        }
    }

    /// The phase the receiver reports at GNSS epoch `epoch_index` (time `t_s`) for the
    /// noise-free phase `phase` of `sat` with the error `error_m` added and the track's
    /// ambiguity. A satellite not received at the previous epoch starts a new track.
    pub fn receive(
        &mut self,
        sat: SatId,
        epoch_index: u64,
        t_s: f64,
        phase: CarrierPhase,
        error_m: f64,
    ) -> CarrierPhase {
        let seed = self.seed;
        let (track, continues) = match self.tracks.entry(sat) {
            Entry::Occupied(e) if e.get().last_epoch + 1 == epoch_index => (e.into_mut(), true),
            Entry::Occupied(mut e) => {
                e.insert(start_track(seed, sat, epoch_index, t_s));
                (e.into_mut(), false)
            }
            Entry::Vacant(e) => (e.insert(start_track(seed, sat, epoch_index, t_s)), false),
        };
        track.last_epoch = epoch_index;
        let wavelength_m = phase.wavelength_m.unwrap_or(f64::NAN);
        CarrierPhase {
            cycles: phase.cycles + error_m / wavelength_m + track.ambiguity_cycles,
            lock_time_s: Some(t_s - track.start_t_s),
            loss_of_lock: !continues,
            ..phase
        }
    }
}

/// A track of `sat` starting at epoch `epoch_index` (time `t_s`), its ambiguity drawn from
/// the stream of (seed, satellite, epoch).
fn start_track(seed: u64, sat: SatId, epoch_index: u64, t_s: f64) -> Track {
    let mut rng = stream_rng(
        seed,
        StreamPurpose::CarrierAmbiguity,
        Some(sat),
        epoch_index,
    );
    let u: f64 = rng.random();
    Track {
        start_t_s: t_s,
        last_epoch: epoch_index,
        ambiguity_cycles: ((2.0 * u - 1.0) * MAX_AMBIGUITY_CYCLES).round(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::Constellation;

    #[test]
    fn a_track_keeps_its_ambiguity_until_the_satellite_is_missed() {
        let sat = SatId {
            constellation: Constellation::Gps,
            prn: 4,
        };
        let phase = |cycles| CarrierPhase {
            cycles,
            wavelength_m: Some(0.2),
            sigma_cycles: None,
            lock_time_s: None,
            loss_of_lock: false,
            half_cycle_unresolved: false,
        };
        let mut tracks = CarrierTracks::new(3);
        let first = tracks.receive(sat, 10, 10.0, phase(100.0), 0.0);
        let second = tracks.receive(sat, 11, 11.0, phase(150.0), 0.02);
        assert!(first.loss_of_lock && !second.loss_of_lock);
        assert_eq!(first.cycles.fract(), 0.0);
        assert!((second.cycles - first.cycles - 50.1).abs() < 1e-6);
        assert_eq!(
            (first.lock_time_s, second.lock_time_s),
            (Some(0.0), Some(1.0))
        );
        // Missed at epoch 12: a new track, a new ambiguity.
        let third = tracks.receive(sat, 13, 13.0, phase(250.0), 0.0);
        assert!(third.loss_of_lock);
        assert_eq!(third.lock_time_s, Some(0.0));
        assert_ne!(third.cycles - 250.0, first.cycles - 100.0);
    }
}
