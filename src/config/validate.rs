//! Range checks on the human-unit values, so that the message quotes the value as the user
//! wrote it. The first offending key is reported; nothing is applied.
//!
//! Zero is accepted only where the documentation gives it a meaning ("0 = off"):
//! `gnss.cn0_mask_dbhz`, `gnss.innovation_gate_sigma`, `gnss.elevation_mask_deg`
//! (horizon), `output.rate_hz`, and the mounting angles and lever arm.

use super::raw::RawConfig;
use super::{ConfigError, FilterBase, FilterVariant};

/// Checks every value of `raw`; `origin` names the file in the error.
pub fn validate(raw: &RawConfig, origin: &str) -> Result<(), ConfigError> {
    let c = Checker { origin };

    let imu = &raw.imu;
    c.positive("imu.gyro_arw_deg_per_sqrt_h", imu.gyro_arw_deg_per_sqrt_h)?;
    c.positive("imu.gyro_bias_deg_per_h", imu.gyro_bias_deg_per_h)?;
    c.positive(
        "imu.gyro_markov_sigma_deg_per_h",
        imu.gyro_markov_sigma_deg_per_h,
    )?;
    c.positive(
        "imu.gyro_markov_correlation_time_s",
        imu.gyro_markov_correlation_time_s,
    )?;
    c.positive("imu.accel_vrw_ug_per_sqrt_hz", imu.accel_vrw_ug_per_sqrt_hz)?;
    c.positive("imu.accel_bias_ug", imu.accel_bias_ug)?;
    c.positive(
        "imu.accel_bias_correlation_time_s",
        imu.accel_bias_correlation_time_s,
    )?;

    let [roll, pitch, yaw] = raw.mounting.imu_rotation_rpy_deg;
    let key = "mounting.imu_rotation_rpy_deg";
    c.within(key, roll, -180.0, 180.0, "roll must lie in [-180, 180] deg")?;
    c.within(key, pitch, -90.0, 90.0, "pitch must lie in [-90, 90] deg")?;
    c.within(key, yaw, -180.0, 180.0, "yaw must lie in [-180, 180] deg")?;
    // Choice: a lever arm beyond 100 m is taken as a unit mistake (cm or mm written as m).
    for x in raw.mounting.antenna_lever_arm_m {
        c.within(
            "mounting.antenna_lever_arm_m",
            x,
            -MAX_LEVER_ARM_M,
            MAX_LEVER_ARM_M,
            "each component must lie in [-100, 100] m",
        )?;
    }

    let clock = &raw.clock;
    c.positive(
        "clock.bias_noise_m_per_sqrt_s",
        clock.bias_noise_m_per_sqrt_s,
    )?;
    c.positive(
        "clock.drift_noise_mps_per_sqrt_s",
        clock.drift_noise_mps_per_sqrt_s,
    )?;
    c.positive(
        "clock.drift_correlation_time_s",
        clock.drift_correlation_time_s,
    )?;

    let gnss = &raw.gnss;
    let mask = gnss.elevation_mask_deg;
    if !(mask.is_finite() && (0.0..90.0).contains(&mask)) {
        return Err(c.invalid("gnss.elevation_mask_deg", mask, "must lie in [0, 90) deg"));
    }
    c.within(
        "gnss.cn0_mask_dbhz",
        gnss.cn0_mask_dbhz,
        0.0,
        100.0,
        "must lie in [0, 100] dB-Hz (0 = off)",
    )?;
    c.positive("gnss.pseudorange_sigma_m", gnss.pseudorange_sigma_m)?;
    c.positive(
        "gnss.pseudorange_rate_sigma_mps",
        gnss.pseudorange_rate_sigma_mps,
    )?;
    // Choice: a gate below 1σ would reject most good measurements; 0 switches gating off.
    let gate = gnss.innovation_gate_sigma;
    if !(gate.is_finite() && (gate == 0.0 || gate >= 1.0)) {
        return Err(c.invalid(
            "gnss.innovation_gate_sigma",
            gate,
            "must be 0 (off) or >= 1",
        ));
    }
    validate_constellations(raw, &c)?;
    c.positive("gnss.clock_jump_threshold_m", gnss.clock_jump_threshold_m)?;

    let loose = &raw.loose;
    c.positive("loose.fix_sigma_horizontal_m", loose.fix_sigma_horizontal_m)?;
    c.positive("loose.fix_sigma_vertical_m", loose.fix_sigma_vertical_m)?;
    c.positive("loose.velocity_sigma_mps", loose.velocity_sigma_mps)?;

    validate_adaptive(raw, &c)?;
    validate_robust(raw, &c)?;

    let init = &raw.init;
    if let Some(heading) = init.heading_deg {
        c.within(
            "init.heading_deg",
            heading,
            -360.0,
            360.0,
            "must lie in [-360, 360] deg, or be null",
        )?;
    }
    c.positive("init.heading_min_speed_mps", init.heading_min_speed_mps)?;
    c.positive("init.leveling_duration_s", init.leveling_duration_s)?;
    if init.min_satellites < 4 {
        return Err(ConfigError::Invalid {
            origin: origin.to_owned(),
            key: "init.min_satellites".to_owned(),
            value: init.min_satellites.to_string(),
            reason: "a single-point solution needs at least 4 satellites".to_owned(),
        });
    }
    c.angle_sigma("init.attitude_sigma_deg", init.attitude_sigma_deg)?;
    c.angle_sigma("init.heading_sigma_deg", init.heading_sigma_deg)?;
    c.positive("init.velocity_sigma_mps", init.velocity_sigma_mps)?;
    c.positive("init.position_sigma_m", init.position_sigma_m)?;
    c.positive("init.clock_bias_sigma_m", init.clock_bias_sigma_m)?;
    c.positive("init.clock_drift_sigma_mps", init.clock_drift_sigma_mps)?;

    c.positive("engine.imu_buffer_s", raw.engine.imu_buffer_s)?;
    c.positive("engine.max_imu_gap_s", raw.engine.max_imu_gap_s)?;

    if let Some([lat, lon, height]) = raw.output.datum_llh_deg_m {
        let key = "output.datum_llh_deg_m";
        c.within(key, lat, -90.0, 90.0, "latitude must lie in [-90, 90] deg")?;
        c.within(
            key,
            lon,
            -180.0,
            180.0,
            "longitude must lie in [-180, 180] deg",
        )?;
        if !height.is_finite() {
            return Err(c.invalid(key, height, "height must be finite"));
        }
    }
    c.within(
        "output.rate_hz",
        raw.output.rate_hz,
        0.0,
        f64::MAX,
        "must be >= 0 Hz (0 = every IMU sample)",
    )?;
    Ok(())
}

