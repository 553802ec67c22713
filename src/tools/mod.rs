//! The offline tools behind the `gnss_ins` command (simulate, convert, replay, compare,
//! spp, play, demo): they read and write files and drive the one engine the live node uses.

pub mod bag_inputs;
pub mod bag_run;
pub mod cli;
pub mod cli_play;
pub mod cli_real;
pub mod compare;
pub mod convert;
pub mod convert_bag;
pub mod imu_csv;
pub mod plots;
pub mod progress;
pub mod replay;
pub mod rtklib_pos;
pub mod scenario_inputs;
pub mod scoring;
pub mod session;
pub mod simulate;
pub mod spp_rinex;
pub mod spp_run;
pub mod start_blocker;
pub mod time_tag;
