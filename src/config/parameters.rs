//! THE parameter table: every parameter of the configuration, declared once with its SI
//! field, file key, type, default, unit, valid range, whether it can change while the
//! node runs, its SI conversion and its manual text (the doc comment). See `table.rs` for
//! the form of a declaration.
//!
//! Everything else comes from here: the section structs and their defaults, loading and
//! checking a file or a `-p` value, the echo, the parameter services' descriptions and
//! read-only flags, the retune rule, `params/defaults.yaml` and `docs/parameters.md` (both
//! generated and checked by `tests/parameter_manual.rs`). Checks that relate two
//! parameters are in `validate.rs`.

use nalgebra::{UnitQuaternion, Vector3};

use super::convert::{
    ByName, LlhDegToPosition, RpyDegToRotation, Scale, ToVector, M_S2_PER_UG, RAD_PER_DEG,
    RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H, RAD_S_PER_DEG_H, STANDARD_GRAVITY_M_S2,
};
use super::file_value::ConstellationName;
use super::spec::{Interval, Range};
use super::table::parameter_table;
use super::{
    AdaptiveFactorKind, Coupling, EquivalentWeightKind, FilterBase, FilterVariant, Platform,
};
use crate::adaptive::burg::OrderCriterion;
use crate::earth::Llh;
use crate::gnss::Constellation;

/// Choice: a 1-sigma (or a noise density) lies between 1e-9 and 1e6 of its unit: below,
/// the filter would trust a sensor beyond any physical one; above, the squares (1e12 and
/// more) swamp every other term of the covariance, and 1e300 overflows it to infinity.
const SIGMA: Range = Range::Within(Interval::closed(1e-9, 1e6));
/// Choice: a correlation time lies between 1 ms (shorter is white noise at any IMU rate)
/// and 1e7 s (four months, beyond which the process is a constant); 1e-300 s makes the
/// discretised process noise overflow.
const TIME_CONSTANT: Range = Range::Within(Interval::closed(1e-3, 1e7));
/// Choice: a threshold on a standardized residual, in sigmas, above 0; beyond 1000 sigma
/// it never acts.
const THRESHOLD: Range = Range::Within(Interval::above(0.0, 1e3));
/// Choice: an epoch window holds at most 1e4 epochs (almost three hours at 1 Hz): every
/// estimator of the table converges within a few hundred, and a window is allocated per
/// satellite, so 1e9 would ask for tens of gigabytes.
const MAX_WINDOW_EPOCHS: u64 = 10_000;
/// A fraction in (0, 1].
const FRACTION: Range = Range::Within(Interval::above(0.0, 1.0));
/// A sensor's measurement range, above 0.
const RANGE: Range = Range::Within(Interval::above(0.0, 1e6));
/// A factor bound at least 1 (and finite).
const FACTOR_MAX: Range = Range::Within(Interval::closed(1.0, 1e12));
const ANY: Range = Range::Any;

