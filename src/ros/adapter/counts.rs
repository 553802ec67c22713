//! What arrived at the adapter and what it dropped before the engine or after it.

/// The adapter's input streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// `imu`: sensor_msgs/Imu.
    Imu,
    /// `gnss/measurements`: GnssMeasurements (tight coupling).
    Gnss,
    /// `gnss/fix`: sensor_msgs/NavSatFix (loose coupling).
    Fix,
    /// `gnss/velocity`: geometry_msgs/TwistWithCovarianceStamped (with the fix).
    Velocity,
    /// `wheel/odometry`: nav_msgs/Odometry of the base controller (its forward speed).
    WheelOdometry,
    /// `ubx_nav_rel_pos_ned`: ublox_ubx_msgs/UBXNavRelPosNED of a moving-base receiver
    /// pair (its baseline heading).
    RelPosNed,
}

impl Input {
    /// The node's topic name of the stream (relative).
    pub fn name(self) -> &'static str {
        match self {
            Input::Imu => "imu",
            Input::Gnss => "gnss/measurements",
            Input::Fix => "gnss/fix",
            Input::Velocity => "gnss/velocity",
            Input::WheelOdometry => "wheel/odometry",
            Input::RelPosNed => "ubx_nav_rel_pos_ned",
        }
    }
}

/// Counts of what arrived and what was dropped before the engine (and of outputs not
/// published).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InputCounts {
    /// Imu messages decoded.
    pub imu_received: u64,
    /// GnssMeasurements messages decoded.
    pub gnss_received: u64,
    /// NavSatFix messages decoded.
    pub fix_received: u64,
    /// TwistWithCovarianceStamped messages decoded on `gnss/velocity`.
    pub velocity_received: u64,
    /// nav_msgs/Odometry messages decoded on `wheel/odometry`.
    pub wheel_odometry_received: u64,
    /// UBXNavRelPosNED messages decoded on `ubx_nav_rel_pos_ned`.
    pub rel_pos_ned_received: u64,
    /// Velocities fed to the engine with their fix.
    pub velocity_paired: u64,
    /// Payloads that did not decode, any topic.
    pub undecodable: u64,
    /// IMU messages that decoded but did not convert (bad stamp, NaN).
    pub unconvertible_imu: u64,
    /// GNSS messages that did not convert (bad stamp or time of week, unknown constellation).
    pub unconvertible_gnss: u64,
    /// NavSatFix messages without a solution or with a bad stamp.
    pub unconvertible_fix: u64,
    /// Velocities with a bad stamp or a non-finite value.
    pub unconvertible_velocity: u64,
    /// Wheel odometries with a bad stamp, a non-finite forward speed or a variance of it
    /// that is not finite or negative.
    pub unconvertible_wheel_odometry: u64,
    /// UBXNavRelPosNED messages with a bad stamp or without a heading (no carrier-phase
    /// solution, a flag relPosValid, relPosHeadingValid or isMoving not set).
    pub unconvertible_rel_pos_ned: u64,
    /// Resets because the IMU time jumped backwards (several consecutive samples agreed).
    pub time_jump_resets: u64,
    /// IMU samples whose stamp was far off the time line and that no run of consecutive
    /// samples confirmed (a spoofed or corrupted stamp): dropped.
    pub imu_stamp_outliers: u64,
    /// Outputs not published because a value was not finite.
    pub non_finite_outputs: u64,
    /// Outputs not published because a covariance had a negative variance.
    pub negative_variance_outputs: u64,
    /// IMU messages from another frame than the locked one (a second publisher).
    pub foreign_frame_imu: u64,
    /// GnssMeasurements messages from another frame than the locked one.
    pub foreign_frame_gnss: u64,
    /// NavSatFix messages from another frame than the locked one.
    pub foreign_frame_fix: u64,
    /// Velocities neither in the map frame nor in their fix's frame (fix used without).
    pub foreign_frame_velocity: u64,
    /// Wheel odometries whose `child_frame_id` is another than the locked one.
    pub foreign_frame_wheel_odometry: u64,
    /// UBXNavRelPosNED messages from another frame than the locked one.
    pub foreign_frame_rel_pos_ned: u64,
    /// Times the IMU stream's learnt frame moved to another one (the locked frame went
    /// silent; the filter reset).
    pub frame_switches_imu: u64,
    /// Times the GnssMeasurements stream's learnt frame moved to another one.
    pub frame_switches_gnss: u64,
    /// Times the NavSatFix stream's learnt frame moved to another one.
    pub frame_switches_fix: u64,
    /// Times the wheel odometry's learnt `child_frame_id` moved to another one.
    pub frame_switches_wheel_odometry: u64,
    /// Times the UBXNavRelPosNED stream's learnt frame moved to another one.
    pub frame_switches_rel_pos_ned: u64,
}

