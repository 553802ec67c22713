//! The `gnss_ins` subcommands: argument definitions and what each one does.

use std::path::{Path, PathBuf};

use clap::{Subcommand, ValueEnum};

use crate::config::{Config, Coupling, FilterVariant};
use crate::ros::adapter::{TIME_JUMP_BACK_S, TIME_JUMP_CONFIRM_SAMPLES};
use crate::ros::bag::ChunkCompression;
use crate::ros::node::params::{node_params_from_files, NodeParams};
use crate::sim::{Scenario, ScenarioSpec};

use super::bag_run::BagRun;
use super::cli_play::{self, PlayArgs};
use super::cli_real::{self, ConvertArgs, SppArgs, SppRinexArgs};
use super::compare::{
    compare_bag, format_csv, format_environment_table, format_table, ComparisonRow, EnvironmentRow,
    NamedConfig,
};
use super::plots::{write_plots, FilterRun};
use super::progress::Progress;
use super::replay::{self, ReplayOptions, TruthSource};
use super::scoring::SessionReport;
use super::simulate::{self, TRUTH_TOPIC};
use super::start_blocker::start_blocker;

/// Scoring interval of a replay (s): every solution that has a reference.
const SCORE_INTERVAL_S: f64 = 0.0;

#[derive(Subcommand)]
pub enum Command {
    /// Simulate a scenario into a rosbag2 MCAP bag (deterministic from the seed).
    Simulate {
        /// A built-in scenario name (default, open_sky, static) or a scenario YAML file.
        #[arg(long, default_value = "default")]
        scenario: String,
        /// Seed of every random draw: the same seed gives the same bag.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output bag (.mcap).
        #[arg(long)]
        out: PathBuf,
        /// Also write the receiver's velocities on /gnss/velocity
        /// (geometry_msgs/TwistWithCovarianceStamped, paired with /gnss/fix by stamp).
        #[arg(long)]
        velocity: bool,
    },
    /// Stream a bag through the engine; write the solution; score it against a reference.
    Replay {
        /// Input bag: an .mcap file or a rosbag2 directory holding one.
        bag: PathBuf,
        /// Parameter file (ROS 2 params layout, as the node reads it); repeat it to load
        /// a preset over the manual, e.g. --params params/defaults.yaml --params
        /// params/ermakf.yaml (a later value wins). Defaults when absent.
        #[arg(long)]
        params: Vec<PathBuf>,
        /// Output bag with /odometry, /fix/filtered, /noise_estimates and, with publish_tf in
        /// a --params file, /tf as the node publishes it (tf_mode map_to_odom reads the
        /// base controller's odom -> base_link from the bag's /tf).
        #[arg(long)]
        out: Option<PathBuf>,
        /// zstd-compress the output bag's chunks: half the size, for about 1.5 s more CPU
        /// per hour of 200 Hz solutions (rosbag2 and the `rosbags` package read it).
        #[arg(long, requires = "out")]
        compress: bool,
        /// Output CSV of the solutions.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Reference as nav_msgs/Odometry on this topic of the bag.
        #[arg(long, conflicts_with = "truth_csv")]
        truth_topic: Option<String>,
        /// Reference CSV: unix time s, lat deg, lon deg, ellipsoidal height m
        /// [, vE vN vU m/s [, roll pitch yaw deg]].
        #[arg(long)]
        truth_csv: Option<PathBuf>,
    },
    /// Run several filter variants over one bag and tabulate their errors.
    Compare {
        /// Input bag: an .mcap file or a rosbag2 directory holding one.
        bag: PathBuf,
        /// Comma-separated variants (e.g. ekf,ermakf); all when absent.
        #[arg(long, value_delimiter = ',')]
        filters: Vec<String>,
        /// Folder of parameter files named VARIANT.yaml, each loaded after the --params
        /// files for its variant (e.g. --params-dir params: the presets).
        #[arg(long)]
        params_dir: Option<PathBuf>,
        /// Parameter file (e.g. a sensor description) for every variant, its
        /// filter.variant replaced by each variant in turn (unless its VARIANT.yaml of
        /// --params-dir sets it); repeatable, a later value wins.
        #[arg(long)]
        params: Vec<PathBuf>,
        /// Also tabulate the errors by environment (simulated segments, or the reference's
        /// solution quality in a converted bag: rtk_fixed, rtk_float).
        #[arg(long)]
        by_environment: bool,
        /// Score each variant only from this many seconds after its first scored solution
        /// (its start), leaving its convergence out of the tables (not of the figures).
        #[arg(long, default_value_t = 0.0)]
        scored_after_start_s: f64,
        /// How the results are printed: an aligned table, JSON or CSV.
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        /// Folder for PNG and SVG figures of the errors over time and of the estimated
        /// against the true noise σ.
        #[arg(long)]
        plots: Option<PathBuf>,
    },
    /// Convert a u-blox UBX log and an IMU CSV (and a reference), or a robot's bag with
    /// the u-blox drivers' raw GNSS and its IMU, into a bag.
    Convert(Box<ConvertArgs>),
    /// Single-point solutions of every epoch of a bag or UBX log, scored against its
    /// reference.
    Spp(SppArgs),
    /// Simulate the default scenario into a temporary folder and compare every variant.
    Demo {
        /// Seed of the simulated scenario.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Publish a bag onto DDS (domain `ROS_DOMAIN_ID`) with its recorded topic names and
    /// types, paced by its log times, like `ros2 bag play`.
    Play(PlayArgs),
    /// Single-point positions of every epoch of a RINEX 3 observation file with RTKLIB
    /// rnx2rtkp's single-point settings (GPS L1 C/A, 10° mask, Klobuchar, Saastamoinen).
    SppRinex(SppRinexArgs),
}

#[derive(Clone, Copy, ValueEnum)]
pub enum Format {
    Table,
    Json,
    Csv,
}

/// Runs one subcommand.
pub fn run(command: Command) -> Result<(), String> {
    match command {
        Command::Simulate {
            scenario,
            seed,
            out,
            velocity,
        } => {
            let scenario = load_scenario(&scenario, seed)?;
            let options = simulate::SimulateOptions { velocity };
            let progress = Progress::new();
            let summary = simulate::simulate_with_progress(&scenario, &out, options, |f| {
                progress.fraction("simulate", f)
            });
            progress.end();
            let summary = summary.map_err(|e| e.to_string())?;
            eprintln!(
                "wrote {}: {} IMU samples, {} GNSS epochs, {} fixes, {} velocities, {} reference \
                 samples",
                out.display(),
                summary.imu,
                summary.gnss,
                summary.fixes,
                summary.velocities,
                summary.truth
            );
            eprintln!("{}", simulate::time_base(&scenario));
            Ok(())
        }
        Command::Replay {
            bag,
            params,
            out,
            compress,
            csv,
            truth_topic,
            truth_csv,
        } => {
            // The node's own parameters too: the frames and the TF are the node's.
            let NodeParams { config, frames, .. } =
                node_params_from_files(&params).map_err(|e| e.to_string())?;
            let truth = match (truth_topic, truth_csv) {
                (Some(t), _) => TruthSource::Topic(t),
                (None, Some(path)) => {
                    TruthSource::Track(replay::read_truth_csv(&path).map_err(|e| e.to_string())?)
                }
                (None, None) => TruthSource::None,
            };
            let options = ReplayOptions {
                out_bag: out.as_deref(),
                csv: csv.as_deref(),
                score_interval_s: SCORE_INTERVAL_S,
                frames,
                compression: if compress {
                    ChunkCompression::Zstd
                } else {
                    ChunkCompression::None
                },
            };
            let progress = Progress::new();
            let result = replay::replay(&bag, &config, truth, &options, |f| {
                progress.fraction("replay", f)
            });
            progress.end();
            let result = result.map_err(|e| e.to_string())?;
            print_problems(&result, config.filter.coupling);
            println!(
                "{} solutions, {} GNSS updates",
                result.report.solutions, result.report.epochs
            );
            if let Some(s) = result.summary() {
                println!(
                    "position RMSE E {:.3} N {:.3} U {:.3} 3D {:.3} m; velocity {:.4} m/s; \
                     attitude roll {:.4} pitch {:.4} yaw {:.4} deg; mean NEES {:.2} ({} epochs)",
                    s.pos_rmse_e_m,
                    s.pos_rmse_n_m,
                    s.pos_rmse_u_m,
                    s.pos_rmse_3d_m,
                    s.vel_rmse_3d_mps,
                    s.att_rmse_roll_deg,
                    s.att_rmse_pitch_deg,
                    s.att_rmse_yaw_deg,
                    s.nees_mean,
                    s.epochs
                );
            }
            if result.report.solutions == 0 {
                let used: Vec<String> = result
                    .problems
                    .used_topics
                    .iter()
                    .map(|(topic, n)| format!("{n} on {topic}"))
                    .collect();
                return Err(format!(
                    "{}: no solution (messages used: {}): {}",
                    bag.display(),
                    if used.is_empty() {
                        "none".to_owned()
                    } else {
                        used.join(", ")
                    },
                    start_blocker(result.start_phase, &config)
                ));
            }
            // Choice: a replay fails when most of its IMU messages did not reach the
            // filter: its outputs then describe a part of the bag only (issue 12, item
            // 14: one sample stamped far ahead once cost every later sample), which a
            // script must not take for the whole. Fewer losses are listed above.
            let (dropped, read) = result.imu_dropped(simulate::IMU_TOPIC);
            if 2 * dropped > read {
                return Err(format!(
                    "{}: {dropped} of the {read} IMU messages did not reach the filter (see \
                     above): the {} solutions written cover only part of the bag",
                    bag.display(),
                    result.report.solutions
                ));
            }
            Ok(())
        }
        Command::Compare {
            bag,
            filters,
            params_dir,
            params,
            by_environment,
            scored_after_start_s,
            format,
            plots,
        } => {
            if !(scored_after_start_s >= 0.0 && scored_after_start_s.is_finite()) {
                return Err(format!(
                    "--scored-after-start-s {scored_after_start_s}: must be a finite number of \
                     seconds, 0 or more"
                ));
            }
            let configs = variant_configs(&filters, params_dir.as_deref(), &params)?;
            let runs = compare_bag(&bag, &configs, TRUTH_TOPIC)?;
            let scored_from = |report: &SessionReport| {
                report
                    .first_scored_t_s()
                    .map_or(f64::NEG_INFINITY, |t| t + scored_after_start_s)
            };
            let rows: Vec<ComparisonRow> = runs
                .iter()
                .map(|(row, report)| {
                    let summary = report.summary(scored_from(report));
                    ComparisonRow::new(&row.filter, &summary, row.divergence_resets, row.runtime_s)
                })
                .collect();
            print!("{}", render(&rows, format)?);
            if by_environment {
                let rows: Vec<EnvironmentRow> = runs
                    .iter()
                    .flat_map(|(row, report)| {
                        EnvironmentRow::rows(
                            &row.filter,
                            &report.summary_by_environment(scored_from(report)),
                        )
                    })
                    .collect();
                println!();
                print!("{}", format_environment_table(&rows));
            }
            if let Some(dir) = plots {
                let runs: Vec<FilterRun> = runs
                    .into_iter()
                    .map(|(row, report)| FilterRun {
                        name: row.filter,
                        report,
                    })
                    .collect();
                let progress = Progress::new();
                let files = write_plots(&dir, &runs, |f| progress.fraction("plots", f));
                progress.end();
                let files = files.map_err(|e| e.to_string())?;
                eprintln!("wrote {} figures into {}", files.len(), dir.display());
            }
            Ok(())
        }
        Command::Play(args) => cli_play::play(args),
        Command::Convert(args) => cli_real::convert(*args),
        Command::Spp(args) => cli_real::spp(args),
        Command::SppRinex(args) => cli_real::spp_rinex(args),
        Command::Demo { seed } => {
            let dir = std::env::temp_dir().join(format!("gnss_ins_demo_{}", std::process::id()));
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            let bag = dir.join("default.mcap");
            let scenario = load_scenario("default", seed)?;
            simulate::simulate(&scenario, &bag).map_err(|e| e.to_string())?;
            println!(
                "Simulated the default scenario (seed {seed}) into {}: a {:.0} s drive with \
                 foliage over 40-120 s and dense buildings over 260-320 s.",
                bag.display(),
                scenario.duration_s()
            );
            let runs = compare_bag(&bag, &variant_configs(&[], None, &[])?, TRUTH_TOPIC)?;
            let rows: Vec<ComparisonRow> = runs.into_iter().map(|(row, _)| row).collect();
            print!("{}", format_table(&rows));
            Ok(())
        }
    }
}

/// What the replay skipped and dropped, on stderr: the bag's problems, the adapter's
/// drops (named as on the node's /diagnostics) and the engine's rejections.
fn print_problems(run: &BagRun, coupling: Coupling) {
    let problems = &run.problems;
    for (what, n) in &problems.unused_topics {
        eprintln!("ignored {n} messages on a topic this run does not use: {what}");
    }
    for (topic, n) in &problems.unfed_inputs {
        eprintln!(
            "ignored {n} messages on {topic}: not an input with filter.coupling {}",
            coupling.as_str()
        );
    }
    for (what, n) in &problems.wrong_types {
        eprintln!("skipped {n} messages of an unexpected type: {what}");
    }
    for (what, n) in &problems.undecodable {
        eprintln!("skipped {n} undecodable messages ({what})");
    }
    for e in &problems.bag_errors {
        eprintln!("bag error: {e}");
    }
    let v = run.velocities();
    if v.paired + v.unpaired + v.foreign_frame > 0 {
        eprintln!(
            "velocities: {} paired with their fix, {} without a fix of their stamp, {} in a \
             foreign frame",
            v.paired, v.unpaired, v.foreign_frame
        );
    }
    if let Some(odom) = run.odom_tf {
        eprintln!(
            "map -> odom: {} odom -> base transforms taken from /tf (odom_tf_received), {} \
             unusable (odom_tf_unusable); {} Odometry messages without a map -> odom \
             (map_to_odom_missing)",
            odom.received, odom.unusable, odom.map_to_odom_missing
        );
    }
    for (name, n) in run.counts.dropped().into_iter().filter(|(_, n)| *n > 0) {
        eprintln!("dropped {n} messages: {name}");
    }
    if run.counts.non_finite_outputs > 0 {
        eprintln!(
            "warning: {} solutions with a non-finite value were not written \
             (non_finite_outputs)",
            run.counts.non_finite_outputs
        );
    }
    if run.counts.negative_variance_outputs > 0 {
        eprintln!(
            "warning: {} solutions with a negative variance were not written \
             (negative_variance_outputs)",
            run.counts.negative_variance_outputs
        );
    }
    if run.counts.time_jump_resets > 0 {
        eprintln!(
            "warning: the filter was reset and started again {} time(s): the IMU time jumped \
             back more than {TIME_JUMP_BACK_S} s for {TIME_JUMP_CONFIRM_SAMPLES} samples in a \
             row (time_jump_resets)",
            run.counts.time_jump_resets
        );
    }
    for (reason, n) in run.rejections.iter() {
        eprintln!("rejected {n} inputs: {}", reason.name());
    }
}

fn load_scenario(name_or_file: &str, seed: u64) -> Result<Scenario, String> {
    let spec = if ScenarioSpec::builtin_names().contains(&name_or_file) {
        ScenarioSpec::builtin(name_or_file).map_err(|e| e.to_string())?
    } else {
        let text = std::fs::read_to_string(name_or_file).map_err(|e| {
            format!(
                "scenario {name_or_file}: neither a built-in scenario ({}) nor a readable \
                 scenario YAML file: {e}",
                ScenarioSpec::builtin_names().join(", ")
            )
        })?;
        ScenarioSpec::from_yaml(&text).map_err(|e| format!("{name_or_file}: {e}"))?
    };
    Scenario::new(spec, seed).map_err(|e| e.to_string())
}

/// The configuration of parameter files read in order as the node reads them (a later
/// value wins; the node's own parameters are ignored); the defaults without any.
fn load_config(paths: &[PathBuf]) -> Result<Config, String> {
    crate::ros::node::params::config_from_files(paths).map_err(|e| e.to_string())
}

/// The configuration of one variant: the `base` files, then `<dir>/<variant>.yaml` when
/// present; without it, the `base` files with that variant.
fn variant_config(
    name: &str,
    params_dir: Option<&Path>,
    base: &[PathBuf],
) -> Result<Config, String> {
    if let Some(dir) = params_dir {
        let path = dir.join(format!("{name}.yaml"));
        if path.exists() {
            let mut files = base.to_vec();
            files.push(path);
            return load_config(&files);
        }
    }
    let variant = FilterVariant::ALL
        .into_iter()
        .find(|v| v.as_str() == name)
        .ok_or_else(|| {
            let known: Vec<&str> = FilterVariant::ALL.iter().map(|v| v.as_str()).collect();
            format!("unknown filter '{name}' (known: {})", known.join(", "))
        })?;
    let mut config = load_config(base)?;
    config.filter.variant = variant;
    Ok(config)
}

/// The named configurations of `filters` (all variants when empty).
fn variant_configs(
    filters: &[String],
    params_dir: Option<&Path>,
    base: &[PathBuf],
) -> Result<Vec<NamedConfig>, String> {
    let names: Vec<String> = if filters.is_empty() {
        FilterVariant::ALL
            .iter()
            .map(|v| v.as_str().to_owned())
            .collect()
    } else {
        filters.to_vec()
    };
    names
        .into_iter()
        .map(|name| {
            let config = variant_config(&name, params_dir, base)?;
            Ok(NamedConfig { name, config })
        })
        .collect()
}

fn render(rows: &[ComparisonRow], format: Format) -> Result<String, String> {
    Ok(match format {
        Format::Table => format_table(rows),
        Format::Csv => format_csv(rows),
        Format::Json => serde_json::to_string_pretty(rows).map_err(|e| e.to_string())? + "\n",
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Coupling;

    /// `compare --params-dir params` gives every variant the --params files' settings:
    /// the ekf preset, like the others, changes nothing but its variant (when it was the
    /// whole manual, the ekf row ran tightly coupled with the default IMU noise while the
    /// other rows ran the user's files).
    #[test]
    fn a_preset_of_params_dir_keeps_what_the_params_files_set() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let base = [
            root.join("params/defaults.yaml"),
            root.join("params/ekf_loose.yaml"),
            root.join("params/imu_consumer_mems.yaml"),
        ];
        let from_files = load_config(&base).unwrap();
        for name in ["ekf", "ermakf"] {
            let config = variant_config(name, Some(&root.join("params")), &base).unwrap();
            assert_eq!(config.filter.variant.as_str(), name);
            assert_eq!(config.filter.coupling, Coupling::Loose, "{name}");
            assert_eq!(config.imu, from_files.imu, "{name}");
        }
    }
}
