//! The launch files of launch_scripts/: the Python launch file parses and names files and
//! topics that exist, declares the node's own parameters (by the node's names) and passes
//! only those the user set, and the node loads the command line launch_ros 0.26 builds
//! from it (reproduced here from launch_ros's source, temporary file included); the
//! shell scripts are valid bash, refuse an unknown preset, load the preset after the
//! manual and pass the node's parameters as `-p`.

use std::path::{Path, PathBuf};
use std::process::Command;

use adaptive_gnss_ins::config::{Config, Coupling};
use adaptive_gnss_ins::ros::args::{parse, parse_as, NodeArgs};
use adaptive_gnss_ins::ros::names::resolve_remapped;
use adaptive_gnss_ins::ros::node::params::{
    config_from_files, load, NodeParams, NODE_PARAMETERS, QUEUE_DEPTH, USE_SIM_TIME,
};
use adaptive_gnss_ins::ros::ubx_adapter::TimeBase;
use adaptive_gnss_ins::ros::ubx_node::{self, params::UBX_NODE_PARAMETERS};

mod venv_support;

/// The names of the node's own parameters.
fn node_parameter_names() -> Vec<&'static str> {
    NODE_PARAMETERS.iter().map(|p| p.name).collect()
}

/// The parameters of gnss_ins_ubx_node the launch file declares: its table but the topic
/// names (remapped instead) and those shared with gnss_ins_node.
fn ubx_launch_parameter_names() -> Vec<&'static str> {
    UBX_NODE_PARAMETERS
        .iter()
        .map(|p| p.name)
        .filter(|n| !n.ends_with("_topic") && ![USE_SIM_TIME, QUEUE_DEPTH].contains(n))
        .collect()
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
    let out = Command::new(venv_support::python())
        .args(["-c", "import ast, sys; ast.parse(open(sys.argv[1]).read())"])
        .arg(&launch)
        .output()
        .expect("the venv python runs the launch file harness");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The default params file, relative to the package root, exists.
    assert!(text.contains("os.path.join(PACKAGE_ROOT, 'params', 'defaults.yaml')"));
    assert!(root().join("params/defaults.yaml").is_file());
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
        "fix/filtered",
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

/// The Python side of the launch tests: the launch file run under stand-ins of the
/// `launch` and `launch_ros` modules (there is no ROS here), its OpaqueFunction resolved
/// with the launch arguments given as NAME=VALUE (the others keep their defaults).
///
/// Mode `describe` prints one line per declared argument (`arg NAME=DEFAULT`), then per
/// node `parameters REPR` (gnss_ins_node's after the manual) and `remap FROM TO`.
///
/// Mode `describe` names each node (`node EXECUTABLE`) before its lines. Mode `argv`
/// prints, as JSON, one line per node: the command line launch_ros 0.26 (Jazzy) builds for
/// it, writing the temporary parameter file as it does. Read from launch_ros 0.26.6,
/// launch_ros/actions/node.py (`Node.__init__`, `_perform_substitutions`, `execute`,
/// `_create_params_file_from_dict`), utilities/namespace_utils.py (`prefix_namespace`,
/// `make_namespace_absolute`), utilities/normalize_parameters.py (nested dicts flattened
/// to dotted names) and utilities/evaluate_parameters.py (string values through YAML):
/// the executable, `arguments`, `--ros-args`, `-r __node:=NAME` (when named), `-r __ns:=NS`
/// (when a namespace is given, made absolute), one `--params-file` per file or dict in
/// order (a dict written to `NamedTemporaryFile(prefix='launch_params_')` with
/// `yaml.dump({NODE: {'ros__parameters': dict}}, default_flow_style=False)`, NODE the
/// fully qualified name when name and namespace are known, else `/**`), then the
/// remappings as `-r FROM:=TO`. Mode `node` does the same for Node keyword arguments
/// given as JSON instead of the launch file's.
const HARNESS: &str = r#"
import json, os, sys, tempfile, types
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

def prefix_namespace(base, ns):
    if base is None and ns is None:
        return None
    if ns is None:
        combined = base
    elif not base or ns.startswith('/'):
        combined = ns
    else:
        combined = ('' if base == '/' else base) + '/' + ns
    return combined if combined == '/' else combined.rstrip('/')

def flatten(params, prefix=''):
    import yaml
    flat = {}
    for name, value in params.items():
        name = prefix + '.' + name if prefix else name
        if isinstance(value, dict):
            flat.update(flatten(value, name))
        elif isinstance(value, str):
            flat[name] = yaml.safe_load(yaml.dump(value))
        else:
            flat[name] = value
    return flat

