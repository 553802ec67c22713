//! The raw configuration as a YAML tree (section -> key -> value, human units), the form
//! that is echoed, listed as ROS parameters and edited by one dotted key.

use serde_yaml::{Mapping, Value};

use super::raw::RawConfig;

impl RawConfig {
    /// The parameters as a YAML tree, section -> key -> value, in file order. This is the
    /// inverse of deserialisation (tested), written out so that it cannot fail.
    pub fn to_tree(&self) -> Mapping {
        let f = &self.filter;
        let i = &self.imu;
        let m = &self.mounting;
        let c = &self.clock;
        let g = &self.gnss;
        let l = &self.loose;
        let a = &self.adaptive;
        let r = &self.robust;
        let n = &self.init;
        let e = &self.engine;
        let o = &self.output;
        let constellations = g.constellations.iter().map(|c| text(c.as_str())).collect();
        let sections = [
            (
                "filter",
                vec![
                    ("variant", text(f.variant.as_str())),
                    ("coupling", text(f.coupling.as_str())),
                    ("joseph_form", Value::Bool(f.joseph_form)),
                    ("base", text(f.base.as_str())),
                    ("q_scaling", Value::Bool(f.q_scaling)),
                ],
            ),
            (
                "imu",
                vec![
                    ("gyro_arw_deg_per_sqrt_h", num(i.gyro_arw_deg_per_sqrt_h)),
                    ("gyro_bias_deg_per_h", num(i.gyro_bias_deg_per_h)),
                    (
                        "gyro_markov_sigma_deg_per_h",
                        num(i.gyro_markov_sigma_deg_per_h),
                    ),
                    (
                        "gyro_markov_correlation_time_s",
                        num(i.gyro_markov_correlation_time_s),
                    ),
                    ("accel_vrw_ug_per_sqrt_hz", num(i.accel_vrw_ug_per_sqrt_hz)),
                    ("accel_bias_ug", num(i.accel_bias_ug)),
                    (
                        "accel_bias_correlation_time_s",
                        num(i.accel_bias_correlation_time_s),
                    ),
                ],
            ),
            (
                "mounting",
                vec![
                    ("imu_rotation_rpy_deg", triple(&m.imu_rotation_rpy_deg)),
                    ("antenna_lever_arm_m", triple(&m.antenna_lever_arm_m)),
                ],
            ),
            (
                "clock",
                vec![
                    ("bias_noise_m_per_sqrt_s", num(c.bias_noise_m_per_sqrt_s)),
                    (
                        "drift_noise_mps_per_sqrt_s",
                        num(c.drift_noise_mps_per_sqrt_s),
                    ),
                    ("drift_correlation_time_s", num(c.drift_correlation_time_s)),
                ],
            ),
            (
                "gnss",
                vec![
                    ("elevation_mask_deg", num(g.elevation_mask_deg)),
                    ("cn0_mask_dbhz", num(g.cn0_mask_dbhz)),
                    ("pseudorange_sigma_m", num(g.pseudorange_sigma_m)),
                    (
                        "pseudorange_rate_sigma_mps",
                        num(g.pseudorange_rate_sigma_mps),
                    ),
                    ("elevation_weighting", Value::Bool(g.elevation_weighting)),
                    ("use_receiver_sigmas", Value::Bool(g.use_receiver_sigmas)),
                    ("use_pseudorange_rate", Value::Bool(g.use_pseudorange_rate)),
                    ("innovation_gate_sigma", num(g.innovation_gate_sigma)),
                    ("constellations", Value::Sequence(constellations)),
                    ("clock_jump_threshold_m", num(g.clock_jump_threshold_m)),
                ],
            ),
            (
                "loose",
                vec![
                    ("use_fix_covariance", Value::Bool(l.use_fix_covariance)),
                    ("fix_sigma_horizontal_m", num(l.fix_sigma_horizontal_m)),
                    ("fix_sigma_vertical_m", num(l.fix_sigma_vertical_m)),
                    ("velocity_sigma_mps", num(l.velocity_sigma_mps)),
                ],
            ),
            (
                "adaptive",
                vec![
                    ("window_size_m", Value::from(a.window_size_m)),
                    ("min_samples", Value::from(a.min_samples)),
                    ("random_weighting", Value::Bool(a.random_weighting)),
                    ("random_seed", Value::from(a.random_seed)),
                    ("kde_threshold", num(a.kde_threshold)),
                    (
                        "kde_consecutive_epochs",
                        Value::from(a.kde_consecutive_epochs),
                    ),
                    ("ar_max_order", Value::from(a.ar_max_order)),
                    ("ar_order_criterion", text(a.ar_order_criterion.as_str())),
                    ("ar_denominator_floor", num(a.ar_denominator_floor)),
                    ("innovation_window", Value::from(a.innovation_window)),
                    ("innovation_significance", num(a.innovation_significance)),
                    ("pseudorange_sigma_min_m", num(a.pseudorange_sigma_min_m)),
                    ("pseudorange_sigma_max_m", num(a.pseudorange_sigma_max_m)),
                    (
                        "pseudorange_rate_sigma_min_mps",
                        num(a.pseudorange_rate_sigma_min_mps),
                    ),
                    (
                        "pseudorange_rate_sigma_max_mps",
                        num(a.pseudorange_rate_sigma_max_mps),
                    ),
                    ("max_epoch_gap_s", num(a.max_epoch_gap_s)),
                ],
            ),
            (
                "robust",
                vec![
                    (
                        "adaptive_factor_function",
                        text(r.adaptive_factor_function.as_str()),
                    ),
                    ("adaptive_factor_c", num(r.adaptive_factor_c)),
                    ("adaptive_factor_c0", num(r.adaptive_factor_c0)),
                    ("adaptive_factor_c1", num(r.adaptive_factor_c1)),
                    ("alpha_floor", num(r.alpha_floor)),
                    (
                        "equivalent_weight_function",
                        text(r.equivalent_weight_function.as_str()),
                    ),
                    ("double_factor_c", num(r.double_factor_c)),
                    ("igg3_k0", num(r.igg3_k0)),
                    ("igg3_k1", num(r.igg3_k1)),
                    ("max_variance_inflation", num(r.max_variance_inflation)),
                    ("chi2_confidence", num(r.chi2_confidence)),
                    (
                        "residual_window_epochs",
                        Value::from(r.residual_window_epochs),
                    ),
                    ("q_window_epochs", Value::from(r.q_window_epochs)),
                    ("q_alpha_min", num(r.q_alpha_min)),
                    ("q_alpha_max", num(r.q_alpha_max)),
                    ("q_scale_min", num(r.q_scale_min)),
                    ("q_scale_max", num(r.q_scale_max)),
                ],
            ),
            (
                "init",
                vec![
                    ("heading_deg", n.heading_deg.map_or(Value::Null, num)),
                    ("heading_min_speed_mps", num(n.heading_min_speed_mps)),
                    ("leveling_duration_s", num(n.leveling_duration_s)),
                    ("min_satellites", Value::from(n.min_satellites)),
                    ("attitude_sigma_deg", num(n.attitude_sigma_deg)),
                    ("heading_sigma_deg", num(n.heading_sigma_deg)),
                    ("velocity_sigma_mps", num(n.velocity_sigma_mps)),
                    ("position_sigma_m", num(n.position_sigma_m)),
                    ("clock_bias_sigma_m", num(n.clock_bias_sigma_m)),
                    ("clock_drift_sigma_mps", num(n.clock_drift_sigma_mps)),
                ],
            ),
            (
                "engine",
                vec![
                    ("imu_buffer_s", num(e.imu_buffer_s)),
                    ("max_imu_gap_s", num(e.max_imu_gap_s)),
                ],
            ),
            (
                "output",
                vec![
                    (
                        "datum_llh_deg_m",
                        o.datum_llh_deg_m.as_ref().map_or(Value::Null, triple),
                    ),
                    ("rate_hz", num(o.rate_hz)),
                ],
            ),
        ];
        sections
            .into_iter()
            .map(|(section, keys)| {
                let keys = keys.into_iter().map(|(k, v)| (text(k), v)).collect();
                (text(section), Value::Mapping(keys))
            })
            .collect()
    }
}

fn num(x: f64) -> Value {
    Value::from(x)
}

fn text(s: &str) -> Value {
    Value::String(s.to_owned())
}

fn triple(v: &[f64; 3]) -> Value {
    Value::Sequence(v.iter().copied().map(num).collect())
}
