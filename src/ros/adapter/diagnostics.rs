//! The adapter's /diagnostics report.

use crate::config::Config;
use crate::engine::{FilterState, Hold};
use crate::ins::error_state::{ACC_SCALE, GYRO_SCALE, WHEEL_SCALE};
use crate::ros::msg::{DiagnosticArray, DiagnosticStatus, Header, KeyValue, Time};

use super::RosAdapter;

impl RosAdapter {
    /// The /diagnostics report at `stamp`: input counts, constraint updates by kind, fix
    /// positions and velocities deweighted as outliers, rejections by reason, resets after
    /// a divergence, measurements applied late (`late_measurements`), with `gnss.tdcp` the
    /// phase changes used and left out by reason, phase and, in `tf_mode` `map_to_odom`
    /// the `odom → base` transforms heard and the Odometry messages without a
    /// `map → odom`, once running, the filter's 3D position sigma
    /// (level ERROR when it is not finite) and the scale factors it estimates; level ERROR
    /// from a divergence until the filter runs again, WARN while initializing, while the
    /// heading is split into hypotheses (its σ beyond the filter's linear range), while
    /// GNSS and filter are in a dispute (`gnss_dispute_m`: the GNSS leapt from the filter
    /// without the IMU's support, and the published covariance is widened by the offset;
    /// the message says whether the receiver's fixes are held back by the leap) or while a
    /// second frame sends on `imu`.
    pub fn diagnostics(&self, node_name: &str, stamp: Time) -> DiagnosticArray {
        let hypotheses = self.engine.heading_hypotheses();
        let phase = match (self.engine.init_phase(), hypotheses) {
            (Some(p), _) => format!("initializing ({p:?})"),
            (None, 0) => "running".to_owned(),
            (None, n) => format!("running, heading split into {n} hypotheses"),
        };
        let mut values = vec![
            key_value("variant", self.engine.variant_name().to_owned()),
            key_value("phase", phase.clone()),
            key_value("imu_frame", self.imu_frame.locked().to_owned()),
        ];
        for (key, n) in self.counts.named() {
            values.push(key_value(&key, n.to_string()));
            if key == "velocity_paired" {
                let unpaired = self.unpaired_velocities().to_string();
                values.push(key_value("unpaired_velocity", unpaired));
            }
        }
        let updates = self.engine.constraint_updates();
        let outliers = self.engine.deweighted();
        for (key, n) in [
            ("updates_zero_velocity", updates.zero_velocity),
            ("updates_zero_rate", updates.zero_rate),
            ("updates_non_holonomic", updates.non_holonomic),
            ("fix_position_outliers", outliers.position),
            ("fix_velocity_outliers", outliers.velocity),
            ("fix_position_rescaled", outliers.position_rescaled),
            ("fix_velocity_rescaled", outliers.velocity_rescaled),
            ("fix_leap_held", outliers.held_back),
            ("correlated_measurements", outliers.correlated),
        ] {
            values.push(key_value(key, n.to_string()));
        }
        if self.engine.config().gnss.tdcp {
            for (key, n) in self.phases.named() {
                values.push(key_value(&key, n.to_string()));
            }
        }
        if let Some(odom) = self.odom_tf_counts() {
            values.push(key_value("odom_tf_received", odom.received.to_string()));
            values.push(key_value("odom_tf_unusable", odom.unusable.to_string()));
            let missing = odom.map_to_odom_missing.to_string();
            values.push(key_value("map_to_odom_missing", missing));
        }
        values.extend(self.engine.counters().iter().map(|(reason, n)| KeyValue {
            key: format!("rejected_{}", reason.name()),
            value: n.to_string(),
        }));
        values.push(key_value(
            "divergence_resets",
            self.engine.divergence_resets().to_string(),
        ));
        values.push(key_value(
            "late_measurements",
            self.engine.late_measurements().to_string(),
        ));
        let dispute_m = self.engine.gnss_dispute_offset_enu_m().map(|o| o.norm());
        values.push(key_value(
            "gnss_dispute_m",
            dispute_m.map_or("none".to_owned(), |m| format!("{m:.1}")),
        ));
        let (level, message) = match (self.engine.state(), self.engine.diverged_at_t_s()) {
            (None, Some(t_s)) => (
                DiagnosticStatus::ERROR,
                format!(
                    "the filter diverged from GNSS at t = {t_s:.3} s; no solution while it re-initializes ({phase})"
                ),
            ),
            (None, None) => (
                DiagnosticStatus::WARN,
                self.imu_frame_conflict().unwrap_or(phase),
            ),
            (Some(state), _) => {
                let solution = (self.engine.published_solution()).unwrap_or_else(|| state.solution());
                let trace_m2 = solution.position_covariance_enu_m2().trace();
                let sigma_m = sigma_of_variance(trace_m2);
                values.push(key_value("position_sigma_3d_m", format!("{sigma_m:.3}")));
                let (floor_m2, _) = self.engine.unclaimed_covariances();
                let floor_m = sigma_of_variance(floor_m2.trace());
                values.push(key_value("unclaimed_sigma_3d_m", format!("{floor_m:.3}")));
                values.extend(scale_factor_values(state, self.engine.config()));
                if !sigma_m.is_finite() {
                    (
                        DiagnosticStatus::ERROR,
                        "filter covariance is not finite and positive".to_owned(),
                    )
                } else if let Some(conflict) = self.imu_frame_conflict() {
                    (DiagnosticStatus::WARN, conflict)
                } else if let Some(dispute_m) = dispute_m {
                    let held = match self.engine.fix_hold() {
                        None => "",
                        Some(Hold::LeftOut { .. }) => {
                            "; the fixes are left out until the leap is confirmed"
                        }
                        Some(Hold::MovedBack { .. }) => {
                            "; the fixes are held back: moved back by the leap, their covariance grown by its uncertainty"
                        }
                    };
                    (
                        DiagnosticStatus::WARN,
                        format!(
                            "{phase}; GNSS leapt {dispute_m:.1} m from the filter without the IMU's support: one of them is wrong, position covariance widened by it{held}"
                        ),
                    )
                } else if hypotheses > 0 {
                    (DiagnosticStatus::WARN, phase)
                } else {
                    (DiagnosticStatus::OK, phase)
                }
            }
        };
        DiagnosticArray {
            header: Header {
                stamp,
                frame_id: String::new(),
            },
            status: vec![DiagnosticStatus {
                level,
                name: format!("{node_name}: filter"),
                message,
                hardware_id: String::new(),
                values,
            }],
        }
    }

