//! Runs several filter variants over the same input and tabulates their errors.

use serde::Serialize;

use crate::config::Config;
use crate::eval::ErrorSummary;

use super::session::{Session, SessionInput, SessionReport};

/// One row of a comparison.
#[derive(Debug, Clone, Serialize)]
pub struct ComparisonRow {
    pub filter: String,
    pub pos_rmse_3d_m: f64,
    pub pos_rmse_e_m: f64,
    pub pos_rmse_n_m: f64,
    pub pos_rmse_u_m: f64,
    pub vel_rmse_3d_mps: f64,
    pub att_rmse_roll_deg: f64,
    pub att_rmse_pitch_deg: f64,
    pub att_rmse_yaw_deg: f64,
    pub nees_mean: f64,
    pub runtime_s: f64,
}

impl ComparisonRow {
    pub fn new(filter: &str, s: &ErrorSummary, runtime_s: f64) -> Self {
        Self {
            filter: filter.to_owned(),
            pos_rmse_3d_m: s.pos_rmse_3d_m,
            pos_rmse_e_m: s.pos_rmse_e_m,
            pos_rmse_n_m: s.pos_rmse_n_m,
            pos_rmse_u_m: s.pos_rmse_u_m,
            vel_rmse_3d_mps: s.vel_rmse_3d_mps,
            att_rmse_roll_deg: s.att_rmse_roll_deg,
            att_rmse_pitch_deg: s.att_rmse_pitch_deg,
            att_rmse_yaw_deg: s.att_rmse_yaw_deg,
            nees_mean: s.nees_mean,
            runtime_s,
        }
    }
}

/// Runs `config` over `inputs` (a fresh stream each call) and returns the session report
/// and the run time of the engine (s), measured by the caller's clock `now`.
pub fn run_one<I, C>(
    config: Config,
    inputs: I,
    score_interval_s: f64,
    mut now: C,
) -> (SessionReport, f64)
where
    I: IntoIterator<Item = SessionInput>,
    C: FnMut() -> f64,
{
    let start = now();
    let mut session = Session::new(config, score_interval_s, None);
    for input in inputs {
        session.push(input);
    }
    let runtime = now() - start;
    (session.finish(), runtime)
}

/// The comparison as an aligned text table.
pub fn format_table(rows: &[ComparisonRow]) -> String {
    let mut out = format!(
        "{:<14} {:>8} {:>7} {:>7} {:>7} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8}\n",
        "filter",
        "pos3d_m",
        "E_m",
        "N_m",
        "U_m",
        "vel_mps",
        "roll_deg",
        "pitch_dg",
        "yaw_deg",
        "NEES",
        "time_s"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<14} {:>8.3} {:>7.3} {:>7.3} {:>7.3} {:>9.4} {:>8.4} {:>8.4} {:>8.4} {:>8.2} {:>8.3}\n",
            r.filter,
            r.pos_rmse_3d_m,
            r.pos_rmse_e_m,
            r.pos_rmse_n_m,
            r.pos_rmse_u_m,
            r.vel_rmse_3d_mps,
            r.att_rmse_roll_deg,
            r.att_rmse_pitch_deg,
            r.att_rmse_yaw_deg,
            r.nees_mean,
            r.runtime_s
        ));
    }
    out
}

/// The comparison as CSV with a header line.
pub fn format_csv(rows: &[ComparisonRow]) -> String {
    let mut out = String::from(
        "filter,pos_rmse_3d_m,pos_rmse_e_m,pos_rmse_n_m,pos_rmse_u_m,vel_rmse_3d_mps,\
         att_rmse_roll_deg,att_rmse_pitch_deg,att_rmse_yaw_deg,nees_mean,runtime_s\n",
    );
    for r in rows {
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{}\n",
            r.filter,
            r.pos_rmse_3d_m,
            r.pos_rmse_e_m,
            r.pos_rmse_n_m,
            r.pos_rmse_u_m,
            r.vel_rmse_3d_mps,
            r.att_rmse_roll_deg,
            r.att_rmse_pitch_deg,
            r.att_rmse_yaw_deg,
            r.nees_mean,
            r.runtime_s
        ));
    }
    out
}
