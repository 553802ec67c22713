//! Runs several filter configurations over the same bag, in parallel, and tabulates their
//! errors.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use serde::Serialize;

use crate::config::{Config, FilterVariant};
use crate::eval::ErrorSummary;

use super::bag_run::BagRunner;
use super::progress;
use super::scoring::SessionReport;

/// Scoring interval of the comparisons (s): every reference sample of a simulated bag
/// (10 Hz).
const SCORE_INTERVAL_S: f64 = 0.0;

/// A configuration of a comparison with its name in the table.
#[derive(Debug, Clone)]
pub struct NamedConfig {
    pub name: String,
    pub config: Config,
}

impl NamedConfig {
    /// `base` with `filter.variant` set to `variant`, named after the variant.
    pub fn of_variant(base: &Config, variant: FilterVariant) -> Self {
        let mut config = base.clone();
        config.filter.variant = variant;
        Self {
            name: variant.as_str().to_owned(),
            config,
        }
    }
}

/// Runs every configuration over `bag` (scored against its `truth_topic`) and returns one
/// row and the scoring report per configuration, in their order.
///
/// Choice: one worker thread per core (`std::thread::available_parallelism`), each taking
/// the next configuration and streaming the bag itself through the ROS adapter, as
/// `replay` does: memory stays that of one replay per worker, and no worker waits for
/// another's input. Each row's `runtime_s` is the wall time of its own run. Progress goes
/// to stderr ([`progress::Progress`]): a live line on a terminal; otherwise a line every
/// few seconds and one per finished configuration.
pub fn compare_bag(
    bag: &Path,
    configs: &[NamedConfig],
    truth_topic: &str,
) -> Result<Vec<(ComparisonRow, SessionReport)>, String> {
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(configs.len());
    let next = AtomicUsize::new(0);
    let progress = Progress::new(configs);
    eprintln!(
        "compare: {} configurations over {} on {workers} threads",
        configs.len(),
        bag.display()
    );
    let results: Mutex<Vec<Option<RunResult>>> = Mutex::new(vec![None; configs.len()]);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(named) = configs.get(k) else {
                    break;
                };
                let result = run_one(bag, named, truth_topic, |f| progress.update(k, f));
                progress.finished(k);
                if let Ok(mut all) = results.lock() {
                    all[k] = Some(result);
                }
            });
        }
    });
    progress.end();
    let results = results.into_inner().map_err(|e| e.to_string())?;
    results
        .into_iter()
        .zip(configs)
        .map(|(r, named)| r.unwrap_or_else(|| Err(format!("{}: the run did not end", named.name))))
        .collect()
}

/// The row and the scoring report of one configuration, or why its run failed.
type RunResult = Result<(ComparisonRow, SessionReport), String>;

/// One configuration over the bag.
fn run_one(
    bag: &Path,
    named: &NamedConfig,
    truth_topic: &str,
    progress: impl FnMut(f64),
) -> RunResult {
    let start = Instant::now();
    let error = |e: &dyn std::fmt::Display| format!("{}: {e}", named.name);
    let runner = BagRunner::scoring_only(
        bag,
        &named.config,
        Some(truth_topic.to_owned()),
        SCORE_INTERVAL_S,
    )
    .map_err(|e| error(&e))?;
    let run = runner
        .run(|_| Ok::<(), std::convert::Infallible>(()), progress)
        .map_err(|e| error(&e))?;
    let runtime = start.elapsed().as_secs_f64();
    let summary = run.report.summary(f64::NEG_INFINITY);
    let row = ComparisonRow::new(&named.name, &summary, run.divergence_resets, runtime);
    Ok((row, run.report))
}

/// The progress of a comparison's runs, shown on stderr.
struct Progress<'a> {
    configs: &'a [NamedConfig],
    /// Fraction done of each run; None before it starts.
    done: Mutex<Vec<Option<f64>>>,
    finished: AtomicUsize,
    line: progress::Progress,
}

