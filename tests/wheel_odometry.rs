//! Issue 14, item 3: the base controller's wheel speed (`wheel_odometry.*`) on the
//! simulated consumer-MEMS car of tests/motion_constraints.rs (loosely coupled with the
//! receiver's velocities, params/imu_consumer_mems.yaml), through its 30 s GNSS outage at
//! 12 m/s ending in a turn (tests/data/consumer_mems_car_outage.yaml). The wheel speed is
//! the true forward speed at the truth's 10 Hz plus white noise of [`WHEEL_SIGMA_MPS`]:
//! - with wheel speeds (and no other constraint) the horizontal error at the outage's end
//!   stays within issue 14's figure, 1 % of the distance travelled in it; free inertial
//!   it does not; with the non-holonomic constraint as well it is smaller than with the
//!   constraint alone;
//! - wheel speeds with `wheel_odometry.enabled` off are rejected and counted, and the run
//!   is identical to the bit to one without them;
//! - bad wheel speeds (NaN speed, stamp or σ, a negative or zero σ, an infinite one) are
//!   rejected and counted, and the run is identical to the bit to one without them.
//! - `wheel_odometry.scale_factor` undoes a wheel radius error, and
//!   `wheel_odometry.scale_factor_state` learns one while GNSS is present.

mod car_outage_support;

use adaptive_gnss_ins::config::{Config, Platform};
use adaptive_gnss_ins::engine::{RejectionCounters, RejectionReason};
use adaptive_gnss_ins::eval::SolutionError;
use adaptive_gnss_ins::sim::Scenario;
use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
use adaptive_gnss_ins::tools::scoring::Reference;
use adaptive_gnss_ins::tools::session::{Session, SessionInput};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use adaptive_gnss_ins::ins::error_state::WHEEL_SCALE;
use car_outage_support::{
    at_outage_end_m, consumer_mems_loose, outage_distance_m, spec, CAR_OUTAGE, MAX_ERROR_FRACTION,
    OUTAGE_START_S, SEED,
};

/// The wheel speed's white noise (m/s), given with each speed as its σ.
const WHEEL_SIGMA_MPS: f64 = 0.05;

fn with_wheels(mut config: Config) -> Config {
    config.wheel_odometry.enabled = true;
    config
}

fn car(mut config: Config) -> Config {
    config.constraints.platform = Platform::Car;
    config
}

/// A wheel whose radius is 3 % small: it reports 0.97 of the true speed.
const REPORTED_PER_TRUE: f64 = 0.97;

/// What the wheels feed: the true speed's wheel readings (times a factor: a wheel whose
/// radius is off), and bad ones besides.
#[derive(Clone, Copy, PartialEq)]
enum Wheels {
    None,
    Speeds,
    Scaled(f64),
    SpeedsAndBad,
}

/// Bad readings (stamp offset from a good one, speed, σ): each is rejected as invalid.
const BAD: [(f64, f64, Option<f64>); 6] = [
    (0.01, f64::NAN, None),
    (0.02, 12.0, Some(f64::NAN)),
    (0.03, 12.0, Some(-0.1)),
    (0.04, 12.0, Some(0.0)),
    (0.05, 12.0, Some(f64::INFINITY)),
    (f64::NAN, 12.0, None),
];

/// What a drive gives.
struct Drive {
    errors: Vec<SolutionError>,
    counters: RejectionCounters,
    /// The filter's wheel scale factor and its σ when the outage starts.
    scale_factor_at_outage: (f64, f64),
}

