//! The launch files of launch_scripts/: the Python launch file parses and names files and
//! topics that exist; the shell script is valid bash and refuses an unknown preset.

use std::path::Path;
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn python_launch_file_parses_and_names_existing_things() {
    let launch = root().join("launch_scripts/gnss_ins_node.launch.py");
    let text = std::fs::read_to_string(&launch).unwrap();
    let out = Command::new("python3")
        .args(["-c", "import ast, sys; ast.parse(open(sys.argv[1]).read())"])
        .arg(&launch)
        .output()
        .expect("python3 is needed to check the launch file");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The default params file, relative to the package root, exists.
    assert!(text.contains("os.path.join(PACKAGE_ROOT, 'params', 'ekf.yaml')"));
    assert!(root().join("params/ekf.yaml").is_file());
    // The executable it starts is a binary of this crate.
    assert!(text.contains("executable='gnss_ins_node'"));
    assert!(root().join("src/bin/gnss_ins_node.rs").is_file());
    // Its remappings address the node's own relative input and output names.
    for topic in ["'imu'", "'gnss/measurements'", "'gnss/fix'", "'odometry'"] {
        assert!(
            text.contains(&format!("({topic}, LaunchConfiguration(")),
            "{topic}"
        );
    }
    let node = std::fs::read_to_string(root().join("src/ros/node/mod.rs")).unwrap();
    for topic in [
        "\"imu\"",
        "\"gnss/measurements\"",
        "\"gnss/fix\"",
        "\"odometry\"",
    ] {
        assert!(node.contains(topic), "the node has no topic {topic}");
    }
}

#[test]
fn shell_script_is_valid_and_refuses_unknown_presets() {
    let script = root().join("launch_scripts/run_node_with_preset.sh");
    let syntax = Command::new("bash")
        .arg("-n")
        .arg(&script)
        .status()
        .unwrap();
    assert!(syntax.success());
    let out = Command::new("bash")
        .arg(&script)
        .arg("no_such_preset")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no preset"));
}