/// Largest accepted lever-arm component (m).
const MAX_LEVER_ARM_M: f64 = 100.0;

fn validate_adaptive(raw: &RawConfig, c: &Checker) -> Result<(), ConfigError> {
    let a = &raw.adaptive;
    let count = |key: &str, value: usize, min: usize| {
        if value < min {
            Err(c.invalid(key, value as f64, &format!("must be at least {min}")))
        } else {
            Ok(())
        }
    };
    // Choice: a KDE or AR fit on fewer than 10 samples is noise (DESIGN.md pitfalls), and
    // the AR fit needs the order plus two samples.
    count("adaptive.window_size_m", a.window_size_m, 10)?;
    count("adaptive.ar_max_order", a.ar_max_order, 1)?;
    count(
        "adaptive.min_samples",
        a.min_samples,
        (a.ar_max_order + 2).max(10),
    )?;
    if a.min_samples > a.window_size_m {
        return Err(c.invalid(
            "adaptive.min_samples",
            a.min_samples as f64,
            "must not exceed adaptive.window_size_m",
        ));
    }
    count(
        "adaptive.kde_consecutive_epochs",
        a.kde_consecutive_epochs,
        1,
    )?;
    count("adaptive.innovation_window", a.innovation_window, 10)?;
    c.positive("adaptive.kde_threshold", a.kde_threshold)?;
    c.within(
        "adaptive.ar_denominator_floor",
        a.ar_denominator_floor,
        1e-3,
        1.0,
        "must be within [0.001, 1]",
    )?;
    c.within(
        "adaptive.innovation_significance",
        a.innovation_significance,
        1e-6,
        0.5,
        "must be within [1e-6, 0.5]",
    )?;
    c.positive(
        "adaptive.pseudorange_sigma_min_m",
        a.pseudorange_sigma_min_m,
    )?;
    c.positive(
        "adaptive.pseudorange_rate_sigma_min_mps",
        a.pseudorange_rate_sigma_min_mps,
    )?;
    c.positive("adaptive.max_epoch_gap_s", a.max_epoch_gap_s)?;
    for (key, min, max) in [
        (
            "adaptive.pseudorange_sigma_max_m",
            a.pseudorange_sigma_min_m,
            a.pseudorange_sigma_max_m,
        ),
        (
            "adaptive.pseudorange_rate_sigma_max_mps",
            a.pseudorange_rate_sigma_min_mps,
            a.pseudorange_rate_sigma_max_mps,
        ),
    ] {
        if !(max.is_finite() && max >= min) {
            return Err(c.invalid(key, max, "must be finite and at least the minimum"));
        }
    }
    Ok(())
}