parameter_table! {
    /// Which filter runs and how its update is formed.
    section filter: FilterConfig {
        /// Filter variant (enum). ekf = error-state extended Kalman filter with the fixed
        /// noise of this file: the baseline the adaptive variants are compared against.
        /// ERMAKF paper: eiakf (innovation-based R), srmakf, ermakf (redundant-measurement
        /// R, see adaptive.*). IARF paper (section 5 schemes, constants in robust.*): ckf
        /// (cubature filter), akf_all (adaptive factor at every epoch), akf_partial
        /// (adaptive factor only at epochs passing the Mahalanobis test), iarf (robust
        /// equivalent R at every epoch + adaptive factor at epochs passing the test). Ding,
        /// Wang and Rizos: residual_akf (R from the post-update residuals, eqs. 14-15).
        variant: FilterVariant = FilterVariant::Ekf, unit "", range ANY, at_start;
        /// What is taken from the receiver (enum). tight = per-satellite pseudo-ranges and
        /// pseudo-range rates (gnss.*); loose = the receiver's position/velocity fix
        /// (loose.*).
        coupling: Coupling = Coupling::Tight, unit "", range ANY, at_start;
        /// Joseph-form covariance update P = (I-KH)P(I-KH)^T + KRK^T (stays symmetric and
        /// positive definite under rounding). false = the short form P = (I-KH)P.
        joseph_form: bool = true, unit "", range ANY, at_start;
        /// Base filter of the measurement update (enum). ekf = linearized update; cubature
        /// = cubature Kalman filter (2n points through the full measurement model; the
        /// covariance time update stays the linearized one); auto = cubature for ckf,
        /// akf_all, akf_partial and iarf (the IARF paper runs all its schemes on the CKF),
        /// ekf for the other variants. akf_all, akf_partial and iarf also run on base ekf;
        /// ckf with base ekf is refused (that is variant ekf).
        base: FilterBase = FilterBase::Auto, unit "", range ANY, at_start;
        /// Ding's process-noise scaling (eqs. 19, 22): Q is multiplied by sqrt(alpha) once
        /// per full window of robust.q_window_epochs, alpha = observed / predicted
        /// innovation power. Combines with every variant.
        q_scaling: bool = false, unit "", range ANY, at_start;
    }

    /// Inertial sensor noise, in data-sheet units.
    section imu: ImuConfig {
        /// Gyro angle random walk (white rate noise density), from the data sheet.
        gyro_arw_rad_per_sqrt_s: f64 ["gyro_arw_deg_per_sqrt_h": f64] = 0.012,
            unit "deg/sqrt(h)", range SIGMA, at_start,
            si Scale::to("rad/sqrt(s)", RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H);
        /// Initial 1-sigma of the constant (turn-on) gyro bias, per axis.
        gyro_bias_sigma_rad_s: f64 ["gyro_bias_deg_per_h": f64] = 0.5,
            unit "deg/h", range SIGMA, at_start, si Scale::to("rad/s", RAD_S_PER_DEG_H);
        /// Steady-state 1-sigma of the first-order Gauss-Markov gyro drift, per axis.
        gyro_markov_sigma_rad_s: f64 ["gyro_markov_sigma_deg_per_h": f64] = 0.5,
            unit "deg/h", range SIGMA, at_start, si Scale::to("rad/s", RAD_S_PER_DEG_H);
        /// Correlation time of the gyro Gauss-Markov drift.
        gyro_markov_time_s: f64 ["gyro_markov_correlation_time_s": f64] = 3600.0,
            unit "s", range TIME_CONSTANT, at_start;
        /// Accelerometer velocity random walk (white specific-force noise density).
        accel_vrw_m_s_per_sqrt_s: f64 ["accel_vrw_ug_per_sqrt_hz": f64] = 100.0,
            unit "ug/sqrt(Hz)", range SIGMA, at_start, si Scale::to("m/s/sqrt(s)", M_S2_PER_UG);
        /// Steady-state 1-sigma of the first-order Gauss-Markov accelerometer bias, per
        /// axis.
        accel_bias_sigma_m_s2: f64 ["accel_bias_ug": f64] = 1250.0,
            unit "ug", range SIGMA, at_start, si Scale::to("m/s^2", M_S2_PER_UG);
        /// Correlation time of the accelerometer Gauss-Markov bias.
        accel_markov_time_s: f64 ["accel_bias_correlation_time_s": f64] = 3600.0,
            unit "s", range TIME_CONSTANT, at_start;
        /// Gyro range per axis; a sample beyond it is dropped (imu_out_of_range).
        gyro_range_rad_s: f64 ["gyro_range_deg_per_s": f64] = 490.0,
            unit "deg/s", range RANGE, at_run_time, si Scale::to("rad/s", RAD_PER_DEG);
        /// Accelerometer range per axis (as gyro_range_deg_per_s).
        accel_range_m_s2: f64 ["accel_range_g": f64] = 10.0,
            unit "g", range RANGE, at_run_time, si Scale::to("m/s^2", STANDARD_GRAVITY_M_S2);
        /// Largest gyro change between samples; a lone larger jump is dropped
        /// (imu_inconsistent). 0 = off.
        gyro_step_max_rad_s: f64 ["gyro_max_step_deg_per_s": f64] = 100.0,
            unit "deg/s", range Range::OffOrWithin(Interval::above(0.0, 1e6)), at_run_time,
            si Scale::to("rad/s", RAD_PER_DEG);
        /// Largest accelerometer change between samples (as gyro_max_step_deg_per_s).
        accel_step_max_m_s2: f64 ["accel_max_step_g": f64] = 5.0,
            unit "g", range Range::OffOrWithin(Interval::above(0.0, 1e6)), at_run_time,
            si Scale::to("m/s^2", STANDARD_GRAVITY_M_S2);
        /// Estimate the gyro and accelerometer scale-factor errors (six states of the
        /// filter, first-order Gauss-Markov, as KF-GINS carries them): worth it where the
        /// turns are long and the scale factors worse than the biases show (a 600 ppm gyro
        /// scale error turns 360 deg of turning into 0.2 deg of heading). Off: the states
        /// are inert and the outputs those of the filter without them.
        scale_factor_states: bool = false, unit "", range ANY, at_start;
        /// Steady-state (and initial) 1-sigma of the gyro scale-factor error, per axis.
        gyro_scale_factor_sigma: f64 ["gyro_scale_factor_ppm": f64] = 1000.0,
            unit "ppm", range SIGMA, at_start, si Scale::to("(ratio)", 1e-6);
        /// Steady-state (and initial) 1-sigma of the accelerometer scale-factor error.
        accel_scale_factor_sigma: f64 ["accel_scale_factor_ppm": f64] = 1000.0,
            unit "ppm", range SIGMA, at_start, si Scale::to("(ratio)", 1e-6);
        /// Correlation time of both scale-factor errors (a large value: a random
        /// constant).
        // Choice: 10 h, not KF-GINS's 1 h: a scale factor holds over a drive, and a 1 h
        // Gauss-Markov process of the steady-state sigma above is driven by enough noise
        // (2 sigma^2 / T) to forget in minutes what the turns teach (a 600 ppm gyro z error
        // was learned to 205 ppm after six circles with 1 h, sigma still 384 ppm).
        scale_factor_time_s: f64 ["scale_factor_correlation_time_s": f64] = 36000.0,
            unit "s", range TIME_CONSTANT, at_start;
    }

    /// IMU orientation and antenna lever arm.
    section mounting: MountingConfig {
        /// Rotation taking IMU-frame vectors into the body frame (FLU): [roll, pitch, yaw]
        /// about x, y, z, composed as R = Rz(yaw) * Ry(pitch) * Rx(roll). [0, 0, 0] = the
        /// IMU axes are the body axes.
        imu_to_body: UnitQuaternion<f64> ["imu_rotation_rpy_deg": [f64; 3]] = [0.0, 0.0, 0.0],
            unit "deg",
            range Range::Components([
                ("roll", Interval::closed(-180.0, 180.0), "deg"),
                ("pitch", Interval::closed(-90.0, 90.0), "deg"),
                ("yaw", Interval::closed(-180.0, 180.0), "deg"),
            ]),
            at_start, si RpyDegToRotation;
        /// GNSS antenna phase centre relative to the IMU, in the body frame [forward, left,
        /// up].
        // Choice: a lever arm beyond 100 m is taken as a unit mistake (cm or mm as m).
        lever_arm_b_m: Vector3<f64> ["antenna_lever_arm_m": [f64; 3]] = [0.0, 0.0, 0.0],
            unit "m", range Range::Within(Interval::closed(-100.0, 100.0)), at_start,
            si ToVector;
        /// Point of the vehicle whose lateral and vertical velocity the non-holonomic
        /// constraint holds at zero (constraints.platform car or robot: the middle of the
        /// rear axle, or of the wheels of a differential drive), relative to the IMU, in
        /// the body frame [forward, left, up]. The body frame is the vehicle's (x
        /// forward): imu_rotation_rpy_deg turns the IMU into it.
        // Choice: a point of its own, not the antenna's lever arm: the antenna sits on the
        // roof, the point that does not slip sideways is on the ground between the wheels.
        constraint_point_b_m: Vector3<f64> ["constraint_point_lever_arm_m": [f64; 3]]
            = [0.0, 0.0, 0.0],
            unit "m", range Range::Within(Interval::closed(-100.0, 100.0)), at_start,
            si ToVector;
    }

    /// Constraints of the vehicle's motion applied as measurements at
    /// constraints.rate_hz: zero velocity and zero angular rate at a standstill (ZUPT,
    /// ZARU), and the non-holonomic constraint of a wheeled vehicle (NHC). All are off by
    /// default; the IMU-class presets (params/imu_*.yaml) set the standstill thresholds
    /// of their class.
    section constraints: ConstraintsConfig {
        /// Zero-velocity and zero-angular-rate updates while the IMU's last second is at
        /// rest (the spreads and the bias-compensated mean rate below) and the receiver's
        /// speed, when a fix gives one, does not say it moves.
        zupt: bool = false, unit "", range ANY, at_start;
        /// Rate of the constraint updates (ZUPT, ZARU, NHC); the IMU samples whose stamp
        /// crosses a multiple of 1 / rate_hz carry them.
        rate_hz: f64 = 10.0,
            unit "Hz", range Range::Within(Interval::closed(0.01, 1e3)), at_start;
        /// 1-sigma of each velocity component at rest (the vehicle rocking on its
        /// suspension).
        zupt_sigma_mps: f64 = 0.02, unit "m/s", range SIGMA, at_start;
        /// 1-sigma of each axis of the mean angular rate over a second at rest, beyond the
        /// gyro's white noise over that second (imu.gyro_arw_deg_per_sqrt_h), which is
        /// added: a parked vehicle's sway and what its idle leaves in the mean.
        zaru_sigma_rad_s: f64 ["zaru_sigma_deg_per_s": f64] = 0.005,
            unit "deg/s", range SIGMA, at_start, si Scale::to("rad/s", RAD_PER_DEG);
        /// Largest spread (root mean square over the axes of each axis's standard
        /// deviation over the last second) of the specific force at rest.
        rest_accel_spread_max_m_s2: f64 ["rest_accel_spread_max_mg": f64] = 10.0,
            unit "mg", range SIGMA, at_start,
            si Scale::to("m/s^2", STANDARD_GRAVITY_M_S2 / 1000.0);
        /// Largest spread of the angular rate at rest (as rest_accel_spread_max_mg).
        rest_gyro_spread_max_rad_s: f64 ["rest_gyro_spread_max_deg_per_s": f64] = 0.2,
            unit "deg/s", range SIGMA, at_start, si Scale::to("rad/s", RAD_PER_DEG);
        /// Largest norm of the mean angular rate over the last second at rest, after the
        /// estimated gyro bias and the earth rate are removed (a slow steady turn has a
        /// steady rate).
        rest_rate_max_rad_s: f64 ["rest_rate_max_deg_per_s": f64] = 0.1,
            unit "deg/s", range SIGMA, at_start, si Scale::to("rad/s", RAD_PER_DEG);
        /// A receiver fix velocity faster than this in the last 2 s vetoes a rest (loose
        /// coupling; in tight coupling the pseudo-range rates themselves outweigh a false
        /// rest).
        rest_gnss_speed_max_mps: f64 = 0.3, unit "m/s", range SIGMA, at_start;
        /// The vehicle (enum): car or robot = a wheeled ground vehicle, whose
        /// constraint point (mounting.constraint_point_lever_arm_m) moves neither sideways
        /// nor up or down in the body frame (NHC); pedestrian or none = no such
        /// constraint.
        platform: Platform = Platform::None, unit "", range ANY, at_start;
        /// 1-sigma of the constraint point's lateral velocity (wheel slip, a loose
        /// mounting).
        nhc_sigma_lateral_mps: f64 = 0.1, unit "m/s", range SIGMA, at_start;
        /// 1-sigma of the constraint point's vertical velocity (suspension, bumps).
        nhc_sigma_vertical_mps: f64 = 0.1, unit "m/s", range SIGMA, at_start;
        /// The NHC is suspended while the bias-compensated yaw rate exceeds this (a hard
        /// turn, where the tyres slip sideways).
        nhc_yaw_rate_max_rad_s: f64 ["nhc_yaw_rate_max_deg_per_s": f64] = 30.0,
            unit "deg/s", range Range::Within(Interval::above(0.0, 1e4)), at_start,
            si Scale::to("rad/s", RAD_PER_DEG);
    }

    /// Wheel odometry (optional): the base controller's forward speed (nav_msgs/Odometry
    /// on wheel/odometry, twist.twist.linear.x in its child frame) measures the forward
    /// velocity, in the body frame, of the point mounting.constraint_point_lever_arm_m
    /// (the middle of the axle whose wheels the controller reads, as for the NHC).
    section wheel_odometry: WheelOdometryConfig {
        /// Use the wheel speeds (the node subscribes wheel/odometry only then); when off,
        /// speeds given to the engine are rejected and counted.
        enabled: bool = false, unit "", range ANY, at_start;
        /// 1-sigma of a speed whose message gives no variance (twist covariance[0] 0).
        sigma_mps: f64 = 0.1, unit "m/s", range SIGMA, at_start;
        /// Factor from the reported speed to the true one (a wheel radius off by 1 %:
        /// 1.01): fixed, or the start of the estimate with scale_factor_state.
        // Choice: within [0.5, 2]: a factor beyond is a wrong unit or wheel, not a tyre.
        scale_factor: f64 = 1.0,
            unit "", range Range::Within(Interval::closed(0.5, 2.0)), at_start;
        /// Estimate the scale factor (a state of the filter) while GNSS holds the velocity,
        /// and use the estimate through outages; off: scale_factor is taken as exact.
        scale_factor_state: bool = false, unit "", range ANY, at_start;
        /// Initial 1-sigma of the scale factor with scale_factor_state (tyre wear and
        /// pressure, a radius guessed from the data sheet).
        scale_factor_sigma: f64 = 0.05, unit "", range SIGMA, at_start;
        /// White noise driving the scale factor (a random walk) with scale_factor_state:
        /// 1e-5 / sqrt(s) lets it move 6e-4 in an hour (tyres warming up, load).
        scale_factor_noise_per_sqrt_s: f64 = 1e-5, unit "1/sqrt(s)", range SIGMA, at_start;
    }

    /// Dual-antenna heading (optional): a moving-base u-blox pair's relative position
    /// (ublox_ubx_msgs/UBXNavRelPosNED on ubx_nav_rel_pos_ned, as ublox_dgnss publishes it)
    /// measures the heading of the baseline from the moving base's antenna to the rover's.
    /// It gives the heading at rest: a start parked takes it, and the running filter is
    /// updated with each valid message (relPosValid, relPosHeadingValid, moving base and a
    /// carrier solution), its sigma the message's accHeading.
    section dual_antenna: DualAntennaConfig {
        /// Use the baseline headings (the node subscribes ubx_nav_rel_pos_ned only then);
        /// when off, headings given to the engine are rejected and counted.
        enabled: bool = false, unit "", range ANY, at_start;
        /// The baseline from the moving base's antenna to the rover's antenna in the body
        /// frame [forward, left, up]: [1, 0, 0] = the rover's antenna 1 m ahead of the
        /// base's, [0, -1, 0] = 1 m to its right (heading offset +90 deg).
        // Choice: a vector rather than a heading offset: it gives the offset, the
        // baseline's length (checked against the message's, a wrong ambiguity fix shows
        // there) and, for antennas at different heights, the exact heading of a tilted
        // baseline. Beyond 100 m it is a unit mistake.
        baseline_b_m: Vector3<f64> ["baseline_m": [f64; 3]] = [1.0, 0.0, 0.0],
            unit "m", range Range::Within(Interval::closed(-100.0, 100.0)), at_start,
            si ToVector;
        /// Largest |measured length - configured length| of the baseline; a message beyond
        /// it is rejected and counted (a wrong integer fix or a wrong baseline_m).
        length_tolerance_m: f64 = 0.1, unit "m", range SIGMA, at_start;
        /// Largest accHeading accepted (after the float scale); beyond, the message is
        /// rejected and counted.
        max_sigma_rad: f64 ["max_sigma_deg": f64] = 5.0,
            unit "deg", range Range::Within(Interval::above(0.0, 180.0)), at_start,
            si Scale::to("rad", RAD_PER_DEG);
        /// Accept a float carrier solution (ambiguities not fixed), its sigma multiplied by
        /// float_sigma_scale; when off, float solutions are rejected and counted.
        accept_float: bool = false, unit "", range ANY, at_start;
        /// Factor on a float solution's accHeading (accept_float): the receiver's accuracy
        /// of an unfixed baseline is optimistic.
        float_sigma_scale: f64 = 3.0, unit "", range FACTOR_MAX, at_start;
        /// Innovation gate of the running filter's heading update, in sigmas of the
        /// innovation (the heading's variance and the filter's); a heading beyond it is
        /// rejected and counted, never applied.
        gate_sigma: f64 = 5.0, unit "", range THRESHOLD, at_start;
    }

    /// Receiver clock model: bias c*dt_u (m) and drift c*dt_ru (m/s). The defaults are a
    /// typical TCXO (Allan coefficients h0 = 2e-19, h-2 = 2e-20, Brown & Hwang):
    /// sqrt(h0/2)*c = 0.1 m/sqrt(s), sqrt(2 pi^2 h-2)*c = 0.2 (m/s)/sqrt(s).
    section clock: ClockConfig {
        /// White noise driving the receiver clock bias c*dt_u (random walk).
        bias_noise_m_per_sqrt_s: f64 = 0.1, unit "m/sqrt(s)", range SIGMA, at_start;
        /// White noise driving the receiver clock drift c*dt_ru (Gauss-Markov).
        drift_noise_m_s_per_sqrt_s: f64 ["drift_noise_mps_per_sqrt_s": f64] = 0.2,
            unit "(m/s)/sqrt(s)", range SIGMA, at_start;
        /// Correlation time of the clock drift.
        drift_time_s: f64 ["drift_correlation_time_s": f64] = 1800.0,
            unit "s", range TIME_CONSTANT, at_start;
    }

    /// Raw measurement selection and weighting (tight coupling).
    section gnss: GnssConfig {
        /// Satellites below this elevation are not used.
        elevation_mask_rad: f64 ["elevation_mask_deg": f64] = 10.0,
            unit "deg", range Range::Within(Interval::below(0.0, 90.0)), at_run_time,
            si Scale::to("rad", RAD_PER_DEG);
        /// Satellites below this carrier-to-noise density are not used. 0 = off.
        cn0_mask_dbhz: f64 = 0.0,
            unit "dB-Hz", range Range::Within(Interval::closed(0.0, 100.0)), at_run_time;
        /// Zenith 1-sigma of a pseudo-range.
        pseudorange_sigma_m: f64 = 3.0, unit "m", range SIGMA, at_run_time;
        /// Zenith 1-sigma of a pseudo-range rate.
        pseudorange_rate_sigma_mps: f64 = 0.1, unit "m/s", range SIGMA, at_run_time;
        /// Scale the zenith sigmas by 1 / sin(elevation).
        elevation_weighting: bool = true, unit "", range ANY, at_run_time;
        /// Use the sigmas the receiver reports with each measurement when present (the
        /// zenith sigmas above otherwise).
        use_receiver_sigmas: bool = false, unit "", range ANY, at_run_time;
        /// Fuse pseudo-range rates as well as pseudo-ranges.
        use_pseudorange_rate: bool = true, unit "", range ANY, at_start;
        /// Reject a measurement whose |innovation| > gate * sqrt(S), S its innovation
        /// variance. 0 = off.
        // Choice: a gate below 1 sigma would reject most good measurements.
        innovation_gate_sigma: f64 = 5.0,
            unit "sigma", range Range::OffOrWithin(Interval::closed(1.0, 1e6)), at_run_time;
        /// Constellations used. Names: gps, glonass, galileo, beidou, qzss, sbas.
        constellations: Vec<Constellation> ["constellations": Vec<ConstellationName>] = vec![
                ConstellationName::Gps,
                ConstellationName::Galileo,
                ConstellationName::Beidou,
            ],
            unit "", range Range::EachOnce, at_start, si ByName;
        /// A pseudo-range step common to all satellites larger than this is absorbed as a
        /// receiver clock jump (receivers jump whole milliseconds, about 300 km).
        max_clock_jump_m: f64 ["clock_jump_threshold_m": f64] = 100_000.0,
            unit "m", range Range::Within(Interval::above(0.0, 1e7)), at_run_time;
        /// Judge each satellite's pseudo-range and rate errors over its last 20 epochs by
        /// the filter's innovations (their part that no error common to all satellites
        /// explains): where their lag-one autocorrelation ρ is significant, multiply the
        /// variance by (1 + ρ)/(1 − ρ), and where their mean square is significantly above
        /// 1, by it too (or by the last 6 epochs' when larger); and every satellite's by at
        /// least the observable's common scale when the median over the last 3 epochs'
        /// satellites is significantly above 1 (entering foliage); and, from the epoch it
        /// is seen, a satellite's by at least 10^(2 (Δ − 3 dB) / 10) when its C/N0 is Δ
        /// below its own recent level (SIGMA-Δ weighting of an obstructed signal). A
        /// filter that takes correlated errors (multipath under foliage, a facade's
        /// reflection) for independent ones claims a precision it does not have, and
        /// follows them: the published covariance is at least what a correlated
        /// satellite's excess beyond its claim gives the position. Counted
        /// (correlated_measurements). false = the variances as the variant gives them
        /// (the papers' filters).
        error_correlation: bool = true, unit "", range ANY, at_start;
        /// Largest factor of that inflation (a variance factor: 25 is σ × 5).
        error_correlation_max_inflation: f64 = 25.0,
            unit "", range Range::Within(Interval::closed(1.0, 1e6)), at_start;
        /// Fuse time-differenced carrier phase (TDCP): each satellite's phase change
        /// between consecutive epochs, a measurement of the antenna's displacement over the
        /// interval (and the receiver clock's change), applied before the epoch's
        /// pseudo-ranges. Needs carrier phase in the measurements; satellites without it,
        /// or with a cycle slip, are left out and counted.
        tdcp: bool = false, unit "", range ANY, at_start;
        /// Zenith 1-sigma of one carrier-phase measurement (the difference of two epochs
        /// has sqrt(2) times it), scaled by elevation as the pseudo-range sigmas.
        tdcp_phase_sigma_m: f64 = 0.01,
            unit "m", range SIGMA, at_run_time;
        /// A phase change further than this from the change the Doppler (pseudo-range
        /// rates of both epochs, trapezoid) predicts is a cycle slip.
        tdcp_slip_threshold_m: f64 = 0.5,
            unit "m", range THRESHOLD, at_run_time;
        /// Epochs further apart than this are not differenced.
        tdcp_max_interval_s: f64 = 1.5,
            unit "s", range Range::Within(Interval::above(0.0, 60.0)), at_run_time;
    }

    /// Weighting of the receiver fix in loose coupling.
    section loose: LooseConfig {
        /// true = weight the receiver fix by the covariance published with it; false = by
        /// the sigmas below.
        use_fix_covariance: bool = true, unit "", range ANY, at_run_time;
        /// Horizontal 1-sigma of a receiver position fix.
        fix_sigma_horizontal_m: f64 = 1.5, unit "m", range SIGMA, at_run_time;
        /// Vertical 1-sigma of a receiver position fix.
        fix_sigma_vertical_m: f64 = 3.0, unit "m", range SIGMA, at_run_time;
        /// 1-sigma of each component of the receiver velocity.
        velocity_sigma_mps: f64 = 0.1, unit "m/s", range SIGMA, at_run_time;
        /// A fix's position (and, on its own, its velocity) whose innovation lies beyond
        /// this Mahalanobis distance d under its innovation covariance is an outlier: its
        /// covariance is scaled by (d / this)^2, so that it pulls as one on the bound
        /// would; counted (fix_position_outliers, fix_velocity_outliers: at 2.8 one in
        /// twenty of a sound receiver's fixes). Not applied by iarf, whose robust R does
        /// the same. 0 = off (the IARF paper's filters).
        // Choice: 2.8, the 95 % quantile of χ²(3) (√7.81), the one the fix judge counts
        // beyond: a clean fix is deweighted with probability 0.05, and then by little.
        // Without it the EKF takes a street canyon's fix 350 m off most of the way. It
        // was 5 (as gnss.innovation_gate_sigma), which let a lone 4.8σ fix, the last
        // before a 60 s outage, set the velocity 0.13 m/s and the pitch 0.05° off: 20 m
        // at the outage's end (consumer-MEMS hour, seed 3). Over the hour's 80 loose
        // rows the sum of the 3D RMSE fell 221.1 → 208.9 m (docs/results.md).
        fix_outlier_sigma: f64 = 2.8,
            unit "sigma", range Range::OffOrWithin(Interval::closed(1.0, 1e6)), at_run_time;
        /// Judge each fix's claimed position (and velocity) covariance by the filter's
        /// innovations: once 4 of the last 10 fixes lie beyond the 95 % quantile of their
        /// χ²(3) (until at most 1 does), the next fix's covariance is scaled by the median
        /// of the factors that make each fix's innovation typical, at most 25 (receivers
        /// claim far too little in foliage), and the published covariance is at least
        /// what the scale adds to the claim; counted (fix_position_rescaled,
        /// fix_velocity_rescaled). false = take the claim as it is (the IARF paper's
        /// filters).
        fix_consistency: bool = true, unit "", range ANY, at_start;
        /// When the fixes leap from agreeing with the filter to beyond 5 sigma of it
        /// without the IMU (or the receiver's velocity) seeing a motion, and out of fixes
        /// that moved little from epoch to epoch, one of the two is wrong: a dispute (WARN
        /// on /diagnostics, published covariance widened by the offset). For at most this
        /// long, until the fixes agree, leap back or scatter like noise, they are held back:
        /// left out until two more epochs confirm it, then moved back by its offset with
        /// their covariance grown by what that offset is known to, so that the filter
        /// follows their motion but not the leap; counted (fix_leap_held). 0 = off: the
        /// fixes are taken as they are (the IARF paper's filters).
        // Choice: 300 s, longer than a street canyon's NLOS bias lasts at driving speed
        // (tests/consumer_mems_hour.rs: 150 s), short enough that a filter that leapt
        // itself (an IMU fault with fixes that carry no velocity) follows the fixes again.
        leap_hold_s: f64 = 300.0,
            unit "s", range Range::OffOrWithin(Interval::closed(1.0, 86400.0)), at_run_time;
    }

    /// Online measurement-noise estimation of the ERMAKF family, used by the variants
    /// eiakf, srmakf and ermakf (ekf ignores this section). Estimates are per satellite
    /// and per observable (pseudo-range, pseudo-range rate).
    section adaptive: AdaptiveConfig {
        /// Window M of the redundant-measurement estimator: the number of second-order
        /// mutual differences (eq. 18) averaged; trades smoothness against sharpness.
        // Choice: a KDE or AR fit on fewer than 10 samples is noise (DESIGN.md pitfalls).
        window_size_m: usize = 100,
            unit "epochs", range Range::Count { min: 10, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Samples needed in a satellite's window before its estimate (and the KDE
        /// verdict) is used; until then the fixed sigmas of gnss.* apply. At least
        /// max(ar_max_order + 2, 10) and at most window_size_m.
        min_samples: usize = 30,
            unit "epochs", range Range::Count { min: 10, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Random weighting of the window (Dirichlet weights, eq. 19) against outliers.
        /// Used by ermakf; srmakf always uses the plain mean (eq. 18).
        random_weighting: bool = true, unit "", range ANY, at_start;
        /// Seed of the random weights (replays are reproducible).
        random_seed: u64 = 0, unit "", range ANY, at_start;
        /// KDE credibility threshold: the newest difference is credible when the window's
        /// kernel density there exceeds that of a Gaussian at this many standard
        /// deviations (section 3.2).
        kde_threshold: f64 = 3.0, unit "sigma", range THRESHOLD, at_start;
        /// Consecutive non-credible epochs that declare the noise non-Gaussian (and
        /// credible epochs that declare it Gaussian again).
        kde_consecutive_epochs: usize = 3,
            unit "epochs", range Range::Count { min: 1, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Highest order of the Burg AR model fitted in the non-Gaussian state (eqs.
        /// 25-27).
        // Choice: at most 100. Burg's recursion costs window x order per satellite and
        // epoch, and an AR fit needs many more samples than its order (the window holds
        // at most 1e4); the criteria pick orders below 10 on GNSS noise.
        ar_max_order: usize = 5, unit "", range Range::Count { min: 1, max: 100 }, at_start;
        /// Criterion choosing the AR order: aic (Akaike, as in the paper) or bic
        /// (Schwarz).
        ar_order_criterion: OrderCriterion = OrderCriterion::Aic, unit "", range ANY, at_start;
        /// Floor of the eq. (29) denominator 1 - sum(a_i beta_i): caps the AR inflation of
        /// the variance at 1/floor.
        ar_denominator_floor: f64 = 0.1,
            unit "", range Range::Within(Interval::closed(1e-3, 1.0)), at_start;
        /// Correlation-aware redundant-measurement estimation (srmakf, ermakf; beyond the
        /// paper): the window's differences over lags 1..variogram_max_lag give the
        /// variance and the correlation of the error together (white + first-order
        /// Gauss-Markov variogram), and R is the whole variance, slow part included.
        /// false = the paper's estimators (one-lag differences keep only 1 - rho1 of a
        /// correlated error's variance).
        correlation_aware: bool = false, unit "", range ANY, at_start;
        /// Longest lag of the correlation-aware variogram; at most a third of the window
        /// is used. Correlation times beyond it are not identified.
        variogram_max_lag: usize = 20,
            unit "epochs", range Range::Count { min: 1, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Innovation window of the eiakf (innovation-based) estimator.
        innovation_window: usize = 50,
            unit "epochs", range Range::Count { min: 10, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Significance level of the eiakf whiteness test of the innovations, and of its
        /// test that their variance exceeds H P⁻ Hᵀ (otherwise the nominal σ is used).
        innovation_significance: f64 = 0.05,
            unit "", range Range::Within(Interval::closed(1e-6, 0.5)), at_start;
        /// Lower bound on an estimated pseudo-range 1-sigma.
        pseudorange_sigma_min_m: f64 = 0.3, unit "m", range SIGMA, at_start;
        /// Upper bound on an estimated pseudo-range 1-sigma (at least the lower one).
        pseudorange_sigma_max_m: f64 = 150.0, unit "m", range SIGMA, at_start;
        /// Lower bound on an estimated pseudo-range-rate 1-sigma.
        pseudorange_rate_sigma_min_mps: f64 = 0.02, unit "m/s", range SIGMA, at_start;
        /// Upper bound on an estimated pseudo-range-rate 1-sigma (at least the lower one).
        pseudorange_rate_sigma_max_mps: f64 = 10.0, unit "m/s", range SIGMA, at_start;
        /// Zenith 1-sigma of the slowly varying part of the pseudo-range error
        /// (atmosphere-model residuals, long-period multipath, orbit and clock errors):
        /// the estimators learn from epoch differences or innovations, which do not see
        /// it, so its variance, scaled by elevation as gnss.pseudorange_sigma_m, is added
        /// to every estimated pseudo-range variance (eiakf, srmakf, ermakf,
        /// residual_akf). 0 = the papers' estimates used as they are.
        // Choice: 1.5 m, beyond the papers (they assume white range errors and set no
        // floor on R). A filter treating a slow error as white averages it over its
        // memory, so the variance it must be given exceeds the error's own: on the
        // simulated open-sky drive the slow part (20 % of the ionosphere left by the
        // Klobuchar model) is 0.9-2.4 m per satellite and constant over minutes, the
        // estimators find the white part (0.5-2 m) within 10 %, and 1.5 m at the zenith
        // is the smallest of the values tried (0.9-3 m) that puts the NEES of srmakf,
        // ermakf and residual_akf inside its 95 % bounds on over 90 % of the epochs
        // (docs/results.md). An addition rather than max(R, floor): the estimate is of
        // the white part, and the variances of independent parts add.
        pseudorange_slow_sigma_m: f64 = 1.5,
            unit "m", range Range::Within(Interval::closed(0.0, 1e3)), at_start;
        /// Longest gap between two epochs of a satellite across which a mutual difference
        /// is still formed; a longer gap restarts that satellite's window.
        max_epoch_gap_s: f64 = 2.0,
            unit "s", range Range::Within(Interval::closed(1e-3, 3600.0)), at_start;
    }

    /// Constants of the IARF paper's schemes (variants akf_all, akf_partial, iarf) and of
    /// Ding's residual R (residual_akf) and Q scaling (filter.q_scaling). Other variants
    /// ignore this section. All are dimensionless.
    section robust: RobustConfig {
        /// Adaptive factor alpha of the predicted-residual statistic dV (section 2.2):
        /// two_segment = eq. (9), alpha = 1 for dV <= c, c/dV above; three_segment = eq.
        /// (10), 1 below c0, (c0/dV)((c1-dV)/(c1-c0))^2 between, 0 above c1.
        adaptive_factor_function: AdaptiveFactorKind = AdaptiveFactorKind::TwoSegment,
            unit "", range ANY, at_start;
        /// Threshold c of the two-segment factor; the paper gives 1.0-1.5 and uses 1.0.
        adaptive_factor_c: f64 = 1.0, unit "", range THRESHOLD, at_start;
        /// Threshold c0 of the three-segment factor; the paper gives 1.0-1.5.
        adaptive_factor_c0: f64 = 1.0, unit "", range THRESHOLD, at_start;
        /// Threshold c1 > c0 of the three-segment factor; the paper gives 3.0-8.5.
        adaptive_factor_c1: f64 = 3.0, unit "", range THRESHOLD, at_start;
        /// Floor of alpha: P-/alpha inflates the prior at most 1/floor times (the paper
        /// lets alpha reach 0, an infinite prior).
        alpha_floor: f64 = 0.01, unit "", range FRACTION, at_start;
        /// Robust equivalent covariance of iarf (section 3): double_factor = the paper's
        /// lambda_ii = 1 for |v| <= c, |v|/c above (v the standardized predicted
        /// residual), lambda_ij = sqrt(lambda_ii lambda_jj), R_bar = lambda_ij R; igg3 =
        /// Yang's IGG-III weights (k0, k1) in the same double-factor form.
        equivalent_weight_function: EquivalentWeightKind = EquivalentWeightKind::DoubleFactor,
            unit "", range ANY, at_start;
        /// Threshold c of the double factor; the paper gives 1.0-1.5.
        double_factor_c: f64 = 1.5, unit "", range THRESHOLD, at_start;
        /// IGG-III threshold k0 (weight 1 below k0).
        igg3_k0: f64 = 1.5, unit "", range THRESHOLD, at_start;
        /// IGG-III threshold k1 > k0 (weight 0 above k1).
        igg3_k1: f64 = 3.0, unit "", range THRESHOLD, at_start;
        /// Largest variance inflation lambda_ii (a zero weight becomes this inflation, so
        /// R_bar stays finite and positive definite).
        max_variance_inflation: f64 = 1e6, unit "", range FACTOR_MAX, at_start;
        /// Confidence of the Mahalanobis test M^2 <= chi2(confidence, dimension) that
        /// decides whether akf_partial and iarf apply the adaptive factor; 1 - confidence
        /// is the false-alarm rate on healthy epochs.
        // Choice: a confidence below one half would raise alarms on most healthy epochs.
        chi2_confidence: f64 = 0.95,
            unit "", range Range::Within(Interval::below(0.5, 1.0)), at_start;
        /// Window m of residual_akf (eq. 15): a satellite's (or the fix's) estimate is used
        /// once its window is full; until then the nominal R.
        // Choice: a second moment from fewer than 5 epochs is noise (spread above 60 %).
        residual_window_epochs: usize = 64,
            unit "epochs", range Range::Count { min: 5, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Window m of the Q-scaling factor alpha (eq. 19); Q is rescaled once per full
        /// window.
        q_window_epochs: usize = 64,
            unit "epochs", range Range::Count { min: 5, max: MAX_WINDOW_EPOCHS }, at_start;
        /// Lower bound on one window's alpha (Q changes by sqrt(alpha) per window).
        q_alpha_min: f64 = 0.01, unit "", range FRACTION, at_start;
        /// Upper bound on one window's alpha.
        q_alpha_max: f64 = 100.0, unit "", range FACTOR_MAX, at_start;
        /// Lower bound on the accumulated factor on the configured Q.
        q_scale_min: f64 = 0.001, unit "", range FRACTION, at_start;
        /// Upper bound on the accumulated factor on the configured Q.
        q_scale_max: f64 = 1000.0, unit "", range FACTOR_MAX, at_start;
    }

    /// Start-up (alignment) and the initial 1-sigma of every state block.
    section init: InitConfig {
        /// Known initial heading of the body x axis, clockwise from true north (compass;
        /// 0 = north, 90 = east; ENU yaw = 90 deg - heading). null = a dual-antenna
        /// heading, else at rest the gyrocompass's (the earth rate's direction in the
        /// levelling's mean rate; only when its 1-sigma from the imu.gyro_* noise is
        /// below 1 deg, which navigation-grade gyros reach), else taken from the GNSS
        /// velocity once the speed exceeds heading_min_speed_mps.
        heading_rad: Option<f64> ["heading_deg": Option<f64>] = None,
            unit "deg", range Range::Within(Interval::closed(-360.0, 360.0)), at_start,
            si Scale::to("rad", RAD_PER_DEG);
        /// Speed above which the GNSS velocity gives the initial heading.
        heading_min_speed_mps: f64 = 1.0,
            unit "m/s", range Range::Within(Interval::above(0.0, 1e3)), at_start;
        /// Accelerometer averaging at rest for the initial roll and pitch.
        leveling_duration_s: f64 = 1.0,
            unit "s", range Range::Within(Interval::closed(1e-3, 3600.0)), at_start;
        /// Satellites needed for the single-point solution that starts the filter.
        // Choice: at most 64. A single-point solution needs 4; no place on Earth sees much
        // more than 60 satellites of all six systems at once, so a start that needs more
        // would never happen (the error names this parameter instead of "nothing usable").
        min_satellites: usize = 5,
            unit "satellites", range Range::Count { min: 4, max: 64 }, at_start;
        /// Initial 1-sigma of roll and pitch.
        attitude_sigma_rad: f64 ["attitude_sigma_deg": f64] = 1.0,
            unit "deg", range Range::Within(Interval::closed(1e-9, 180.0)), at_start,
            si Scale::to("rad", RAD_PER_DEG);
        /// Initial 1-sigma of heading.
        heading_sigma_rad: f64 ["heading_sigma_deg": f64] = 5.0,
            unit "deg", range Range::Within(Interval::closed(1e-9, 180.0)), at_start,
            si Scale::to("rad", RAD_PER_DEG);
        /// Initial 1-sigma of each velocity component.
        velocity_sigma_mps: f64 = 0.5, unit "m/s", range SIGMA, at_start;
        /// Least initial 1-sigma of the position: of each component of the receiver's fix
        /// a loosely-coupled start takes, and of the components' mean (the root of their
        /// mean variance) of each single-point solution a tightly-coupled start combines.
        position_sigma_m: f64 = 5.0, unit "m", range SIGMA, at_start;
        /// Initial 1-sigma of the receiver clock bias c*dt_u.
        clock_bias_sigma_m: f64 = 30.0, unit "m", range SIGMA, at_start;
        /// Initial 1-sigma of the receiver clock drift c*dt_ru.
        clock_drift_sigma_mps: f64 = 5.0, unit "m/s", range SIGMA, at_start;
    }

    /// Buffering and gaps of the input streams.
    section engine: EngineConfig {
        /// How far back a late GNSS epoch may reach into the IMU history.
        // Choice: at most a minute: GNSS latency is well below a second, and the history
        // is kept in memory (a minute of a 1 kHz IMU is 60,000 samples).
        imu_buffer_s: f64 = 2.0,
            unit "s", range Range::Within(Interval::closed(1e-3, 60.0)), at_start;
        /// A larger gap between IMU samples is rejected (the filter coasts or
        /// re-initialises).
        // Choice: at least 1 ms (a 1 kHz IMU's period): a smaller limit rejects every
        // sample and the filter never starts.
        max_imu_gap_s: f64 = 1.0,
            unit "s", range Range::Within(Interval::closed(1e-3, 60.0)), at_run_time;
    }

    /// What is published and where the local frame sits.
    section output: OutputConfig {
        /// Origin of the local ENU frame of the odometry: [latitude, longitude, height
        /// above the WGS84 ellipsoid]. null = the first fix.
        // Choice: heights from 10 km below the ellipsoid to 100 km above it (the edge of
        // space); anything else is a unit or sign mistake.
        datum: Option<Llh> ["datum_llh_deg_m": Option<[f64; 3]>] = None,
            unit "[deg, deg, m]",
            range Range::Components([
                ("latitude", Interval::closed(-90.0, 90.0), "deg"),
                ("longitude", Interval::closed(-180.0, 180.0), "deg"),
                ("height", Interval::closed(-1e4, 1e5), "m"),
            ]),
            at_start, si LlhDegToPosition;
        /// Output rate. 0 = every IMU sample.
        // Choice: at most 10 kHz, above any IMU's rate.
        rate_hz: f64 = 0.0,
            unit "Hz", range Range::Within(Interval::closed(0.0, 1e4)), at_run_time;
    }
}