def launch_ros_argv(executable, kw):
    import yaml
    cmd = [executable] + list(kw.get('arguments') or [])
    if kw.get('ros_arguments') is not None:
        cmd += ['--ros-args'] + list(kw['ros_arguments'])
    cmd += ['--ros-args']
    name, namespace = kw.get('name'), kw.get('namespace')
    if name is not None:
        cmd += ['-r', '__node:=' + name]
    final_ns = '<node_namespace_unspecified>'
    if namespace is not None:
        ns = prefix_namespace(None, namespace)
        final_ns = ns if ns.startswith('/') else '/' + ns
        cmd += ['-r', '__ns:=' + final_ns]
    node_name = prefix_namespace(final_ns, name if name is not None else '<node_name_unspecified>')
    specified = 'unspecified>' not in node_name
    for params in kw.get('parameters') or []:
        if isinstance(params, dict):
            with tempfile.NamedTemporaryFile(mode='w', prefix='launch_params_', delete=False) as h:
                key = node_name if specified else '/**'
                yaml.dump({key: {'ros__parameters': flatten(params)}}, h, default_flow_style=False)
                params = h.name
        cmd += ['--params-file', str(params)]
    for old, new in kw.get('remappings') or []:
        cmd += ['-r', old + ':=' + new]
    return cmd

mode = sys.argv[1]
if mode == 'node':
    print(json.dumps(launch_ros_argv('gnss_ins_node', json.loads(sys.argv[2]))))
    sys.exit(0)
launch = {'__file__': sys.argv[2]}
exec(compile(open(sys.argv[2]).read(), sys.argv[2], 'exec'), launch)
description = launch['generate_launch_description']()
context = {}
for action in description.args[0]:
    if action.args:
        name, default = action.args[0], action.kwargs['default_value']
        if mode == 'describe':
            print(f'arg {name}={default}')
        context[name] = default
    else:
        opaque = action
for pair in sys.argv[3:]:
    name, value = pair.split('=', 1)
    context[name] = value
for node in opaque.kwargs['function'](context):
    executable = node.kwargs['executable']
    if mode == 'describe':
        # gnss_ins_node's parameters after the manual; gnss_ins_ubx_node's all.
        skip = 1 if executable == 'gnss_ins_node' else 0
        print('node', executable)
        print('parameters', repr(node.kwargs['parameters'][skip:]))
        for old, new in node.kwargs['remappings']:
            print('remap', old, new)
    else:
        print(json.dumps(launch_ros_argv(executable, node.kwargs)))
"#;

/// Runs the harness in `mode` with `args`, from the package root (where `ros2 launch`
/// is run in the README), and returns its standard output.
fn harness(mode: &str, args: &[String]) -> Result<String, String> {
    let out = Command::new(venv_support::python())
        .current_dir(root())
        .arg("-c")
        .arg(HARNESS)
        .arg(mode)
        .args(args)
        .output()
        .expect("the venv python runs the launch file harness");
    stdout_or_stderr(&out)
}

/// The launch file resolved with the launch arguments `set` (name, value), in `mode`.
fn run_launch_file_in(mode: &str, set: &[(&str, &str)]) -> Result<String, String> {
    let launch = root().join("launch_scripts/gnss_ins_node.launch.py");
    let mut args = vec![launch.display().to_string()];
    args.extend(set.iter().map(|(n, v)| format!("{n}={v}")));
    harness(mode, &args)
}

/// What the launch file declares and passes to the node (mode `describe`).
fn run_launch_file(set: &[(&str, &str)]) -> Result<String, String> {
    run_launch_file_in("describe", set)
}

/// The argv launch_ros 0.26 gives the node, and the temporary files in it.
struct LaunchedArgv {
    argv: Vec<String>,
    temporary: Vec<PathBuf>,
}

impl LaunchedArgv {
    fn parse(json: &str) -> Self {
        let argv: Vec<String> = serde_json::from_str(json.trim()).unwrap();
        let temporary = argv
            .iter()
            .filter(|a| {
                Path::new(a)
                    .file_name()
                    .is_some_and(|f| f.to_string_lossy().starts_with("launch_params_"))
            })
            .map(PathBuf::from)
            .collect();
        Self { argv, temporary }
    }

    /// One per node: the lines of mode `argv`.
    fn parse_each(json: &str) -> Vec<Self> {
        json.lines().map(Self::parse).collect()
    }

    /// The node's parameters as it loads them from this command line.
    fn load(&self) -> NodeParams {
        let args = parse(self.argv[1..].iter().cloned()).unwrap();
        load(&args).unwrap_or_else(|e| panic!("{e}\n{:?}", self.argv))
    }
}

impl Drop for LaunchedArgv {
    fn drop(&mut self) {
        for file in &self.temporary {
            let _ = std::fs::remove_file(file);
        }
    }
}