impl<'a> Progress<'a> {
    fn new(configs: &'a [NamedConfig]) -> Self {
        Self {
            configs,
            done: Mutex::new(vec![None; configs.len()]),
            finished: AtomicUsize::new(0),
            line: progress::Progress::new(),
        }
    }

    fn update(&self, k: usize, fraction: f64) {
        let Ok(mut done) = self.done.lock() else {
            return;
        };
        done[k] = Some(fraction);
        self.line.show(|| {
            let running: Vec<String> = done
                .iter()
                .zip(self.configs)
                .filter(|(f, _)| f.is_some_and(|f| f < 1.0))
                .map(|(f, c)| format!("{} {:.0} %", c.name, f.unwrap_or(0.0) * 100.0))
                .collect();
            let finished = self.finished.load(Ordering::Relaxed);
            format!(
                "compare: {finished}/{} done; {}",
                self.configs.len(),
                running.join(", ")
            )
        });
    }

    fn finished(&self, k: usize) {
        let n = self.finished.fetch_add(1, Ordering::Relaxed) + 1;
        if !self.line.is_live() {
            eprintln!(
                "compare: {} done ({n}/{})",
                self.configs[k].name,
                self.configs.len()
            );
        }
    }

    fn end(&self) {
        self.line.end();
    }
}

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
    /// Resets by the divergence monitor over the run.
    pub divergence_resets: u64,
    pub runtime_s: f64,
}

impl ComparisonRow {
    pub fn new(filter: &str, s: &ErrorSummary, divergence_resets: u64, runtime_s: f64) -> Self {
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
            divergence_resets,
            runtime_s,
        }
    }
}

/// A numeric column of [`ComparisonRow`]: its CSV name, and its table header, width and
/// decimals.
struct Column {
    csv: &'static str,
    header: &'static str,
    width: usize,
    decimals: usize,
}

const fn column(csv: &'static str, header: &'static str, width: usize, decimals: usize) -> Column {
    Column {
        csv,
        header,
        width,
        decimals,
    }
}

/// The numeric columns after the filter name, in the order of [`ComparisonRow::values`].
const COLUMNS: [Column; 11] = [
    column("pos_rmse_3d_m", "pos3d_m", 8, 3),
    column("pos_rmse_e_m", "E_m", 7, 3),
    column("pos_rmse_n_m", "N_m", 7, 3),
    column("pos_rmse_u_m", "U_m", 7, 3),
    column("vel_rmse_3d_mps", "vel_mps", 9, 4),
    column("att_rmse_roll_deg", "roll_deg", 8, 4),
    column("att_rmse_pitch_deg", "pitch_dg", 8, 4),
    column("att_rmse_yaw_deg", "yaw_deg", 8, 4),
    column("nees_mean", "NEES", 8, 2),
    column("divergence_resets", "resets", 6, 0),
    column("runtime_s", "time_s", 8, 3),
];

/// Width of the table's filter column.
const FILTER_WIDTH: usize = 14;

impl ComparisonRow {
    /// The row's numbers in the order of [`COLUMNS`].
    fn values(&self) -> [f64; 11] {
        [
            self.pos_rmse_3d_m,
            self.pos_rmse_e_m,
            self.pos_rmse_n_m,
            self.pos_rmse_u_m,
            self.vel_rmse_3d_mps,
            self.att_rmse_roll_deg,
            self.att_rmse_pitch_deg,
            self.att_rmse_yaw_deg,
            self.nees_mean,
            self.divergence_resets as f64,
            self.runtime_s,
        ]
    }
}

/// The comparison as an aligned text table.
pub fn format_table(rows: &[ComparisonRow]) -> String {
    let mut out = format!("{:<FILTER_WIDTH$}", "filter");
    for c in &COLUMNS {
        out.push_str(&format!(" {:>w$}", c.header, w = c.width));
    }
    out.push('\n');
    for r in rows {
        out.push_str(&format!("{:<FILTER_WIDTH$}", r.filter));
        for (c, value) in COLUMNS.iter().zip(r.values()) {
            out.push_str(&format!(" {value:>w$.d$}", w = c.width, d = c.decimals));
        }
        out.push('\n');
    }
    out
}

