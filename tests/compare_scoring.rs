//! `gnss_ins compare --scored-after-start-s S` on the golden fixture: each variant is
//! scored only from S seconds after its first scored solution, in both tables; a negative
//! or non-finite S is refused.

use std::path::Path;
use std::process::{Command, Output};

fn compare(extra: &[&str]) -> Output {
    let bag = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixture_small.mcap");
    Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .arg("compare")
        .arg(&bag)
        .args(["--filters", "ekf", "--by-environment", "--format", "csv"])
        .args(extra)
        .output()
        .unwrap()
}

/// The ekf's scored epochs of the environment table and its 3D position RMSE of the main
/// table.
fn scored(extra: &[&str]) -> (usize, f64) {
    let out = compare(extra);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rmse = stdout
        .lines()
        .find_map(|l| l.strip_prefix("ekf,"))
        .and_then(|l| l.split(',').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no ekf row: {stdout}"));
    let epochs: usize = stdout
        .lines()
        .filter(|l| l.starts_with("ekf ") && l.contains("open_sky"))
        .map(|l| {
            l.split_whitespace()
                .nth(2)
                .unwrap()
                .parse::<usize>()
                .unwrap()
        })
        .sum();
    (epochs, rmse)
}

#[test]
fn scoring_after_the_start_leaves_the_convergence_out() {
    let (all_epochs, all_rmse) = scored(&[]);
    let (late_epochs, late_rmse) = scored(&["--scored-after-start-s", "10"]);
    println!(
        "all: {all_epochs} epochs, {all_rmse:.3} m; from 10 s: {late_epochs}, {late_rmse:.3} m"
    );
    // The fixture's reference comes at 5 Hz: ten seconds are 50 epochs fewer.
    assert_eq!(
        all_epochs - late_epochs,
        50,
        "{all_epochs} -> {late_epochs}"
    );
    assert!(late_rmse != all_rmse);
    for bad in ["-1", "nan", "inf"] {
        let out = compare(&[&format!("--scored-after-start-s={bad}")]);
        assert!(!out.status.success(), "{bad} accepted");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("--scored-after-start-s"), "{bad}: {stderr}");
    }
}
