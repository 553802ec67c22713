//! Typed rejections of inputs and their counters (what /diagnostics reports).

use std::collections::BTreeMap;

/// Why an input was not processed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RejectionReason {
    /// An IMU field is NaN or infinite.
    ImuNotFinite,
    /// An IMU stamp equal to the previous one.
    ImuDuplicate,
    /// An IMU stamp older than the previous one.
    ImuOutOfOrder,
    /// The IMU stream stopped for longer than `engine.max_imu_gap_s` (the filter reset).
    ImuGap,
    /// The strapdown step failed (non-finite result).
    ImuStepFailed,
    /// An IMU axis beyond the sensor's range (`imu.gyro_range_deg_per_s`,
    /// `imu.accel_range_g`).
    ImuOutOfRange,
    /// An IMU sample jumping from its neighbours beyond what the signal can change
    /// (`imu.gyro_max_step_deg_per_s`, `imu.accel_max_step_g`).
    ImuInconsistent,
    /// The GNSS epoch's time is NaN or infinite.
    GnssNotFinite,
    /// A GNSS epoch with no satellites.
    GnssNoSatellites,
    /// A fix with a NaN or infinite field.
    FixNotFinite,
    /// A measurement with the same time as one already received.
    MeasurementDuplicate,
    /// A measurement older than the IMU buffer (`engine.imu_buffer_s`).
    MeasurementTooOld,
    /// A measurement more than `engine.imu_buffer_s` ahead of the last IMU sample.
    MeasurementTooNew,
    /// A waiting measurement dropped for a newer one: the queue was full (no IMU came).
    MeasurementQueueFull,
    /// A pseudo-range epoch in loosely-coupled mode, or a fix in tightly-coupled mode.
    WrongCoupling,
    /// The Kalman update failed (singular or non-finite); the state was kept.
    UpdateFailed,
    /// A wheel speed whose time or speed is not finite, or whose given σ is not finite
    /// and positive.
    WheelSpeedInvalid,
    /// A wheel speed while `wheel_odometry.enabled` is off.
    WheelOdometryOff,
    /// A wheel speed before the filter runs (start-up uses GNSS only).
    WheelSpeedBeforeStart,
    /// A baseline heading whose time, heading, σ or length is not finite, or whose σ or
    /// length is not positive.
    BaselineHeadingInvalid,
    /// A baseline heading while `dual_antenna.enabled` is off.
    DualAntennaOff,
    /// A baseline heading of a float carrier solution (`dual_antenna.accept_float` off).
    BaselineHeadingFloat,
    /// A baseline heading whose σ exceeds `dual_antenna.max_sigma_deg`.
    BaselineHeadingInaccurate,
    /// A baseline whose length differs from `dual_antenna.baseline_m`'s by more than
    /// `dual_antenna.length_tolerance_m`.
    BaselineLengthMismatch,
    /// A baseline heading beyond `dual_antenna.gate_sigma` of the running filter's.
    BaselineHeadingGated,
}

impl RejectionReason {
    /// Stable snake_case name, used for diagnostics keys.
    pub fn name(self) -> &'static str {
        match self {
            Self::ImuNotFinite => "imu_not_finite",
            Self::ImuDuplicate => "imu_duplicate_stamp",
            Self::ImuOutOfOrder => "imu_out_of_order",
            Self::ImuGap => "imu_gap",
            Self::ImuStepFailed => "imu_step_failed",
            Self::ImuOutOfRange => "imu_out_of_range",
            Self::ImuInconsistent => "imu_inconsistent",
            Self::GnssNotFinite => "gnss_not_finite",
            Self::GnssNoSatellites => "gnss_no_satellites",
            Self::FixNotFinite => "fix_not_finite",
            Self::MeasurementDuplicate => "measurement_duplicate",
            Self::MeasurementTooOld => "measurement_too_old",
            Self::MeasurementTooNew => "measurement_too_new",
            Self::MeasurementQueueFull => "measurement_queue_full",
            Self::WrongCoupling => "wrong_coupling",
            Self::UpdateFailed => "update_failed",
            Self::WheelSpeedInvalid => "wheel_speed_invalid",
            Self::WheelOdometryOff => "wheel_odometry_off",
            Self::WheelSpeedBeforeStart => "wheel_speed_before_start",
            Self::BaselineHeadingInvalid => "baseline_heading_invalid",
            Self::DualAntennaOff => "dual_antenna_off",
            Self::BaselineHeadingFloat => "baseline_heading_float",
            Self::BaselineHeadingInaccurate => "baseline_heading_inaccurate",
            Self::BaselineLengthMismatch => "baseline_length_mismatch",
            Self::BaselineHeadingGated => "baseline_heading_gated",
        }
    }
}

/// An input the engine did not process.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("input at t = {t_s} s rejected: {}", reason.name())]
pub struct InputRejected {
    pub reason: RejectionReason,
    pub t_s: f64,
}

/// Counts of rejected inputs by reason.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RejectionCounters {
    counts: BTreeMap<RejectionReason, u64>,
}

impl RejectionCounters {
    /// Counts one rejection and returns it as an error value.
    pub fn reject(&mut self, reason: RejectionReason, t_s: f64) -> InputRejected {
        *self.counts.entry(reason).or_insert(0) += 1;
        InputRejected { reason, t_s }
    }

    pub fn count(&self, reason: RejectionReason) -> u64 {
        self.counts.get(&reason).copied().unwrap_or(0)
    }

    pub fn total(&self) -> u64 {
        self.counts.values().sum()
    }

    /// (reason, count) pairs with a non-zero count.
    pub fn iter(&self) -> impl Iterator<Item = (RejectionReason, u64)> + '_ {
        self.counts.iter().map(|(r, c)| (*r, *c))
    }
}