/// Issue 16: the README's own launch example failed with "only one --params-file is
/// supported": launch_ros writes the overrides to a temporary file and passes it as a
/// further --params-file.
#[test]
fn the_readme_launch_example_loads_as_launch_ros_runs_it() {
    let json = run_launch_file_in(
        "argv",
        &[
            ("params_file", "params/ekf_loose.yaml"),
            ("publish_tf", "true"),
            ("base_frame", "imu_link"),
            ("velocity_topic", "/ublox/fix_velocity"),
        ],
    )
    .unwrap();
    let launched = LaunchedArgv::parse(&json);
    let manual = root().join("params/defaults.yaml").display().to_string();
    let argv: Vec<&str> = launched.argv.iter().map(String::as_str).collect();
    assert_eq!(
        argv[..16],
        [
            "gnss_ins_node",
            "--ros-args",
            "--log-level",
            "info",
            "--ros-args",
            "-r",
            "__node:=gnss_ins_node",
            "-r",
            "__ns:=/",
            "--params-file",
            manual.as_str(),
            "--params-file",
            "params/ekf_loose.yaml",
            "--params-file",
            launched.temporary[0].to_str().unwrap(),
            "-r",
        ],
        "{argv:?}"
    );
    assert!(
        argv.contains(&"gnss/velocity:=/ublox/fix_velocity"),
        "{argv:?}"
    );
    // The temporary file, byte for byte as PyYAML writes it for launch_ros.
    assert_eq!(
        std::fs::read_to_string(&launched.temporary[0]).unwrap(),
        "/gnss_ins_node:\n  ros__parameters:\n    base_frame: imu_link\n    publish_tf: true\n"
    );
    let p = launched.load();
    assert_eq!(p.frames.base_frame, "imu_link");
    assert!(p.frames.publish_tf);
    assert_eq!(
        p.config.filter.coupling,
        Coupling::Loose,
        "the preset applies"
    );
    let mut expected = Config::default();
    expected.filter.coupling = Coupling::Loose;
    assert_eq!(p.config, expected);
}

#[test]
fn a_launch_in_a_namespace_addresses_the_fully_qualified_name() {
    let json = run_launch_file_in(
        "argv",
        &[
            ("namespace", "robot"),
            ("params_file", "params/iarf.yaml"),
            ("use_sim_time", "true"),
        ],
    )
    .unwrap();
    let launched = LaunchedArgv::parse(&json);
    assert!(launched.argv.contains(&"__ns:=/robot".to_owned()));
    let text = std::fs::read_to_string(&launched.temporary[0]).unwrap();
    assert!(text.starts_with("/robot/gnss_ins_node:\n"), "{text}");
    let p = launched.load();
    assert!(p.use_sim_time);
    assert_eq!(p.config.filter.variant.as_str(), "iarf");
}

