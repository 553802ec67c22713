//! The configuration loader against the preset files in `params/` and against bad input.
//! Every preset but the manual (`params/defaults.yaml`) is an overlay loaded after it.

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::config::{
    Config, ConfigError, Coupling, FilterVariant, PARAMETER_OVERRIDE_ORIGIN, RAD_PER_DEG,
    RAD_S_PER_DEG_H,
};
use adaptive_gnss_ins::gnss::Constellation;
use adaptive_gnss_ins::ros::node::params::config_from_files;
use serde_yaml::Value;

fn params_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("params")
}

fn preset_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(params_dir())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "yaml"))
        .collect();
    files.sort();
    files
}

/// The preset `name` as it is meant to be loaded: over the manual.
fn load(name: &str) -> Config {
    config_from_files(&[params_dir().join("defaults.yaml"), params_dir().join(name)])
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A parameter file holding `body` (section lines indented by four spaces).
fn file(body: &str) -> String {
    format!("gnss_ins_node:\n  ros__parameters:\n{body}")
}

fn load_error(body: &str) -> ConfigError {
    Config::from_yaml_str(&file(body), "test.yaml").unwrap_err()
}

/// The message names the key and the origin.
fn assert_names(error: &ConfigError, key: &str, origin: &str) {
    let message = error.to_string();
    assert!(
        message.contains(&format!("`{key}`")),
        "no key `{key}` in: {message}"
    );
    assert!(message.contains(origin), "no origin {origin} in: {message}");
    assert_eq!(error.key(), Some(key));
    assert_eq!(error.origin(), origin);
}

/// Every non-default value of every key, to check that each key is read and echoed.
const EVERY_KEY_CHANGED: &str = "
    filter: {variant: ermakf, coupling: loose, joseph_form: false, base: cubature, q_scaling: true}
    imu:
      gyro_arw_deg_per_sqrt_h: 0.15
      gyro_bias_deg_per_h: 3.3
      gyro_markov_sigma_deg_per_h: 1.7
      gyro_markov_correlation_time_s: 1000.5
      accel_vrw_ug_per_sqrt_hz: 57.0
      accel_bias_ug: 321.0
      accel_bias_correlation_time_s: 777.0
      gyro_range_deg_per_s: 2000.0
      accel_range_g: 16.0
      gyro_max_step_deg_per_s: 0.0
      accel_max_step_g: 8.0
      scale_factor_states: true
      gyro_scale_factor_ppm: 500.0
      accel_scale_factor_ppm: 700.0
      scale_factor_correlation_time_s: 7200.0
    mounting:
      imu_rotation_rpy_deg: [1.5, -2.25, 179.0]
      antenna_lever_arm_m: [0.31, -0.12, 1.07]
      constraint_point_lever_arm_m: [-1.2, 0.0, -0.4]
    constraints:
      zupt: true
      rate_hz: 20.0
      zupt_sigma_mps: 0.05
      zaru_sigma_deg_per_s: 0.01
      rest_accel_spread_max_mg: 15.0
      rest_gyro_spread_max_deg_per_s: 0.3
      rest_rate_max_deg_per_s: 0.2
      rest_gnss_speed_max_mps: 0.5
      platform: car
      nhc_sigma_lateral_mps: 0.2
      nhc_sigma_vertical_mps: 0.3
      nhc_yaw_rate_max_deg_per_s: 45.0
    wheel_odometry:
      enabled: true
      sigma_mps: 0.04
      scale_factor: 1.02
      scale_factor_state: true
      scale_factor_sigma: 0.02
      scale_factor_noise_per_sqrt_s: 2e-5
    dual_antenna:
      enabled: true
      baseline_m: [0.1, -1.2, 0.05]
      length_tolerance_m: 0.03
      max_sigma_deg: 2.0
      accept_float: true
      float_sigma_scale: 4.0
      gate_sigma: 6.0
    clock:
      bias_noise_m_per_sqrt_s: 0.7
      drift_noise_mps_per_sqrt_s: 0.03
      drift_correlation_time_s: 600.0
    gnss:
      elevation_mask_deg: 15.5
      cn0_mask_dbhz: 32.0
      pseudorange_sigma_m: 4.2
      pseudorange_rate_sigma_mps: 0.25
      elevation_weighting: false
      use_receiver_sigmas: true
      use_pseudorange_rate: false
      innovation_gate_sigma: 0.0
      constellations: [glonass, qzss, sbas, gps]
      clock_jump_threshold_m: 5000.0
      error_correlation: false
      error_correlation_max_inflation: 50.0
      tdcp: true
      tdcp_phase_sigma_m: 0.02
      tdcp_slip_threshold_m: 0.3
      tdcp_max_interval_s: 2.5
    loose:
      use_fix_covariance: false
      fix_sigma_horizontal_m: 2.5
      fix_sigma_vertical_m: 4.5
      velocity_sigma_mps: 0.3
      fix_outlier_sigma: 8.0
      fix_consistency: false
      leap_hold_s: 120.0
    adaptive:
      window_size_m: 60
      min_samples: 20
      random_weighting: false
      random_seed: 17
      kde_threshold: 2.5
      kde_consecutive_epochs: 4
      ar_max_order: 3
      ar_order_criterion: bic
      ar_denominator_floor: 0.2
      correlation_aware: true
      variogram_max_lag: 12
      innovation_window: 40
      innovation_significance: 0.01
      pseudorange_sigma_min_m: 0.5
      pseudorange_sigma_max_m: 90.0
      pseudorange_rate_sigma_min_mps: 0.03
      pseudorange_rate_sigma_max_mps: 5.0
      pseudorange_slow_sigma_m: 0.8
      max_epoch_gap_s: 3.0
    robust:
      adaptive_factor_function: three_segment
      adaptive_factor_c: 1.2
      adaptive_factor_c0: 1.3
      adaptive_factor_c1: 6.0
      alpha_floor: 0.05
      equivalent_weight_function: igg3
      double_factor_c: 1.1
      igg3_k0: 1.2
      igg3_k1: 4.0
      max_variance_inflation: 1000.0
      chi2_confidence: 0.99
      residual_window_epochs: 32
      q_window_epochs: 40
      q_alpha_min: 0.1
      q_alpha_max: 10.0
      q_scale_min: 0.01
      q_scale_max: 100.0
    init:
      heading_deg: -37.3
      heading_min_speed_mps: 2.0
      leveling_duration_s: 3.5
      min_satellites: 6
      attitude_sigma_deg: 2.0
      heading_sigma_deg: 20.0
      velocity_sigma_mps: 0.1
      position_sigma_m: 2.0
      clock_bias_sigma_m: 100.0
      clock_drift_sigma_mps: 1.0
    engine:
      imu_buffer_s: 5.0
      max_imu_gap_s: 0.2
    output:
      datum_llh_deg_m: [-33.8688, 151.2093, 58.2]
      rate_hz: 50.0
";

#[test]
fn every_preset_file_parses() {
    let files = preset_files();
    assert!(files.len() >= 2, "{files:?}");
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        Config::from_yaml_str(&text, &name).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn ekf_preset_is_the_built_in_default() {
    assert_eq!(load("ekf.yaml"), Config::default());
}

#[test]
fn ekf_loose_preset_differs_from_the_default_only_in_coupling() {
    let mut expected = Config::default();
    expected.filter.coupling = Coupling::Loose;
    assert_eq!(load("ekf_loose.yaml"), expected);
}

/// The variant presets differ from the default only in `filter.variant`.
#[test]
fn variant_presets_differ_from_the_default_only_in_the_variant() {
    for variant in FilterVariant::ALL {
        let name = format!("{}.yaml", variant.as_str());
        let mut expected = Config::default();
        expected.filter.variant = variant;
        assert_eq!(load(&name), expected, "{name}");
    }
}

/// The IARF paper's loose set-up: its fix variances (0.5 m)², (0.05 m/s)² (section 5).
#[test]
fn iarf_loose_preset_is_the_papers_set_up() {
    let mut expected = Config::default();
    expected.filter.variant = FilterVariant::Iarf;
    expected.filter.coupling = Coupling::Loose;
    expected.loose.fix_sigma_horizontal_m = 0.5;
    expected.loose.fix_sigma_vertical_m = 0.5;
    expected.loose.velocity_sigma_mps = 0.05;
    let config = load("iarf_loose.yaml");
    assert_eq!(config, expected);
    assert!(config.filter.uses_cubature());
}

#[test]
fn robust_constants_out_of_range_are_refused() {
    for (body, key) in [
        (
            "    robust: {adaptive_factor_c0: 2.0, adaptive_factor_c1: 1.5}\n",
            "robust.adaptive_factor_c1",
        ),
        ("    robust: {alpha_floor: 0.0}\n", "robust.alpha_floor"),
        ("    robust: {igg3_k1: 1.0}\n", "robust.igg3_k1"),
        (
            "    robust: {chi2_confidence: 1.0}\n",
            "robust.chi2_confidence",
        ),
        (
            "    robust: {q_window_epochs: 2}\n",
            "robust.q_window_epochs",
        ),
        ("    robust: {q_alpha_max: 0.5}\n", "robust.q_alpha_max"),
        ("    filter: {variant: ckf, base: ekf}\n", "filter.base"),
    ] {
        assert_names(&load_error(body), key, "test.yaml");
    }
}

/// Each preset other than the manual holds only keys whose value differs from the
/// manual's (so a preset says exactly how it differs); ekf.yaml only its variant.
#[test]
fn every_overlay_holds_only_what_differs_from_the_manual() {
    let defaults = Config::default().parameters();
    for path in preset_files() {
        if path.ends_with("defaults.yaml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let entries = adaptive_gnss_ins::config::parse_parameter_file(&text, "p").unwrap();
        assert_eq!(entries.len(), 1, "{path:?}");
        assert!(!entries[0].values.is_empty(), "{path:?}");
        // The baseline's preset states its variant, the default, and nothing else.
        if path.ends_with("ekf.yaml") {
            assert_eq!(entries[0].values.len(), 1, "{path:?}");
            assert_eq!(entries[0].values[0].0, "filter.variant", "{path:?}");
            continue;
        }
        for (name, value) in &entries[0].values {
            let (_, default) = defaults
                .iter()
                .find(|(k, _)| k == name)
                .unwrap_or_else(|| panic!("{path:?}: unknown {name}"));
            assert_ne!(
                value, default,
                "{path:?}: {name} repeats the manual's default"
            );
        }
    }
}

/// Issue 10: turning the presets into overlays keeps each one's effective configuration:
/// the full file it was (tests/data/presets_before_overlays) loads to the same
/// configuration as the manual followed by the overlay.
#[test]
fn every_overlay_over_the_manual_is_the_full_preset_it_replaced() {
    let before = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/presets_before_overlays");
    let mut compared = 0;
    for path in preset_files() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        // The IMU-class overlays (params/imu_*.yaml, issue 11) came after the overlays
        // replaced the full presets: there is no full file they replaced.
        if name == "defaults.yaml" || name == "ekf.yaml" || name.starts_with("imu_") {
            continue;
        }
        let full = std::fs::read_to_string(before.join(&name))
            .unwrap_or_else(|e| panic!("{name}: no full preset to compare with: {e}"));
        let full = Config::from_yaml_str(&full, &name).unwrap();
        assert_eq!(load(&name), full, "{name}");
        assert_ne!(full, Config::default(), "{name}");
        compared += 1;
    }
    assert_eq!(compared, 11);
}

#[test]
fn human_units_are_converted_to_si() {
    let config = Config::default();
    // 0.5 deg/h = 0.5 × 4.8481368e-6 rad/s.
    assert!((config.imu.gyro_bias_sigma_rad_s - 2.424_068_4e-6).abs() < 1e-13);
    // 0.012 deg/√h = 0.012 × π/180/60 rad/√s = 3.4906585e-6 rad/√s.
    assert!((config.imu.gyro_arw_rad_per_sqrt_s - 3.490_658_5e-6).abs() < 1e-13);
    // 100 µg/√Hz = 9.80665e-4 m/s/√s; 1250 µg = 0.0122583 m/s².
    assert!((config.imu.accel_vrw_m_s_per_sqrt_s - 9.806_65e-4).abs() < 1e-15);
    assert!((config.imu.accel_bias_sigma_m_s2 - 0.012_258_312_5).abs() < 1e-15);
    // 10° = 0.17453293 rad.
    assert!((config.gnss.elevation_mask_rad - 0.174_532_925_2).abs() < 1e-10);
    assert!((config.init.heading_sigma_rad - 0.087_266_462_6).abs() < 1e-10);
    assert_eq!(
        config.gnss.constellations,
        vec![
            Constellation::Gps,
            Constellation::Galileo,
            Constellation::Beidou
        ]
    );

    let one = Config::from_yaml_str(
        &file(
            "    imu: {gyro_bias_deg_per_h: 1.0}\n    output: {datum_llh_deg_m: [45.0, -90.0, 12.5]}\n",
        ),
        "one.yaml",
    )
    .unwrap();
    // 1 deg/h = 4.8481e-6 rad/s.
    assert!((one.imu.gyro_bias_sigma_rad_s - 4.848_1e-6).abs() < 1e-10);
    assert!((one.imu.gyro_bias_sigma_rad_s - RAD_S_PER_DEG_H).abs() < 1e-20);
    let datum = one.output.datum.unwrap();
    assert!((datum.lat_rad - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    assert!((datum.lon_rad + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(datum.height_m, 12.5);
}

#[test]
fn a_partial_file_keeps_every_other_default() {
    let config = Config::from_yaml_str(
        "/**:\n  ros__parameters:\n    gnss:\n      pseudorange_sigma_m: 2.0\n    init:\n",
        "partial.yaml",
    )
    .unwrap();
    let mut expected = Config::default();
    expected.gnss.pseudorange_sigma_m = 2.0;
    assert_eq!(config, expected);
    let empty = Config::from_yaml_str("my_node:\n  ros__parameters:\n", "empty.yaml").unwrap();
    assert_eq!(empty, Config::default());
}

#[test]
fn every_key_is_read_and_echoed_back_exactly() {
    let config = Config::from_yaml_str(&file(EVERY_KEY_CHANGED), "all.yaml").unwrap();
    let changed = config.parameters();
    let defaults = Config::default().parameters();
    assert_eq!(changed.len(), defaults.len());
    for ((key, value), (default_key, default)) in changed.iter().zip(&defaults) {
        assert_eq!(key, default_key);
        assert_ne!(value, default, "{key} was not read");
    }
    assert!((config.init.heading_rad.unwrap() + 37.3 * RAD_PER_DEG).abs() < 1e-15);

    let echo = config.to_human_yaml();
    assert!(
        echo.contains("imu_rotation_rpy_deg: [1.5, -2.25, 179.0]\n"),
        "{echo}"
    );
    assert_eq!(
        Config::from_yaml_str(&echo, "echo").unwrap(),
        config,
        "echo:\n{echo}"
    );
}

#[test]
fn a_rotation_with_many_decimals_echoes_to_within_rounding() {
    let body = "    mounting:\n      imu_rotation_rpy_deg: [0.333333333333333333, 89.9, -179.123456789012345]\n";
    let config = Config::from_yaml_str(&file(body), "rot.yaml").unwrap();
    let reparsed = Config::from_yaml_str(&config.to_human_yaml(), "echo").unwrap();
    let angle = reparsed
        .mounting
        .imu_to_body
        .angle_to(&config.mounting.imu_to_body);
    assert!(angle < 1e-12, "rotation echo off by {angle} rad");
    let mut aligned = reparsed;
    aligned.mounting.imu_to_body = config.mounting.imu_to_body;
    assert_eq!(aligned, config);
}

#[test]
fn the_echo_of_each_preset_parses_back_to_an_equal_config() {
    for name in ["ekf.yaml", "ekf_loose.yaml"] {
        let config = load(name);
        let echo = config.to_human_yaml();
        assert_eq!(
            Config::from_yaml_str(&echo, "echo").unwrap(),
            config,
            "{echo}"
        );
    }
    let echo = Config::default().to_human_yaml();
    assert!(echo.contains("/**:\n  ros__parameters:\n    filter:\n      variant: ekf\n"));
    assert!(echo.contains("      gyro_bias_deg_per_h: 0.5\n"), "{echo}");
    assert!(
        echo.contains("      constellations: [gps, galileo, beidou]\n"),
        "{echo}"
    );
    assert!(echo.contains("      heading_deg: null\n"), "{echo}");
}

#[test]
fn unknown_keys_are_refused_with_their_full_name() {
    let e = load_error("    imu:\n      gyro_bias_deg_per_hr: 0.5\n");
    assert!(matches!(e, ConfigError::UnknownKey { .. }), "{e:?}");
    assert_names(&e, "imu.gyro_bias_deg_per_hr", "test.yaml");
    assert!(
        e.to_string().contains("gyro_bias_deg_per_h"),
        "known keys listed: {e}"
    );

    let e = load_error("    imus:\n      gyro_bias_deg_per_h: 0.5\n");
    assert!(matches!(e, ConfigError::UnknownKey { .. }), "{e:?}");
    assert_names(&e, "imus.gyro_bias_deg_per_h", "test.yaml");
    assert!(
        e.to_string().contains("imu, mounting"),
        "known sections listed: {e}"
    );
}

#[test]
fn wrong_types_are_refused_with_their_full_name() {
    let cases = [
        (
            "    imu:\n      gyro_bias_deg_per_h: fast\n",
            "imu.gyro_bias_deg_per_h",
        ),
        ("    filter:\n      joseph_form: 1\n", "filter.joseph_form"),
        ("    filter:\n      variant: ukf\n", "filter.variant"),
        (
            "    init:\n      min_satellites: 5.5\n",
            "init.min_satellites",
        ),
        (
            "    mounting:\n      antenna_lever_arm_m: [0.1, 0.2]\n",
            "mounting.antenna_lever_arm_m",
        ),
        (
            "    gnss:\n      constellations: [gps, compass]\n",
            "gnss.constellations[1]",
        ),
        ("    engine: 3\n", "engine"),
    ];
    for (body, key) in cases {
        let e = load_error(body);
        assert!(matches!(e, ConfigError::WrongType { .. }), "{body}: {e:?}");
        assert_names(&e, key, "test.yaml");
    }
}

#[test]
fn out_of_range_values_are_refused_with_their_full_name() {
    let cases = [
        (
            "    imu:\n      gyro_bias_deg_per_h: -0.5\n",
            "imu.gyro_bias_deg_per_h",
        ),
        (
            "    gnss:\n      pseudorange_sigma_m: 0.0\n",
            "gnss.pseudorange_sigma_m",
        ),
        (
            "    imu:\n      accel_bias_correlation_time_s: 0\n",
            "imu.accel_bias_correlation_time_s",
        ),
        (
            "    clock:\n      drift_correlation_time_s: 0.0\n",
            "clock.drift_correlation_time_s",
        ),
        (
            "    engine:\n      imu_buffer_s: 0.0\n",
            "engine.imu_buffer_s",
        ),
        (
            "    init:\n      leveling_duration_s: .nan\n",
            "init.leveling_duration_s",
        ),
        (
            "    loose:\n      velocity_sigma_mps: .inf\n",
            "loose.velocity_sigma_mps",
        ),
        (
            "    init:\n      min_satellites: 3\n",
            "init.min_satellites",
        ),
        (
            "    gnss:\n      elevation_mask_deg: 90.0\n",
            "gnss.elevation_mask_deg",
        ),
        (
            "    gnss:\n      cn0_mask_dbhz: -1.0\n",
            "gnss.cn0_mask_dbhz",
        ),
        (
            "    gnss:\n      innovation_gate_sigma: 0.5\n",
            "gnss.innovation_gate_sigma",
        ),
        (
            "    gnss:\n      constellations: []\n",
            "gnss.constellations",
        ),
        (
            "    gnss:\n      constellations: [gps, gps]\n",
            "gnss.constellations",
        ),
        (
            "    output:\n      datum_llh_deg_m: [91.0, 0.0, 0.0]\n",
            "output.datum_llh_deg_m",
        ),
        ("    output:\n      rate_hz: -1.0\n", "output.rate_hz"),
        (
            "    mounting:\n      imu_rotation_rpy_deg: [0.0, 95.0, 0.0]\n",
            "mounting.imu_rotation_rpy_deg",
        ),
        (
            "    mounting:\n      antenna_lever_arm_m: [120.0, 0.0, 0.0]\n",
            "mounting.antenna_lever_arm_m",
        ),
        (
            "    init:\n      heading_sigma_deg: 400.0\n",
            "init.heading_sigma_deg",
        ),
    ];
    for (body, key) in cases {
        let e = load_error(body);
        assert!(matches!(e, ConfigError::Invalid { .. }), "{body}: {e:?}");
        assert_names(&e, key, "test.yaml");
    }
    let e = load_error("    imu:\n      gyro_bias_deg_per_h: -0.5\n");
    assert_eq!(
        e.to_string(),
        "test.yaml: parameter `imu.gyro_bias_deg_per_h` = -0.5: must be in [1e-9, 1e6] deg/h"
    );
}

#[test]
fn a_file_without_the_ros_layout_says_what_is_expected() {
    let bad = [
        "imu:\n  gyro_bias_deg_per_h: 0.5\n",
        "gnss_ins_node:\n  imu:\n    gyro_bias_deg_per_h: 0.5\n",
        "a:\n  ros__parameters: {}\nb:\n  ros__parameters: {}\n",
        "gnss_ins_node:\n  ros__parameters: 3\n",
        "",
        "- 1\n- 2\n",
    ];
    for text in bad {
        let e = Config::from_yaml_str(text, "layout.yaml").unwrap_err();
        assert!(matches!(e, ConfigError::Layout { .. }), "{text}: {e:?}");
        let message = e.to_string();
        assert!(message.starts_with("layout.yaml: "), "{message}");
        assert!(message.contains("ros__parameters"), "{message}");
    }
}

#[test]
fn yaml_syntax_errors_carry_line_and_column() {
    let text = file("    imu:\n      gyro_bias_deg_per_h: [0.5\n    gnss: {}\n");
    let e = Config::from_yaml_str(&text, "syntax.yaml").unwrap_err();
    match &e {
        ConfigError::Yaml { origin, line, .. } => {
            assert_eq!(origin, "syntax.yaml");
            assert!(line.is_some_and(|l| l >= 4), "{e}");
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains(" at line "), "{e}");

    let duplicate = file("    imu:\n      accel_bias_ug: 1.0\n      accel_bias_ug: 2.0\n");
    let e = Config::from_yaml_str(&duplicate, "dup.yaml").unwrap_err();
    // The parser points at the start of the mapping that holds the duplicate (line 4).
    assert!(
        matches!(e, ConfigError::Yaml { line: Some(4), .. }),
        "{e:?}"
    );
    assert!(e.to_string().contains("accel_bias_ug"), "{e}");
}

#[test]
fn set_parameter_applies_and_validates() {
    let mut config = Config::default();
    config
        .set_parameter("imu.gyro_bias_deg_per_h", "0.3")
        .unwrap();
    assert_eq!(config.imu.gyro_bias_sigma_rad_s, 0.3 * RAD_S_PER_DEG_H);
    config.set_parameter("filter.coupling", "loose").unwrap();
    config.set_parameter("init.heading_deg", "90").unwrap();
    assert_eq!(config.filter.coupling, Coupling::Loose);
    assert!((config.init.heading_rad.unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let listed = config.parameters();
    let value = |key: &str| listed.iter().find(|(k, _)| k == key).unwrap().1.clone();
    assert_eq!(value("imu.gyro_bias_deg_per_h"), Value::from(0.3));
    assert_eq!(value("filter.coupling"), Value::from("loose"));
    assert_eq!(value("init.heading_deg"), Value::from(90.0));

    let mut expected = Config::default();
    expected.imu.gyro_bias_sigma_rad_s = 0.3 * RAD_S_PER_DEG_H;
    expected.filter.coupling = Coupling::Loose;
    expected.init.heading_rad = Some(90.0 * RAD_PER_DEG);
    assert_eq!(config, expected);

    let before = config.clone();
    let cases = [
        ("imu.gyro_bias_deg_per_h", "-1", "imu.gyro_bias_deg_per_h"),
        ("imu.gyro_bias_deg_per_h", "abc", "imu.gyro_bias_deg_per_h"),
        ("imu.gyro_bias_deg_per_hr", "1", "imu.gyro_bias_deg_per_hr"),
        ("imu", "1", "imu"),
        (
            "inertial.gyro_bias_deg_per_h",
            "1",
            "inertial.gyro_bias_deg_per_h",
        ),
        ("init.min_satellites", "2", "init.min_satellites"),
    ];
    for (key, value, named) in cases {
        let e = config.set_parameter(key, value).unwrap_err();
        assert_names(&e, named, PARAMETER_OVERRIDE_ORIGIN);
        assert_eq!(config, before, "{key} = {value} changed the configuration");
    }
    let e = config
        .set_parameter("imu.gyro_bias_deg_per_h", "[1,")
        .unwrap_err();
    assert!(matches!(e, ConfigError::Yaml { .. }), "{e:?}");
    assert_eq!(config, before);
}

/// Issue 12 items 1-3, 6, 9 and 12: counts, windows and orders have an upper bound,
/// physical quantities a physical range, and a configuration that can never start names
/// the parameter that prevents it; each is refused at load, naming the key.
#[test]
fn absurd_values_are_refused_naming_the_key() {
    for (section, key, value) in [
        ("adaptive", "window_size_m", "18446744073709551615"),
        ("adaptive", "ar_max_order", "18446744073709551614"),
        ("adaptive", "window_size_m", "1000000000"),
        ("adaptive", "innovation_window", "1000000000"),
        ("robust", "residual_window_epochs", "1000000000"),
        ("robust", "q_window_epochs", "1000000000"),
        ("init", "position_sigma_m", "1e300"),
        ("imu", "gyro_bias_deg_per_h", "1e300"),
        ("imu", "gyro_markov_correlation_time_s", "1e-300"),
        ("init", "min_satellites", "1000"),
        ("engine", "max_imu_gap_s", "1e-300"),
        ("engine", "imu_buffer_s", "1e300"),
    ] {
        let body = format!("    {section}:\n      {key}: {value}\n");
        let e = load_error(&body);
        assert!(matches!(e, ConfigError::Invalid { .. }), "{body}: {e:?}");
        assert_names(&e, &format!("{section}.{key}"), "test.yaml");
    }
    // The largest AR order with the smallest window it needs loads (no overflow anywhere).
    let body = "    adaptive: {ar_max_order: 100, min_samples: 102, window_size_m: 10000}\n";
    assert!(Config::from_yaml_str(&file(body), "t").is_ok());
    let e = load_error("    adaptive: {ar_max_order: 100, min_samples: 30}\n");
    assert_names(&e, "adaptive.min_samples", "test.yaml");
}

/// Issue 12 item 5: an error quotes at most a short prefix of a value or a key.
#[test]
fn a_huge_value_or_key_is_quoted_by_a_short_prefix() {
    let huge = "x".repeat(200_000);
    for (body, quoted) in [
        (
            format!("    imu:\n      gyro_bias_deg_per_h: {huge}\n"),
            true,
        ),
        (
            format!("    gnss:\n      constellations: [gps, {huge}]\n"),
            true,
        ),
        (format!("    imu:\n      ? {huge}\n      : 1.0\n"), true),
        // YAML itself refuses a plain key of more than 1024 characters.
        (format!("    imu:\n      {huge}: 1.0\n"), false),
    ] {
        let e = load_error(&body).to_string();
        assert!(e.len() < 600, "{} bytes: {}...", e.len(), &e[..200]);
        assert_eq!(e.contains(" bytes)"), quoted, "{e}");
    }
}

/// Issue 12 item 5: size and nesting are checked before the YAML parser sees the text,
/// so 500,000 nested `[` are refused at once instead of hanging the loader.
#[test]
fn deep_or_large_files_are_refused_before_parsing() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let deep = format!("/**:\n  ros__parameters:\n    a: {}", "[".repeat(500_000));
        let _ = tx.send(Config::from_yaml_str(&deep, "deep.yaml"));
    });
    // The timeout only keeps a regression from hanging the test suite.
    let result = rx
        .recv_timeout(std::time::Duration::from_secs(120))
        .expect("loading 500,000 nested brackets hangs");
    let e = result.unwrap_err();
    assert!(matches!(e, ConfigError::TooDeep { line: 3, .. }), "{e}");
    assert!(e.to_string().contains("deep.yaml"), "{e}");

    let large = file(&format!("    # {}\n", "x".repeat(2 << 20)));
    let e = Config::from_yaml_str(&large, "large.yaml").unwrap_err();
    assert!(matches!(e, ConfigError::TooLarge { .. }), "{e}");
    // A file of 64 levels is parsed (and refused for what it holds, not for its depth).
    let nested = format!(
        "/**:\n  ros__parameters:\n    a: {}1{}\n",
        "[".repeat(61),
        "]".repeat(61)
    );
    let e = Config::from_yaml_str(&nested, "ok.yaml").unwrap_err();
    assert!(matches!(e, ConfigError::UnknownKey { .. }), "{e}");
}
