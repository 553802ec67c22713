//! # adaptive_gnss_ins
//!
//! A tightly-coupled IMU + raw GNSS (pseudo-range and pseudo-range rate) error-state
//! Kalman filter whose noise covariances adapt online, packaged as a ROS 2 Jazzy node.
//!
//! ## Frames and conventions
//! - Navigation frame n: local-level East-North-Up (REP-103; the ERMAKF paper's n-frame,
//!   V_x east, V_y north, V_z up).
//! - Body frame b: Forward-Left-Up (REP-103). IMU samples are specific force (REP-145).
//! - Attitude `q_nb` rotates body vectors into ENU: v^n = C_b^n v^b.
//! - Positions are geodetic WGS84 (radians, metres above the ellipsoid) inside; ECEF for
//!   the GNSS geometry; Odometry uses a local ENU tangent frame at a datum.
//! - SI units and radians everywhere inside; any other unit is in the name.
//!
//! ## Layers
//! The core (`earth`, `linalg`, `ins`, `gnss`, `filter`, `adaptive`, `engine`, `config`,
//! `eval`, `sim`) does no I/O, reads no clock and knows nothing of ROS; `ros` converts
//! messages, holds the adapter that turns decoded messages into engine inputs and engine
//! outputs into messages (for the node and `gnss_ins replay` alike), the u-blox driver
//! adapter, bags, and wires the node; `tools` are the offline tools, the only code that
//! reads and writes files besides the node's recorder. The README's layout section and
//! docs/architecture.md draw the same map.

pub mod adaptive;
pub mod config;
pub mod earth;
pub mod engine;
pub mod eval;
pub mod filter;
pub mod gnss;
pub mod ins;
pub mod linalg;
pub mod ros;
pub mod sim;
pub mod tools;
