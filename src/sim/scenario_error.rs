//! Why a scenario could not be built or run.

use thiserror::Error;

use crate::gnss::geometry::GnssModelError;
use crate::sim::constellation::SimError;
use crate::sim::{ImuErrorModelError, TrajectoryError};

/// Why a scenario could not be built or run.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScenarioError {
    /// The YAML does not parse into a spec.
    #[error("scenario YAML: {message}")]
    Yaml { message: String },
    /// No built-in scenario of that name.
    #[error("no built-in scenario '{name}' (known: {known})")]
    UnknownBuiltin { name: String, known: String },
    /// A spec value is out of range.
    #[error("invalid scenario field {field}: {reason}")]
    InvalidSpec { field: String, reason: &'static str },
    /// The trajectory spec was refused.
    #[error("scenario trajectory: {0}")]
    Trajectory(#[from] TrajectoryError),
    /// The IMU error spec was refused.
    #[error("scenario IMU errors: {0}")]
    ImuErrors(#[from] ImuErrorModelError),
    /// The observation simulator failed at an epoch.
    #[error("GNSS simulation at t = {t_s} s: {source}")]
    Simulation { t_s: f64, source: SimError },
    /// The geometry of a satellite could not be computed at an epoch.
    #[error("satellite geometry at t = {t_s} s: {source}")]
    Geometry { t_s: f64, source: GnssModelError },
    /// The antenna position has no geodetic coordinates.
    #[error("antenna position undefined at t = {t_s} s")]
    AntennaPosition { t_s: f64 },
}