    /// The message telling that another frame sent on `imu` lately, if one did.
    fn imu_frame_conflict(&self) -> Option<String> {
        self.imu_frame.conflict().map(|other| {
            format!(
                "imu: messages from frame `{other}` besides the followed `{}` (a second publisher?)",
                self.imu_frame.locked()
            )
        })
    }
}

/// The σ of a variance (the 3D position σ of the trace of the position covariance): NaN
/// when the variance is NaN, infinite or negative, so that a broken covariance reports
/// ERROR instead of a σ of zero (`NaN.max(0.0)` is 0).
fn sigma_of_variance(variance: f64) -> f64 {
    if variance >= 0.0 && variance.is_finite() {
        variance.sqrt()
    } else {
        f64::NAN
    }
}

/// The scale factors the filter estimates, each with its σ: the wheel odometry's with
/// `wheel_odometry.scale_factor_state`, the gyro's and accelerometer's errors (ppm, per
/// body axis) with `imu.scale_factor_states`; none otherwise.
fn scale_factor_values(state: &FilterState, config: &Config) -> Vec<KeyValue> {
    let sigma = |i: usize| sigma_of_variance(state.p[(i, i)]);
    let mut values = Vec::new();
    if config.wheel_odometry.scale_factor_state {
        let (factor, factor_sigma) = (state.wheel_scale_factor, sigma(WHEEL_SCALE));
        values.push(key_value("wheel_scale_factor", format!("{factor:.5}")));
        values.push(key_value(
            "wheel_scale_factor_sigma",
            format!("{factor_sigma:.5}"),
        ));
    }
    if config.imu.scale_factor_states {
        for (name, error, first) in [
            ("gyro", state.gyro_scale_error, GYRO_SCALE),
            ("accel", state.accel_scale_error, ACC_SCALE),
        ] {
            let ppm = |x: [f64; 3]| format!("{:.0}, {:.0}, {:.0}", x[0], x[1], x[2]);
            let errors = error.map(|s| s * 1e6).into();
            let sigmas = std::array::from_fn(|axis| sigma(first + axis) * 1e6);
            values.push(key_value(&format!("{name}_scale_error_ppm"), ppm(errors)));
            values.push(key_value(
                &format!("{name}_scale_error_sigma_ppm"),
                ppm(sigmas),
            ));
        }
    }
    values
}

fn key_value(key: &str, value: String) -> KeyValue {
    KeyValue {
        key: key.to_owned(),
        value,
    }
}

#[cfg(test)]
mod tests {
    use super::sigma_of_variance;

    #[test]
    fn a_broken_covariance_has_no_sigma() {
        assert_eq!(sigma_of_variance(9.0), 3.0);
        assert_eq!(sigma_of_variance(0.0), 0.0);
        for variance in [f64::NAN, f64::INFINITY, -1e-6, f64::NEG_INFINITY] {
            assert!(sigma_of_variance(variance).is_nan(), "variance {variance}");
        }
    }
}