fn validate_robust(raw: &RawConfig, c: &Checker) -> Result<(), ConfigError> {
    let f = &raw.filter;
    if f.base == FilterBase::Ekf && f.variant == FilterVariant::Ckf {
        return Err(ConfigError::Invalid {
            origin: c.origin.to_owned(),
            key: "filter.base".to_owned(),
            value: "ekf".to_owned(),
            reason: "variant ckf is the cubature filter; use variant ekf for the EKF".to_owned(),
        });
    }
    let r = &raw.robust;
    c.positive("robust.adaptive_factor_c", r.adaptive_factor_c)?;
    c.positive("robust.adaptive_factor_c0", r.adaptive_factor_c0)?;
    c.above(
        "robust.adaptive_factor_c1",
        r.adaptive_factor_c1,
        "robust.adaptive_factor_c0",
        r.adaptive_factor_c0,
    )?;
    if !(r.alpha_floor.is_finite() && r.alpha_floor > 0.0 && r.alpha_floor <= 1.0) {
        return Err(c.invalid("robust.alpha_floor", r.alpha_floor, "must lie in (0, 1]"));
    }
    c.positive("robust.double_factor_c", r.double_factor_c)?;
    c.positive("robust.igg3_k0", r.igg3_k0)?;
    c.above("robust.igg3_k1", r.igg3_k1, "robust.igg3_k0", r.igg3_k0)?;
    c.within(
        "robust.max_variance_inflation",
        r.max_variance_inflation,
        1.0,
        1e12,
        "must lie in [1, 1e12]",
    )?;
    // Choice: a confidence below one half would raise alarms on most healthy epochs.
    if !(r.chi2_confidence.is_finite() && r.chi2_confidence >= 0.5 && r.chi2_confidence < 1.0) {
        return Err(c.invalid(
            "robust.chi2_confidence",
            r.chi2_confidence,
            "must lie in [0.5, 1)",
        ));
    }
    // Choice: a second moment from fewer than 5 epochs is noise (spread above 60 %).
    for (key, value) in [
        ("robust.residual_window_epochs", r.residual_window_epochs),
        ("robust.q_window_epochs", r.q_window_epochs),
    ] {
        if value < 5 {
            return Err(c.invalid(key, value as f64, "must be at least 5"));
        }
    }
    for (key, value) in [
        ("robust.q_alpha_min", r.q_alpha_min),
        ("robust.q_scale_min", r.q_scale_min),
    ] {
        if !(value.is_finite() && value > 0.0 && value <= 1.0) {
            return Err(c.invalid(key, value, "must lie in (0, 1]"));
        }
    }
    for (key, value) in [
        ("robust.q_alpha_max", r.q_alpha_max),
        ("robust.q_scale_max", r.q_scale_max),
    ] {
        c.within(key, value, 1.0, 1e12, "must lie in [1, 1e12]")?;
    }
    Ok(())
}

fn validate_constellations(raw: &RawConfig, c: &Checker) -> Result<(), ConfigError> {
    let names = &raw.gnss.constellations;
    let listed = || {
        let names: Vec<&str> = names.iter().map(|n| n.as_str()).collect();
        format!("[{}]", names.join(", "))
    };
    let reason = if names.is_empty() {
        "at least one constellation is needed"
    } else if names
        .iter()
        .enumerate()
        .any(|(i, n)| names.iter().take(i).any(|earlier| earlier == n))
    {
        "each constellation may be listed only once"
    } else {
        return Ok(());
    };
    Err(ConfigError::Invalid {
        origin: c.origin.to_owned(),
        key: "gnss.constellations".to_owned(),
        value: listed(),
        reason: reason.to_owned(),
    })
}

struct Checker<'a> {
    origin: &'a str,
}

impl Checker<'_> {
    fn invalid(&self, key: &str, value: f64, reason: &str) -> ConfigError {
        ConfigError::Invalid {
            origin: self.origin.to_owned(),
            key: key.to_owned(),
            value: format!("{value:?}"),
            reason: reason.to_owned(),
        }
    }

    /// A finite value > 0 (σ, noise density, correlation time, duration).
    fn positive(&self, key: &str, value: f64) -> Result<(), ConfigError> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(self.invalid(key, value, "must be finite and > 0"))
        }
    }

    /// A finite value above `lower`, the value of the key `lower_key` (an upper threshold
    /// above its lower one).
    fn above(&self, key: &str, value: f64, lower_key: &str, lower: f64) -> Result<(), ConfigError> {
        if value.is_finite() && value > lower {
            Ok(())
        } else {
            Err(self.invalid(key, value, &format!("must be finite and > {lower_key}")))
        }
    }

    /// A finite value in [lo, hi].
    fn within(
        &self,
        key: &str,
        value: f64,
        lo: f64,
        hi: f64,
        reason: &str,
    ) -> Result<(), ConfigError> {
        if value.is_finite() && (lo..=hi).contains(&value) {
            Ok(())
        } else {
            Err(self.invalid(key, value, reason))
        }
    }

    /// An angular 1σ in (0, 180] deg.
    fn angle_sigma(&self, key: &str, value: f64) -> Result<(), ConfigError> {
        if value.is_finite() && value > 0.0 && value <= 180.0 {
            Ok(())
        } else {
            Err(self.invalid(key, value, "must lie in (0, 180] deg"))
        }
    }
}
