//! The launch files of launch_scripts/: the Python launch file parses and names files and
//! topics that exist, declares the node's own parameters (by the node's names) and passes
//! only those the user set; the shell script is valid bash, refuses an unknown preset and
//! passes the node's parameters as `-p`.

use std::path::Path;
use std::process::Command;

use adaptive_gnss_ins::ros::node::params::{NODE_PARAMETERS, USE_SIM_TIME};

/// The names of the node's own parameters.
fn node_parameter_names() -> Vec<&'static str> {
    NODE_PARAMETERS.iter().map(|p| p.name).collect()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A finished command's standard output when it succeeded, its standard error otherwise.
fn stdout_or_stderr(out: &std::process::Output) -> Result<String, String> {
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).into_owned())
    }
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
    let node = std::fs::read_to_string(root().join("src/ros/node/mod.rs")).unwrap();
    for topic in [
        "imu",
        "gnss/measurements",
        "gnss/fix",
        "gnss/velocity",
        "odometry",
    ] {
        assert!(
            text.contains(&format!("': '{topic}',")),
            "no remap of {topic}"
        );
        assert!(
            node.contains(&format!("\"{topic}\"")),
            "the node has no topic {topic}"
        );
    }
}

/// Runs the launch file under stand-ins of the `launch` and `launch_ros` modules (no ROS
/// here), resolves its OpaqueFunction with the launch arguments `set` (name, value; the
/// others keep their defaults) and returns what it printed: one line per declared argument
/// (`arg NAME=DEFAULT`), then `parameters REPR` and `remap FROM TO` of the node.
fn run_launch_file(set: &[(&str, &str)]) -> Result<String, String> {
    const HARNESS: &str = r#"
import sys, types
def module(name, **members):
    m = types.ModuleType(name)
    m.__dict__.update(members)
    sys.modules[name] = m
class Record:
    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs
class LaunchConfiguration:
    def __init__(self, name):
        self.name = name
    def perform(self, context):
        return context[self.name]
module('launch', LaunchDescription=Record)
module('launch.actions', DeclareLaunchArgument=Record, OpaqueFunction=Record)
module('launch.substitutions', LaunchConfiguration=LaunchConfiguration)
module('launch_ros'); module('launch_ros.actions', Node=Record)
launch = {'__file__': sys.argv[1]}
exec(compile(open(sys.argv[1]).read(), sys.argv[1], 'exec'), launch)
description = launch['generate_launch_description']()
context = {}
for action in description.args[0]:
    if action.args:
        name, default = action.args[0], action.kwargs['default_value']
        print(f'arg {name}={default}')
        context[name] = default
    else:
        opaque = action
for pair in sys.argv[2:]:
    name, value = pair.split('=', 1)
    context[name] = value
(node,) = opaque.kwargs['function'](context)
print('parameters', repr(node.kwargs['parameters'][1:]))
for old, new in node.kwargs['remappings']:
    print('remap', old, new)
"#;
    let launch = root().join("launch_scripts/gnss_ins_node.launch.py");
    let out = Command::new("python3")
        .arg("-c")
        .arg(HARNESS)
        .arg(&launch)
        .args(set.iter().map(|(n, v)| format!("{n}={v}")))
        .output()
        .expect("python3 is needed to check the launch file");
    stdout_or_stderr(&out)
}

#[test]
fn launch_file_declares_the_nodes_parameters_and_passes_only_those_set() {
    let printed = run_launch_file(&[]).unwrap();
    // Every node parameter is a launch argument whose default means "not set".
    for name in node_parameter_names() {
        assert!(
            printed.lines().any(|l| l == format!("arg {name}=")),
            "no launch argument {name} defaulting to '':\n{printed}"
        );
    }
    // ... and no other argument does (but the namespace): the same set as the node's.
    let mut not_set: Vec<&str> = printed
        .lines()
        .filter_map(|l| l.strip_prefix("arg")?.trim().strip_suffix('='))
        .filter(|name| *name != "namespace")
        .collect();
    let mut node = node_parameter_names();
    not_set.sort_unstable();
    node.sort_unstable();
    assert_eq!(not_set, node);
    assert!(
        printed.contains("remap gnss/velocity gnss/velocity"),
        "{printed}"
    );
    // Nothing set: only the params file, which then decides every node parameter.
    assert!(printed.contains("parameters []"), "{printed}");

    // Set ones are passed after the params file, typed as the node expects.
    let printed = run_launch_file(&[
        (USE_SIM_TIME, "True"),
        ("map_frame", "odom_enu"),
        ("queue_depth", "500"),
        ("velocity_topic", "/ublox/fix_velocity"),
    ])
    .unwrap();
    assert!(
        printed.contains(
            "parameters [{'use_sim_time': True, 'map_frame': 'odom_enu', 'queue_depth': 500}]"
        ),
        "{printed}"
    );
    assert!(
        printed.contains("remap gnss/velocity /ublox/fix_velocity"),
        "{printed}"
    );
    // A value of the wrong type is refused by the launch file, naming the parameter.
    for (name, bad) in [("publish_tf", "yes"), ("queue_depth", "deep")] {
        let e = run_launch_file(&[(name, bad)]).unwrap_err();
        assert!(e.contains(name), "{e}");
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

/// The command the shell script would run with `args` (GNSS_INS_DRY_RUN), or its stderr.
fn shell_command(args: &[&str]) -> Result<String, String> {
    let out = Command::new("bash")
        .arg(root().join("launch_scripts/run_node_with_preset.sh"))
        .args(args)
        .env("GNSS_INS_DRY_RUN", "1")
        .output()
        .unwrap();
    stdout_or_stderr(&out)
}

#[test]
fn shell_script_passes_node_parameters_as_p() {
    for name in node_parameter_names() {
        let set = format!("{name}:=x");
        let command = shell_command(&["ekf", &set, "-r", "__ns:=/robot"]).unwrap();
        assert!(
            command
                .trim_end()
                .ends_with(&format!("params/ekf.yaml -p {name}:=x -r __ns:=/robot")),
            "{command}"
        );
    }
    let plain = shell_command(&["ekf"]).unwrap();
    assert!(plain.trim_end().ends_with("params/ekf.yaml"), "{plain}");
    let e = shell_command(&["ekf", "map_frme:=odom"]).unwrap_err();
    assert!(e.contains("map_frme is not a node parameter"), "{e}");
}
