//! The offline tools behind the `gnss_ins` command (simulate, replay, compare, demo): they
//! read and write files and drive the one engine the live node uses.

pub mod bag_inputs;
pub mod cli;
pub mod compare;
pub mod plots;
pub mod replay;
pub mod scenario_inputs;
pub mod session;
pub mod simulate;
pub mod spp_rinex;