/// The car's drive with `config` and `wheels`.
fn drive(config: Config, wheels: Wheels) -> Drive {
    let scenario = Scenario::new(spec(CAR_OUTAGE), SEED).unwrap();
    let mut scale_factor_at_outage = (f64::NAN, f64::NAN);
    let mut session = Session::new(config, 0.0, None);
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let noise = Normal::new(0.0, WHEEL_SIGMA_MPS).unwrap();
    for input in scenario_inputs(&scenario) {
        let input = input.unwrap();
        let truth = match &input {
            SessionInput::Reference(Reference::Truth(t)) => Some(*t),
            _ => None,
        };
        session.push(input);
        if let Some(state) = session
            .engine()
            .state()
            .filter(|_| truth.is_some_and(|t| t.t_s <= OUTAGE_START_S) && wheels != Wheels::None)
        {
            let sigma = state.p[(WHEEL_SCALE, WHEEL_SCALE)].sqrt();
            scale_factor_at_outage = (state.wheel_scale_factor, sigma);
        }
        let Some(truth) = truth.filter(|_| wheels != Wheels::None) else {
            continue;
        };
        let (v_n, q_nb) = (truth.v_n.unwrap(), truth.q_nb.unwrap());
        let forward_mps = q_nb.inverse_transform_vector(&v_n).x;
        let reported_per_true = match wheels {
            Wheels::Scaled(factor) => factor,
            _ => 1.0,
        };
        session.push(SessionInput::WheelSpeed {
            t_s: truth.t_s,
            speed_mps: reported_per_true * forward_mps + noise.sample(&mut rng),
            sigma_mps: Some(WHEEL_SIGMA_MPS),
        });
        if wheels == Wheels::SpeedsAndBad {
            for (dt_s, speed_mps, sigma_mps) in BAD {
                session.push(SessionInput::WheelSpeed {
                    t_s: truth.t_s + dt_s,
                    speed_mps,
                    sigma_mps,
                });
            }
        }
    }
    let counters = session.engine().counters().clone();
    let errors = session.finish().into_solution_errors();
    Drive {
        errors,
        counters,
        scale_factor_at_outage,
    }
}

#[test]
fn wheel_speeds_bound_a_cars_outage() {
    let error_m = |config: Config, wheels: Wheels| at_outage_end_m(&drive(config, wheels).errors);
    let free_m = error_m(consumer_mems_loose(), Wheels::None);
    let wheels_m = error_m(with_wheels(consumer_mems_loose()), Wheels::Speeds);
    let nhc_m = error_m(car(consumer_mems_loose()), Wheels::None);
    let nhc_wheels_m = error_m(car(with_wheels(consumer_mems_loose())), Wheels::Speeds);
    let distance_m = outage_distance_m();
    println!(
        "horizontal error at the outage's end ({distance_m} m travelled): free inertial \
         {free_m:.2} m, wheel speed {wheels_m:.2} m ({:.2} %); NHC {nhc_m:.2} m, NHC and \
         wheel speed {nhc_wheels_m:.2} m",
        100.0 * wheels_m / distance_m
    );
    let bound_m = MAX_ERROR_FRACTION * distance_m;
    assert!(wheels_m <= bound_m, "wheel speed: {wheels_m:.2} m");
    // Without the wheel speed the same figure fails.
    assert!(free_m > bound_m, "free inertial: {free_m:.2} m");
    assert!(
        nhc_wheels_m < nhc_m,
        "NHC and wheel speed {nhc_wheels_m:.2} m, NHC {nhc_m:.2} m"
    );
}

#[test]
fn wheel_speeds_switched_off_are_counted_and_change_nothing() {
    let plain = drive(consumer_mems_loose(), Wheels::None).errors;
    let Drive {
        errors: off,
        counters,
        ..
    } = drive(consumer_mems_loose(), Wheels::Speeds);
    assert!(!plain.is_empty());
    assert_eq!(off, plain);
    let off_count = counters.count(RejectionReason::WheelOdometryOff);
    println!("wheel speeds rejected while off: {off_count}");
    // The truth's 10 Hz over the 240 s drive.
    assert!(off_count > 2000, "{off_count}");
}

#[test]
fn bad_wheel_speeds_are_counted_and_change_nothing() {
    let Drive {
        errors: clean,
        counters: clean_counters,
        ..
    } = drive(with_wheels(consumer_mems_loose()), Wheels::Speeds);
    let Drive {
        errors: bad,
        counters,
        ..
    } = drive(with_wheels(consumer_mems_loose()), Wheels::SpeedsAndBad);
    assert!(!clean.is_empty());
    assert_eq!(bad, clean);
    let good_count = clean_counters.count(RejectionReason::WheelSpeedBeforeStart);
    let invalid = counters.count(RejectionReason::WheelSpeedInvalid);
    println!(
        "wheel speeds before the start: {good_count}; bad ones rejected as invalid: {invalid}"
    );
    assert_eq!(clean_counters.count(RejectionReason::WheelSpeedInvalid), 0);
    assert!(invalid > 2000 * BAD.len() as u64, "{invalid}");
    // Every bad reading is refused before anything else looks at it.
    assert_eq!(
        counters.total() - clean_counters.total(),
        invalid,
        "{counters:?}"
    );
}

