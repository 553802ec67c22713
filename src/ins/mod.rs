//! Strapdown inertial navigation: the nominal navigation state, IMU samples, the
//! mechanization in the local-level ENU frame, and the error-state definition.

pub mod error_state;
pub mod mechanization;
mod nav_state;

pub use mechanization::{integrate, ImuIncrement, MechanizationError};
pub use nav_state::{ImuSample, NavState};