/// launch_ros flattens a nested dict to dotted names, under `/**` when the node has no
/// name in the launch file.
#[test]
fn a_nested_parameter_dict_arrives_as_dotted_keys_under_the_wildcard() {
    let node = r#"{"parameters": [{"filter": {"variant": "ermakf"}, "gnss": {"elevation_mask_deg": 15.0}, "publish_tf": true}]}"#;
    let launched = LaunchedArgv::parse(&harness("node", &[node.to_owned()]).unwrap());
    assert_eq!(
        std::fs::read_to_string(&launched.temporary[0]).unwrap(),
        "/**:\n  ros__parameters:\n    filter.variant: ermakf\n    gnss.elevation_mask_deg: 15.0\n    publish_tf: true\n"
    );
    let p = launched.load();
    assert_eq!(p.config.filter.variant.as_str(), "ermakf");
    assert!((p.config.gnss.elevation_mask_rad - 15f64.to_radians()).abs() < 1e-15);
    assert!(p.frames.publish_tf);
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
    node.extend(ubx_launch_parameter_names());
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

/// `with_ubx_adapter:=true` starts gnss_ins_ubx_node beside gnss_ins_node, in the same
/// namespace, with ublox_dgnss's topics at the root namespace remapped in, the IMU of
/// gnss_ins_node, and its output on gnss_ins_node's GNSS input; the parameters set reach
/// each node as it loads them (the shared ones both).
#[test]
fn with_ubx_adapter_starts_both_nodes_as_a_ublox_dgnss_user_needs() {
    let json = run_launch_file_in(
        "argv",
        &[
            ("with_ubx_adapter", "true"),
            ("namespace", "robot"),
            ("imu_topic", "/sensors/imu"),
            ("time_base", "host"),
            ("host_latency_s", "0.02"),
            ("leap_seconds", "18"),
            ("use_sim_time", "true"),
        ],
    )
    .unwrap();
    let nodes = LaunchedArgv::parse_each(&json);
    assert_eq!(nodes.len(), 2, "{json}");
    let (filter, ubx) = (&nodes[0], &nodes[1]);
    assert_eq!(ubx.argv[0], "gnss_ins_ubx_node");
    assert!(
        !ubx.argv.iter().any(|a| a.ends_with("defaults.yaml")),
        "the filter's manual is no parameter file of the adapter: {:?}",
        ubx.argv
    );
    assert_eq!(
        std::fs::read_to_string(&ubx.temporary[0]).unwrap(),
        "/robot/gnss_ins_ubx_node:\n  ros__parameters:\n    host_latency_s: 0.02\n    \
         leap_seconds: 18\n    time_base: host\n    use_sim_time: true\n"
    );
    let ubx_args = parse_as(ubx_node::DEFAULT_NODE_NAME, ubx.argv[1..].iter().cloned()).unwrap();
    let p = ubx_node::params::load(&ubx_args).unwrap();
    assert_eq!(p.adapter.time_base, TimeBase::Host);
    assert_eq!(p.adapter.host_latency_s, 0.02);
    assert!(p.use_sim_time);
    assert!(filter.load().use_sim_time, "shared with gnss_ins_node");
    let filter_args = parse(filter.argv[1..].iter().cloned()).unwrap();
    let topic = |args: &NodeArgs, name: &str| {
        resolve_remapped(name, &args.namespace, &args.node_name, &args.remaps)
    };
    assert_eq!(topic(&ubx_args, &p.topics.rawx), "/ubx_rxm_rawx");
    assert_eq!(topic(&ubx_args, &p.topics.sfrbx), "/ubx_rxm_sfrbx");
    assert_eq!(topic(&ubx_args, &p.topics.stream), "/robot/ubx_raw");
    assert_eq!(topic(&ubx_args, &p.topics.imu), "/sensors/imu");
    assert_eq!(topic(&filter_args, "imu"), "/sensors/imu");
    assert_eq!(
        topic(&ubx_args, &p.topics.measurements),
        topic(&filter_args, "gnss/measurements"),
        "the adapter publishes what the filter reads"
    );
    assert_eq!(
        topic(&filter_args, "gnss/measurements"),
        "/robot/gnss/measurements"
    );

    // Off by default; a set parameter of the wrong type is refused naming it.
    let one = run_launch_file_in("argv", &[]).unwrap();
    assert_eq!(LaunchedArgv::parse_each(&one).len(), 1);
    let e =
        run_launch_file(&[("with_ubx_adapter", "true"), ("host_latency_s", "soon")]).unwrap_err();
    assert!(e.contains("host_latency_s"), "{e}");
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
    assert_eq!(plain.matches("--params-file").count(), 2, "{plain}");
    // The manual is not given twice.
    let manual = shell_command(&["defaults"]).unwrap();
    assert!(
        manual.trim_end().ends_with("params/defaults.yaml"),
        "{manual}"
    );
    assert_eq!(manual.matches("--params-file").count(), 1, "{manual}");
    let e = shell_command(&["ekf", "map_frme:=odom"]).unwrap_err();
    assert!(e.contains("map_frme is not a node parameter"), "{e}");
}

/// The words after `--` of a printed `cargo run ... -- ARGS` command.
fn program_args(command: &str) -> Vec<String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    let start = words.iter().position(|w| *w == "--").unwrap() + 1;
    words[start..].iter().map(|w| w.to_string()).collect()
}

/// The scripts load a preset after the manual, and the node (and replay) read that
/// command line to the preset's configuration.
#[test]
fn shell_scripts_load_the_preset_over_the_manual() {
    let command = shell_command(&["ermakf", "publish_tf:=true"]).unwrap();
    let manual = root().join("params/defaults.yaml");
    let preset = root().join("params/ermakf.yaml");
    assert!(
        command.contains(&format!(
            "--params-file {} --params-file {} -p publish_tf:=true",
            manual.display(),
            preset.display()
        )),
        "{command}"
    );
    let p = load(&parse(program_args(&command)).unwrap()).unwrap();
    assert_eq!(p.config.filter.variant.as_str(), "ermakf");
    assert!(p.frames.publish_tf);

    let out = Command::new("bash")
        .arg(root().join("launch_scripts/replay_with_preset.sh"))
        .args(["bag.mcap", "walk_0827"])
        .env("GNSS_INS_DRY_RUN", "1")
        .output()
        .unwrap();
    let command = stdout_or_stderr(&out).unwrap();
    let words = program_args(&command);
    let files: Vec<PathBuf> = words
        .windows(2)
        .filter(|w| w[0] == "--params")
        .map(|w| PathBuf::from(&w[1]))
        .collect();
    assert_eq!(
        files,
        vec![manual, root().join("params/walk_0827.yaml")],
        "{command}"
    );
    let config = config_from_files(&files).unwrap();
    assert_eq!(config.init.leveling_duration_s, 5.0);
}
