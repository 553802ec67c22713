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
    /// (the dual-antenna heading).
    RelPosNed,
}

impl Input {
    /// Every input, in the order of the /diagnostics report.
    pub const ALL: [Input; 6] = [
        Input::Imu,
        Input::Gnss,
        Input::Fix,
        Input::Velocity,
        Input::WheelOdometry,
        Input::RelPosNed,
    ];

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

    /// The stream's part of its /diagnostics counter names (`imu_received`,
    /// `unconvertible_imu`, `foreign_frame_imu`, `frame_switches_imu`).
    pub fn key(self) -> &'static str {
        match self {
            Input::Imu => "imu",
            Input::Gnss => "gnss",
            Input::Fix => "fix",
            Input::Velocity => "velocity",
            Input::WheelOdometry => "wheel_odometry",
            Input::RelPosNed => "rel_pos_ned",
        }
    }

    /// Whether the stream follows a frame of its own (a velocity follows its fix's).
    fn locks_a_frame(self) -> bool {
        self != Input::Velocity
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// What arrived on one input stream and what of it was dropped.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Messages decoded.
    pub received: u64,
    /// Messages that decoded but did not convert (a bad stamp, a non-finite value, no
    /// solution in a NavSatFix, an unknown constellation, a UBXNavRelPosNED without a
    /// carrier-phase heading...).
    pub unconvertible: u64,
    /// Messages from another frame than the locked one (a second publisher); velocities
    /// neither in the map frame nor in their fix's frame (the fix is used without).
    pub foreign_frame: u64,
    /// Times the stream's learnt frame moved to another one (the locked frame went
    /// silent); none for velocities, which follow their fix's frame.
    pub frame_switches: u64,
}

/// Counts of what arrived and what was dropped before the engine (and of outputs not
/// published).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InputCounts {
    streams: [StreamCounts; Input::ALL.len()],
    /// Velocities fed to the engine with their fix.
    pub velocity_paired: u64,
    /// Payloads that did not decode, any topic.
    pub undecodable: u64,
    /// Resets because the IMU time jumped backwards (several consecutive samples agreed).
    pub time_jump_resets: u64,
    /// IMU samples whose stamp was far off the time line and that no run of consecutive
    /// samples confirmed (a spoofed or corrupted stamp): dropped.
    pub imu_stamp_outliers: u64,
    /// Outputs not published because a value was not finite.
    pub non_finite_outputs: u64,
    /// Outputs not published because a covariance had a negative variance.
    pub negative_variance_outputs: u64,
}

impl InputCounts {
    /// The counts of `input`'s stream.
    pub fn stream(&self, input: Input) -> &StreamCounts {
        &self.streams[input.index()]
    }

    /// The counts of `input`'s stream, to count in.
    pub(super) fn stream_mut(&mut self, input: Input) -> &mut StreamCounts {
        &mut self.streams[input.index()]
    }

    /// The messages dropped before the engine that decoded: (name, count) of the IMU
    /// stamp outliers, the ones that did not convert and the ones from a foreign frame (a
    /// velocity in a foreign frame drops no message: its fix goes on alone), named as on
    /// /diagnostics.
    pub fn dropped(&self) -> Vec<(String, u64)> {
        let mut dropped = vec![("imu_stamp_outliers".to_owned(), self.imu_stamp_outliers)];
        dropped.extend(self.per_stream("unconvertible_", "", |s| s.unconvertible, |_| true));
        dropped.extend(self.per_stream(
            "foreign_frame_",
            "",
            |s| s.foreign_frame,
            Input::locks_a_frame,
        ));
        dropped
    }

    /// The counters as (name, value) in the order of the /diagnostics report; the names
    /// are the report's keys.
    pub fn named(&self) -> Vec<(String, u64)> {
        let all = |_: Input| true;
        let mut named = self.per_stream("", "_received", |s| s.received, all);
        for (key, n) in [
            ("velocity_paired", self.velocity_paired),
            ("undecodable", self.undecodable),
        ] {
            named.push((key.to_owned(), n));
        }
        named.extend(self.per_stream("unconvertible_", "", |s| s.unconvertible, all));
        for (key, n) in [
            ("time_jump_resets", self.time_jump_resets),
            ("imu_stamp_outliers", self.imu_stamp_outliers),
            ("non_finite_outputs", self.non_finite_outputs),
            ("negative_variance_outputs", self.negative_variance_outputs),
        ] {
            named.push((key.to_owned(), n));
        }
        named.extend(self.per_stream("foreign_frame_", "", |s| s.foreign_frame, all));
        named.extend(self.per_stream(
            "frame_switches_",
            "",
            |s| s.frame_switches,
            Input::locks_a_frame,
        ));
        named
    }

    /// One counter of every input that `include` keeps, named `prefix` + key + `suffix`.
    fn per_stream(
        &self,
        prefix: &str,
        suffix: &str,
        count: impl Fn(&StreamCounts) -> u64,
        include: impl Fn(Input) -> bool,
    ) -> Vec<(String, u64)> {
        Input::ALL
            .into_iter()
            .filter(|&input| include(input))
            .map(|input| {
                let name = format!("{prefix}{}{suffix}", input.key());
                (name, count(self.stream(input)))
            })
            .collect()
    }
}
