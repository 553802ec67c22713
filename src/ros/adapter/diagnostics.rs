//! The adapter's /diagnostics report.

use crate::ros::msg::{DiagnosticArray, DiagnosticStatus, Header, KeyValue, Time};

use super::RosAdapter;

impl RosAdapter {
    /// The /diagnostics report at `stamp`: input counts, rejections by reason, phase and,
    /// once running, the filter's 3D position sigma (level ERROR when it is not finite);
    /// level WARN while initializing or while a second frame sends on `imu`.
    pub fn diagnostics(&self, node_name: &str, stamp: Time) -> DiagnosticArray {
        let phase = match self.engine.init_phase() {
            Some(p) => format!("initializing ({p:?})"),
            None => "running".to_owned(),
        };
        let mut values = vec![
            key_value("variant", self.engine.variant_name().to_owned()),
            key_value("phase", phase.clone()),
            key_value("imu_frame", self.imu_frame.locked().to_owned()),
        ];
        for (key, n) in self.counts.named() {
            values.push(key_value(key, n.to_string()));
            if key == "velocity_paired" {
                let unpaired = self.unpaired_velocities().to_string();
                values.push(key_value("unpaired_velocity", unpaired));
            }
        }
        values.extend(self.engine.counters().iter().map(|(reason, n)| KeyValue {
            key: format!("rejected_{}", reason.name()),
            value: n.to_string(),
        }));
        let (level, message) = match self.engine.state() {
            None => (
                DiagnosticStatus::WARN,
                self.imu_frame_conflict().unwrap_or(phase),
            ),
            Some(state) => {
                // Filter health: the 3D position sigma the filter claims.
                let sigma_m = state
                    .solution()
                    .position_covariance_enu_m2()
                    .trace()
                    .max(0.0)
                    .sqrt();
                values.push(key_value("position_sigma_3d_m", format!("{sigma_m:.3}")));
                if !sigma_m.is_finite() {
                    (
                        DiagnosticStatus::ERROR,
                        "filter covariance is not finite".to_owned(),
                    )
                } else if let Some(conflict) = self.imu_frame_conflict() {
                    (DiagnosticStatus::WARN, conflict)
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

fn key_value(key: &str, value: String) -> KeyValue {
    KeyValue {
        key: key.to_owned(),
        value,
    }
}