/// A wheel whose radius is 3 % small reports 3 % too slow: `wheel_odometry.scale_factor`
/// undoes it (within 10 cm of the run with true speeds); without it the error at the
/// outage's end grows by metres: the speeds' σ (5 cm/s) is far below their bias (36 cm/s
/// at 12 m/s), the filter believes them and the GNSS before the outage cannot pull it
/// back (measured 41 m, worse than free inertial: what the scale-factor state fixes).
#[test]
fn the_scale_factor_undoes_a_wheel_radius_error() {
    let error_m = |config: Config, wheels: Wheels| at_outage_end_m(&drive(config, wheels).errors);
    let true_m = error_m(with_wheels(consumer_mems_loose()), Wheels::Speeds);
    let mut scaled = with_wheels(consumer_mems_loose());
    scaled.wheel_odometry.scale_factor = 1.0 / REPORTED_PER_TRUE;
    let scaled_m = error_m(scaled, Wheels::Scaled(REPORTED_PER_TRUE));
    let unscaled_m = error_m(
        with_wheels(consumer_mems_loose()),
        Wheels::Scaled(REPORTED_PER_TRUE),
    );
    println!(
        "horizontal error at the outage's end, wheels 3 % slow: scale factor set {scaled_m:.2} \
         m, not set {unscaled_m:.2} m; true speeds {true_m:.2} m"
    );
    assert!((scaled_m - true_m).abs() < 0.1, "{scaled_m:.2} m");
    assert!(unscaled_m > true_m + 3.0, "{unscaled_m:.2} m");
}

/// The same 3 % slow wheels with `wheel_odometry.scale_factor_state` and the factor left at
/// 1: the 125 s with GNSS before the outage (wheel speeds against the receiver's
/// velocities) teach the filter the factor, within a few tenths of a percent of the true
/// 1/0.97 and within its own 3σ, and the outage ends within issue 14's 1 % figure (1.03 m
/// measured, against 0.54 m with true speeds) instead of 41 m off. With the state off the
/// same run is the 41 m one.
#[test]
fn the_scale_factor_state_learns_a_wheel_radius_error() {
    let true_m = at_outage_end_m(&drive(with_wheels(consumer_mems_loose()), Wheels::Speeds).errors);
    let mut learning = with_wheels(consumer_mems_loose());
    learning.wheel_odometry.scale_factor_state = true;
    let learned = drive(learning.clone(), Wheels::Scaled(REPORTED_PER_TRUE));
    let learned_m = at_outage_end_m(&learned.errors);
    let (factor, sigma) = learned.scale_factor_at_outage;
    let unlearned = drive(
        with_wheels(consumer_mems_loose()),
        Wheels::Scaled(REPORTED_PER_TRUE),
    );
    let unlearned_m = at_outage_end_m(&unlearned.errors);
    let truth = 1.0 / REPORTED_PER_TRUE;
    let relative_error = (factor - truth) / truth;
    println!(
        "wheels 3 % slow: scale factor at the outage's start {factor:.5} (true {truth:.5}, \
         error {:.3} %, sigma {:.3} %); horizontal error at the outage's end with the state \
         {learned_m:.2} m, without {unlearned_m:.2} m; true speeds {true_m:.2} m",
        100.0 * relative_error,
        100.0 * sigma / truth,
    );
    assert!(relative_error.abs() < 0.003, "{factor}");
    assert!((factor - truth).abs() < 3.0 * sigma, "{factor} +- {sigma}");
    // Issue 14's figure (1 % of the 360 m), where the unlearned factor is far beyond it.
    let bound_m = MAX_ERROR_FRACTION * outage_distance_m();
    assert!(learned_m <= bound_m, "{learned_m:.2} m");
    assert!(unlearned_m > bound_m, "{unlearned_m:.2} m");
    assert!(unlearned_m > true_m + 3.0, "{unlearned_m:.2} m");
    // The state off: the factor stays at wheel_odometry.scale_factor.
    assert_eq!(unlearned.scale_factor_at_outage, (1.0, 0.0));
    // True speeds: the state finds no error to learn.
    let calibrated = drive(learning, Wheels::Speeds);
    let (factor, _) = calibrated.scale_factor_at_outage;
    println!("true speeds: scale factor at the outage's start {factor:.5}");
    assert!((factor - 1.0).abs() < 0.003, "{factor}");
}