/// The comparison as CSV with a header line.
pub fn format_csv(rows: &[ComparisonRow]) -> String {
    let mut out = String::from("filter");
    for c in &COLUMNS {
        out.push(',');
        out.push_str(c.csv);
    }
    out.push('\n');
    for r in rows {
        out.push_str(&r.filter);
        for value in r.values() {
            out.push_str(&format!(",{value}"));
        }
        out.push('\n');
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
    /// Horizontal RMSE after removing the mean offset over the environment's epochs.
    pub pos_rmse_horizontal_offset_removed_m: f64,
    pub pos_rmse_u_m: f64,
    pub pos_rmse_3d_m: f64,
    pub vel_rmse_3d_mps: f64,
    /// Fraction of the epochs whose NEES lies inside its 95 % χ² bounds.
    pub nees_in_bounds_95: f64,
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
                pos_rmse_horizontal_offset_removed_m: s.pos_rmse_horizontal_offset_removed_m,
                pos_rmse_u_m: s.pos_rmse_u_m,
                pos_rmse_3d_m: s.pos_rmse_3d_m,
                vel_rmse_3d_mps: s.vel_rmse_3d_mps,
                nees_in_bounds_95: s.nees_in_bounds_95,
            })
            .collect()
    }
}

/// The comparison by environment as an aligned text table.
pub fn format_environment_table(rows: &[EnvironmentRow]) -> String {
    let mut out = format!(
        "{:<14} {:<14} {:>7} {:>8} {:>12} {:>8} {:>8} {:>9} {:>8}\n",
        "filter",
        "environment",
        "epochs",
        "horiz_m",
        "horiz_demean",
        "vert_m",
        "pos3d_m",
        "vel_mps",
        "nees_95"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<14} {:<14} {:>7} {:>8.3} {:>12.3} {:>8.3} {:>8.3} {:>9.4} {:>8.3}\n",
            r.filter,
            r.environment,
            r.epochs,
            r.pos_rmse_horizontal_m,
            r.pos_rmse_horizontal_offset_removed_m,
            r.pos_rmse_u_m,
            r.pos_rmse_3d_m,
            r.vel_rmse_3d_mps,
            r.nees_in_bounds_95
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row() -> ComparisonRow {
        ComparisonRow {
            filter: "ermakf".to_owned(),
            pos_rmse_3d_m: 1.25,
            pos_rmse_e_m: 0.5,
            pos_rmse_n_m: 0.75,
            pos_rmse_u_m: 0.875,
            vel_rmse_3d_mps: 0.0625,
            att_rmse_roll_deg: 0.03125,
            att_rmse_pitch_deg: 0.015625,
            att_rmse_yaw_deg: 0.5625,
            nees_mean: 2.5,
            divergence_resets: 3,
            runtime_s: 3.375,
        }
    }

    #[test]
    fn csv_names_every_field_and_writes_it_exactly() {
        let text = format_csv(&[row()]);
        let lines: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
        assert_eq!(lines.len(), 2);
        let (header, values) = (&lines[0], &lines[1]);
        assert_eq!(header[..2], ["filter", "pos_rmse_3d_m"]);
        assert_eq!(header.last(), Some(&"runtime_s"));
        assert_eq!(values[0], "ermakf");
        let numbers: Vec<f64> = values[1..].iter().map(|v| v.parse().unwrap()).collect();
        assert_eq!(numbers, row().values());
        assert_eq!(numbers[8], 2.5, "nees_mean under its own name");
        assert_eq!(header[9], "nees_mean");
        assert_eq!((header[10], values[10]), ("divergence_resets", "3"));
    }

    #[test]
    fn table_rows_line_up_with_the_header() {
        let text = format_table(&[row(), row()]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines.iter().all(|l| l.len() == lines[0].len()), "{text}");
        assert!(lines[1].starts_with("ermakf "));
        assert!(lines[1].ends_with("    2.50      3    3.375"), "{text}");
    }
}
