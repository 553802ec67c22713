//! GNSS side of the core: satellite observations as the engine receives them, and the
//! measurement models (predicted pseudo-range and rate, atmosphere, single-point solution).

pub mod atmosphere;
pub mod ephemeris;
pub mod epoch_build;
pub mod geometry;
pub mod ionosphere;
mod observation;
pub mod rinex_nav;
pub mod rinex_obs;
pub mod rinex_spp;
pub mod satellite_bounds;
pub mod spp;
pub mod time_scale;
pub mod ubx;

pub use observation::{CarrierPhase, Constellation, GnssEpoch, Klobuchar, SatId, SatObservation};
