//! Runs several filter variants over the same input and tabulates their errors.

use serde::Serialize;

use crate::eval::ErrorSummary;

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

/// One row of a comparison by environment (a simulated segment, or a real reference's
/// solution quality such as `rtk_fixed` and `rtk_float`).
#[derive(Debug, Clone, Serialize)]
pub struct EnvironmentRow {
    pub filter: String,
    pub environment: String,
    pub epochs: usize,
    pub pos_rmse_horizontal_m: f64,
    pub pos_rmse_u_m: f64,
    pub pos_rmse_3d_m: f64,
    pub vel_rmse_3d_mps: f64,
}

impl EnvironmentRow {
    /// One row per environment of `by_environment`.
    pub fn rows(
        filter: &str,
        by_environment: &std::collections::BTreeMap<String, ErrorSummary>,
    ) -> Vec<Self> {
        by_environment
            .iter()
            .map(|(environment, s)| Self {
                filter: filter.to_owned(),
                environment: environment.clone(),
                epochs: s.epochs,
                pos_rmse_horizontal_m: s.pos_rmse_horizontal_m,
                pos_rmse_u_m: s.pos_rmse_u_m,
                pos_rmse_3d_m: s.pos_rmse_3d_m,
                vel_rmse_3d_mps: s.vel_rmse_3d_mps,
            })
            .collect()
    }
}

/// The comparison by environment as an aligned text table.
pub fn format_environment_table(rows: &[EnvironmentRow]) -> String {
    let mut out = format!(
        "{:<14} {:<14} {:>7} {:>8} {:>8} {:>8} {:>9}\n",
        "filter", "environment", "epochs", "horiz_m", "vert_m", "pos3d_m", "vel_mps"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<14} {:<14} {:>7} {:>8.3} {:>8.3} {:>8.3} {:>9.4}\n",
            r.filter,
            r.environment,
            r.epochs,
            r.pos_rmse_horizontal_m,
            r.pos_rmse_u_m,
            r.pos_rmse_3d_m,
            r.vel_rmse_3d_mps
        ));
    }
    out
}