impl InputCounts {
    /// The unconvertible counter of `input`.
    pub(super) fn unconvertible(&mut self, input: Input) -> &mut u64 {
        match input {
            Input::Imu => &mut self.unconvertible_imu,
            Input::Gnss => &mut self.unconvertible_gnss,
            Input::Fix => &mut self.unconvertible_fix,
            Input::Velocity => &mut self.unconvertible_velocity,
            Input::WheelOdometry => &mut self.unconvertible_wheel_odometry,
            Input::RelPosNed => &mut self.unconvertible_rel_pos_ned,
        }
    }

    /// The foreign-frame counter of `input`.
    pub(super) fn foreign_frame(&mut self, input: Input) -> &mut u64 {
        match input {
            Input::Imu => &mut self.foreign_frame_imu,
            Input::Gnss => &mut self.foreign_frame_gnss,
            Input::Fix => &mut self.foreign_frame_fix,
            Input::Velocity => &mut self.foreign_frame_velocity,
            Input::WheelOdometry => &mut self.foreign_frame_wheel_odometry,
            Input::RelPosNed => &mut self.foreign_frame_rel_pos_ned,
        }
    }

    /// The frame-switch counter of `input` (velocities follow their fix's frame).
    pub(super) fn frame_switches(&mut self, input: Input) -> &mut u64 {
        match input {
            Input::Imu => &mut self.frame_switches_imu,
            Input::Gnss => &mut self.frame_switches_gnss,
            Input::Fix | Input::Velocity => &mut self.frame_switches_fix,
            Input::WheelOdometry => &mut self.frame_switches_wheel_odometry,
            Input::RelPosNed => &mut self.frame_switches_rel_pos_ned,
        }
    }

    /// The messages dropped before the engine that decoded: (name, count) of the IMU
    /// stamp outliers, the ones that did not convert and the ones from a foreign frame (a
    /// velocity in a foreign frame drops no message: its fix goes on alone), named as on
    /// /diagnostics.
    pub fn dropped(&self) -> [(&'static str, u64); 12] {
        [
            ("imu_stamp_outliers", self.imu_stamp_outliers),
            ("unconvertible_imu", self.unconvertible_imu),
            ("unconvertible_gnss", self.unconvertible_gnss),
            ("unconvertible_fix", self.unconvertible_fix),
            ("unconvertible_velocity", self.unconvertible_velocity),
            (
                "unconvertible_wheel_odometry",
                self.unconvertible_wheel_odometry,
            ),
            ("unconvertible_rel_pos_ned", self.unconvertible_rel_pos_ned),
            ("foreign_frame_imu", self.foreign_frame_imu),
            ("foreign_frame_gnss", self.foreign_frame_gnss),
            ("foreign_frame_fix", self.foreign_frame_fix),
            (
                "foreign_frame_wheel_odometry",
                self.foreign_frame_wheel_odometry,
            ),
            ("foreign_frame_rel_pos_ned", self.foreign_frame_rel_pos_ned),
        ]
    }

    /// The counters as (name, value) in the order of the /diagnostics report; the names
    /// are the report's keys.
    pub fn named(&self) -> [(&'static str, u64); 29] {
        [
            ("imu_received", self.imu_received),
            ("gnss_received", self.gnss_received),
            ("fix_received", self.fix_received),
            ("velocity_received", self.velocity_received),
            ("wheel_odometry_received", self.wheel_odometry_received),
            ("rel_pos_ned_received", self.rel_pos_ned_received),
            ("velocity_paired", self.velocity_paired),
            ("undecodable", self.undecodable),
            ("unconvertible_imu", self.unconvertible_imu),
            ("unconvertible_gnss", self.unconvertible_gnss),
            ("unconvertible_fix", self.unconvertible_fix),
            ("unconvertible_velocity", self.unconvertible_velocity),
            (
                "unconvertible_wheel_odometry",
                self.unconvertible_wheel_odometry,
            ),
            ("unconvertible_rel_pos_ned", self.unconvertible_rel_pos_ned),
            ("time_jump_resets", self.time_jump_resets),
            ("imu_stamp_outliers", self.imu_stamp_outliers),
            ("non_finite_outputs", self.non_finite_outputs),
            ("negative_variance_outputs", self.negative_variance_outputs),
            ("foreign_frame_imu", self.foreign_frame_imu),
            ("foreign_frame_gnss", self.foreign_frame_gnss),
            ("foreign_frame_fix", self.foreign_frame_fix),
            ("foreign_frame_velocity", self.foreign_frame_velocity),
            (
                "foreign_frame_wheel_odometry",
                self.foreign_frame_wheel_odometry,
            ),
            ("foreign_frame_rel_pos_ned", self.foreign_frame_rel_pos_ned),
            ("frame_switches_imu", self.frame_switches_imu),
            ("frame_switches_gnss", self.frame_switches_gnss),
            ("frame_switches_fix", self.frame_switches_fix),
            (
                "frame_switches_wheel_odometry",
                self.frame_switches_wheel_odometry,
            ),
            (
                "frame_switches_rel_pos_ned",
                self.frame_switches_rel_pos_ned,
            ),
        ]
    }
}
