//! `gnss_ins replay` as the offline twin of the loosely-coupled node with receiver
//! velocities: a simulated bag with `/gnss/velocity` (the fixture scenario of
//! tests/data/fixture_small.yaml, written with `simulate --velocity`) replayed with the
//! `ekf_loose` preset joins every velocity with its fix, the velocities make the filter's
//! velocity better against the truth, and the result does not depend on whether each fix
//! or its velocity comes first in the bag.

mod bag_support;

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::ros::bag::{BagReader, BagWriter};
use adaptive_gnss_ins::sim::{Scenario, ScenarioSpec};
use adaptive_gnss_ins::tools::bag_run::BagRun;
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::{self, simulate_with, SimulateOptions, SimulateSummary};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The fixture's scenario (seed 1, as the committed bag).
fn scenario() -> Scenario {
    let yaml = std::fs::read_to_string(root().join("tests/data/fixture_small.yaml")).unwrap();
    Scenario::new(ScenarioSpec::from_yaml(&yaml).unwrap(), 1).unwrap()
}

fn loose_config() -> Config {
    let path = root().join("params/ekf_loose.yaml");
    let text = std::fs::read_to_string(&path).unwrap();
    Config::from_yaml_str(&text, &path.display().to_string()).unwrap()
}

/// Writes the scenario to `dir/name`, with or without velocities.
fn simulated(dir: &Path, name: &str, velocity: bool) -> (PathBuf, SimulateSummary) {
    let path = dir.join(name);
    let summary = simulate_with(&scenario(), &path, SimulateOptions { velocity }).unwrap();
    (path, summary)
}

/// Replays `bag` loosely coupled, scored against its `/ground_truth`, writing `csv`.
fn replay_loose(bag: &Path, csv: &Path) -> BagRun {
    let options = ReplayOptions {
        csv: Some(csv),
        ..ReplayOptions::default()
    };
    let truth = TruthSource::Topic(simulate::TRUTH_TOPIC.to_owned());
    replay(bag, &loose_config(), truth, &options, |_| {}).unwrap()
}

#[test]
fn replay_joins_every_velocity_with_its_fix_and_uses_it() {
    let dir = tempfile::tempdir().unwrap();
    let (with, summary) = simulated(dir.path(), "with.mcap", true);
    let (without, plain) = simulated(dir.path(), "without.mcap", false);
    assert!(summary.velocities > 30, "{summary:?}");
    assert_eq!(
        summary.velocities, summary.fixes,
        "every simulated fix has a velocity"
    );
    assert_eq!(plain.velocities, 0, "opt-in: {plain:?}");

    let a = replay_loose(&with, &dir.path().join("with.csv"));
    let b = replay_loose(&without, &dir.path().join("without.csv"));
    let v = a.velocities();
    assert_eq!(
        v.paired, summary.velocities as u64,
        "every velocity joined: {v:?}"
    );
    assert_eq!((v.unpaired, v.foreign_frame), (0, 0), "{v:?}");
    assert_eq!(a.problems.used(simulate::VELOCITY_TOPIC), v.paired);
    assert_eq!(b.velocities().paired, 0);

    // Scored over the same span: from the later of the two first scored solutions.
    let first_t_s = |r: &BagRun| r.report.errors.first().unwrap().1.t_s;
    let from_t_s = first_t_s(&a).max(first_t_s(&b));
    let (sa, sb) = (a.report.summary(from_t_s), b.report.summary(from_t_s));
    eprintln!(
        "{} velocities paired; velocity RMSE {:.4} m/s with them ({} epochs), {:.4} m/s \
         without ({} epochs); position 3D {:.3} / {:.3} m",
        v.paired,
        sa.vel_rmse_3d_mps,
        sa.epochs,
        sb.vel_rmse_3d_mps,
        sb.epochs,
        sa.pos_rmse_3d_m,
        sb.pos_rmse_3d_m
    );
    assert!(
        sa.epochs > 100 && sa.epochs == sb.epochs,
        "{} / {}",
        sa.epochs,
        sb.epochs
    );
    assert!(
        sa.vel_rmse_3d_mps < sb.vel_rmse_3d_mps,
        "the receiver velocities must help: {} vs {} m/s",
        sa.vel_rmse_3d_mps,
        sb.vel_rmse_3d_mps
    );
}

/// Copies `from` to `to`, delaying the log time of every message on `delayed` by 1 µs (the
/// stamps stay), so the bag order of every fix and its velocity is set.
fn with_log_time_delayed(from: &Path, to: &Path, delayed: &str) {
    let reader = BagReader::open(from).unwrap();
    let mut writer = BagWriter::create(to).unwrap();
    bag_support::add_simulated_topics(&mut writer);
    let mut moved = 0;
    for m in reader.messages().unwrap() {
        let m = m.unwrap();
        let mut t = m.log_time_ns;
        if m.topic == delayed {
            moved += 1;
            t += 1_000;
        }
        writer.write_cdr(&m.topic, &m.data, t).unwrap();
    }
    writer.finish().unwrap();
    assert!(moved > 30);
}

/// The topics of the fix and velocity messages of `bag`, in read order.
fn fix_velocity_order(bag: &Path) -> Vec<String> {
    BagReader::open(bag)
        .unwrap()
        .messages()
        .unwrap()
        .map(|m| m.unwrap().topic)
        .filter(|t| t == simulate::FIX_TOPIC || t == simulate::VELOCITY_TOPIC)
        .collect()
}

#[test]
fn replay_does_not_depend_on_whether_a_fix_or_its_velocity_comes_first() {
    let dir = tempfile::tempdir().unwrap();
    let (bag, summary) = simulated(dir.path(), "sim.mcap", true);
    let first = dir.path().join("velocity_first.mcap");
    let last = dir.path().join("velocity_last.mcap");
    with_log_time_delayed(&bag, &first, simulate::FIX_TOPIC);
    with_log_time_delayed(&bag, &last, simulate::VELOCITY_TOPIC);
    // The two bags do order each pair differently.
    let order = fix_velocity_order(&first);
    assert_eq!(order[0], simulate::VELOCITY_TOPIC);
    assert!(order
        .chunks(2)
        .all(|p| p == [simulate::VELOCITY_TOPIC, simulate::FIX_TOPIC]));
    let order = fix_velocity_order(&last);
    assert!(order
        .chunks(2)
        .all(|p| p == [simulate::FIX_TOPIC, simulate::VELOCITY_TOPIC]));

    let a = replay_loose(&first, &dir.path().join("first.csv"));
    let b = replay_loose(&last, &dir.path().join("last.csv"));
    assert_eq!(a.velocities(), b.velocities());
    assert_eq!(a.velocities().paired, summary.fixes as u64);
    assert_eq!(a.velocities().unpaired, 0);
    let csv_a = std::fs::read_to_string(dir.path().join("first.csv")).unwrap();
    let csv_b = std::fs::read_to_string(dir.path().join("last.csv")).unwrap();
    assert!(
        csv_a.lines().count() > 2500,
        "{} rows",
        csv_a.lines().count()
    );
    assert!(csv_a == csv_b, "the solutions differ with the order");
}
