//! `gnss_ins compare --plots DIR` on the golden fixture: every figure as a PNG of the set
//! size and a labelled SVG, one line per filter; the table still goes to stdout.

use std::path::Path;
use std::process::Command;

#[test]
fn compare_writes_png_and_svg_figures_with_every_filter() {
    let bag = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixture_small.mcap");
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("figures");
    let output = Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .arg("compare")
        .arg(&bag)
        .args(["--filters", "ekf,ermakf", "--format", "csv", "--plots"])
        .arg(&plots)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(stdout.lines().count(), 3, "{stdout}");
    assert!(stderr.contains("wrote 8 figures"), "{stderr}");

    for stem in [
        "position_error",
        "velocity_error",
        "attitude_error",
        "noise_sigma",
    ] {
        let png = std::fs::read(plots.join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}");
        // IHDR: width and height, big-endian, at bytes 16..24.
        let width = u32::from_be_bytes(png[16..20].try_into().unwrap());
        let height = u32::from_be_bytes(png[20..24].try_into().unwrap());
        assert_eq!((width, height), (1400, 1000), "{stem}");
        let svg = std::fs::read_to_string(plots.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.starts_with("<svg"), "{stem}");
        // The fixture is stamped in UTC (October 2025): its time axis counts from a
        // whole second named in UTC.
        assert!(
            svg.lines()
                .any(|l| l.starts_with("time since 2025-10-02 ") && l.ends_with(" UTC (s)")),
            "{stem}: no UTC time axis"
        );
        for label in ["ekf", "ermakf"] {
            // The SVG backend writes each text on a line of its own.
            assert!(
                svg.contains(&format!("\n{label}\n")),
                "{stem}: no label {label}"
            );
        }
        // One polyline per filter and panel at least (three or four panels).
        assert!(svg.matches("<polyline").count() >= 6, "{stem}");
    }
    let noise = std::fs::read_to_string(plots.join("noise_sigma.svg")).unwrap();
    assert!(noise.contains("true σ"));
}
