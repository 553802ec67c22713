//! `gnss_ins replay` and `compare` read their `--params` files as the node does: any
//! number, in order (a later value wins), nested or dotted keys, the node's own
//! parameters accepted (issue 16: `replay` refused `use_sim_time` and a second file;
//! `replay` checks them as the node does and frames its outputs and TF by them, `compare`
//! ignores them).

use std::path::Path;
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn gnss_ins(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

fn succeeded(out: &Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

const BAG: &str = "tests/data/fixture_small.mcap";

#[test]
fn replay_takes_the_manual_then_a_launch_style_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("launch_style.yaml");
    std::fs::write(
        &file,
        "/**:\n  ros__parameters:\n    use_sim_time: true\n    map_frame: enu\n    \
         filter.variant: ermakf\n",
    )
    .unwrap();
    let out = gnss_ins(&[
        "replay",
        BAG,
        "--params",
        "params/defaults.yaml",
        "--params",
        file.to_str().unwrap(),
    ]);
    assert!(succeeded(&out).contains("solutions"));
    // A file for another node is refused, naming it.
    std::fs::write(
        &file,
        "other_node:\n  ros__parameters:\n    filter.variant: ermakf\n",
    )
    .unwrap();
    let out = gnss_ins(&["replay", BAG, "--params", file.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("other_node"));
}

#[test]
fn compare_overlays_each_preset_on_the_params_files() {
    let out = gnss_ins(&[
        "compare",
        BAG,
        "--params",
        "params/defaults.yaml",
        "--params-dir",
        "params",
        "--filters",
        "ekf,ermakf",
        "--format",
        "csv",
    ]);
    let table = succeeded(&out);
    assert!(table.lines().any(|l| l.starts_with("ermakf")), "{table}");
    assert!(table.lines().any(|l| l.starts_with("ekf")), "{table}");
}
