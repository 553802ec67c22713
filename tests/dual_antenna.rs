//! Issue 14, item 4 (second half): the heading of a dual-antenna (moving-base) receiver
//! pair (`dual_antenna.*`) on the simulated consumer-MEMS car of tests/motion_constraints.rs
//! (loosely coupled with the receiver's velocities, params/imu_consumer_mems.yaml). The
//! simulator's pair (the scenario's `dual_antenna`) reports the heading of a 1 m baseline
//! along the body's x axis at each fix, with an error of [`HEADING_SIGMA_DEG`]:
//! - parked from the start, no GNSS course exists: without the pair the filter never
//!   starts (no heading); with it the start takes the pair's heading;
//! - parked from the start with a configured heading 15° off (and a σ that says so) and
//!   the zero-velocity updates holding the heading, the heading converges to the truth
//!   with the pair and stays off without it;
//! - on the drive through the 30 s outage the heading error stays small;
//! - bad readings (NaN heading or σ, zero or absurd σ, a float solution, a baseline of
//!   the wrong length) are rejected and counted and change nothing to the bit; a heading
//!   90° off is gated, counted and moves the heading by nothing visible (no jump).

mod car_outage_support;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::engine::{
    BaselineHeadingReading, CarrierSolution, RejectionCounters, RejectionReason,
};
use adaptive_gnss_ins::eval::SolutionError;
use adaptive_gnss_ins::sim::{DualAntennaSpec, Scenario, ScenarioSpec, Segment};
use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
use adaptive_gnss_ins::tools::session::{Session, SessionInput};

use car_outage_support::{consumer_mems_loose, spec, CAR_OUTAGE, OUTAGE_END_S, SEED};

/// The simulated pair's heading error (1-sigma, deg), reported as its accuracy.
const HEADING_SIGMA_DEG: f64 = 0.3;
/// How long the parked car stands (s).
const PARKED_S: f64 = 180.0;

fn with_pair(mut spec: ScenarioSpec) -> ScenarioSpec {
    spec.dual_antenna = Some(DualAntennaSpec {
        baseline_m: [1.0, 0.0, 0.0],
        heading_sigma_deg: HEADING_SIGMA_DEG,
    });
    spec
}

fn enabled(mut config: Config) -> Config {
    config.dual_antenna.enabled = true;
    config
}

/// The consumer-MEMS car standing still with GNSS for [`PARKED_S`], with a pair.
fn parked_from_start() -> ScenarioSpec {
    let mut spec = with_pair(spec("tests/data/consumer_mems_parked.yaml"));
    spec.trajectory.segments = vec![Segment::Stationary {
        duration_s: PARKED_S,
    }];
    spec.environments.clear();
    spec
}

/// What to add to the pair's readings.
#[derive(Clone, Copy, PartialEq)]
enum Extra {
    None,
    /// After each reading, the bad ones of [`bad_readings`].
    Bad,
    /// Every tenth reading turned 90°.
    Turned,
}

/// Readings the engine refuses, each after the good `r`, and why.
fn bad_readings(r: &BaselineHeadingReading) -> [(BaselineHeadingReading, RejectionReason); 7] {
    let at = |dt_s: f64| BaselineHeadingReading {
        t_s: r.t_s + dt_s,
        ..*r
    };
    [
        (
            BaselineHeadingReading {
                heading_rad: f64::NAN,
                ..at(0.01)
            },
            RejectionReason::BaselineHeadingInvalid,
        ),
        (
            BaselineHeadingReading {
                sigma_rad: f64::NAN,
                ..at(0.02)
            },
            RejectionReason::BaselineHeadingInvalid,
        ),
        (
            BaselineHeadingReading {
                sigma_rad: 0.0,
                ..at(0.03)
            },
            RejectionReason::BaselineHeadingInvalid,
        ),
        (
            BaselineHeadingReading {
                t_s: f64::NAN,
                ..*r
            },
            RejectionReason::BaselineHeadingInvalid,
        ),
        (
            BaselineHeadingReading {
                sigma_rad: 30f64.to_radians(),
                ..at(0.04)
            },
            RejectionReason::BaselineHeadingInaccurate,
        ),
        (
            BaselineHeadingReading {
                carrier: CarrierSolution::Float,
                ..at(0.05)
            },
            RejectionReason::BaselineHeadingFloat,
        ),
        (
            BaselineHeadingReading {
                length_m: 2.0,
                ..at(0.06)
            },
            RejectionReason::BaselineLengthMismatch,
        ),
    ]
}

/// What a replay gives: the solution errors, the rejections and the pair's readings.
struct Run {
    errors: Vec<SolutionError>,
    counters: RejectionCounters,
    readings: u64,
}

/// `spec` replayed with `config` and `extra`.
fn run(spec: ScenarioSpec, config: Config, extra: Extra) -> Run {
    let scenario = Scenario::new(spec, SEED).unwrap();
    let mut session = Session::new(config, 0.0, None);
    let mut readings = 0;
    for input in scenario_inputs(&scenario) {
        let input = input.unwrap();
        let SessionInput::BaselineHeading(reading) = input else {
            session.push(input);
            continue;
        };
        readings += 1;
        match extra {
            Extra::Turned if readings % 10 == 0 => {
                session.push(SessionInput::BaselineHeading(BaselineHeadingReading {
                    heading_rad: reading.heading_rad + std::f64::consts::FRAC_PI_2,
                    ..reading
                }));
            }
            _ => {
                session.push(input);
            }
        }
        if extra == Extra::Bad {
            for (bad, _) in bad_readings(&reading) {
                session.push(SessionInput::BaselineHeading(bad));
            }
        }
    }
    let counters = session.engine().counters().clone();
    let errors = session.finish().into_solution_errors();
    Run {
        errors,
        counters,
        readings,
    }
}

fn yaw_error_deg(e: &SolutionError) -> f64 {
    e.attitude_rpy_rad.unwrap().z.to_degrees()
}

fn max_yaw_error_deg(errors: &[SolutionError]) -> f64 {
    errors
        .iter()
        .map(|e| yaw_error_deg(e).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_car_parked_from_the_start_takes_its_heading_from_the_pair() {
    let without = run(parked_from_start(), consumer_mems_loose(), Extra::None);
    let off = without.counters.count(RejectionReason::DualAntennaOff);
    assert_eq!(off, without.readings);
    let (without, with) = (
        without.errors,
        run(
            parked_from_start(),
            enabled(consumer_mems_loose()),
            Extra::None,
        )
        .errors,
    );
    println!(
        "parked {PARKED_S} s from the start: without the pair {} solutions ({off} headings \
         rejected as off); with it {} solutions from t = {:.1} s, heading error at most \
         {:.3} deg, at the end {:.3} deg",
        without.len(),
        with.len(),
        with.first().map_or(f64::NAN, |e| e.t_s),
        max_yaw_error_deg(&with),
        with.last().map_or(f64::NAN, yaw_error_deg),
    );
    assert!(without.is_empty(), "no heading: the filter must not start");
    assert!(off as f64 > 0.9 * PARKED_S, "{off}");
    // The start waits for the levelling only (a few seconds).
    assert!(with.first().unwrap().t_s < 10.0);
    assert!(max_yaw_error_deg(&with) < 3.0 * HEADING_SIGMA_DEG);
}

#[test]
fn a_wrong_heading_at_rest_converges_with_the_pair_only() {
    // The configured heading 15° off, with a σ of 10° (above, the start would run the
    // bank of heading hypotheses): the zero-velocity and zero-rate updates hold the
    // heading at rest but cannot find it.
    let config = |pair: bool| {
        let mut config = consumer_mems_loose();
        config.constraints.zupt = true;
        // The scenario's car faces west (ENU yaw 180°: compass 270°).
        config.init.heading_rad = Some(285f64.to_radians());
        config.init.heading_sigma_rad = 10f64.to_radians();
        config.dual_antenna.enabled = pair;
        config
    };
    let without = run(parked_from_start(), config(false), Extra::None).errors;
    let Run {
        errors: with,
        counters,
        ..
    } = run(parked_from_start(), config(true), Extra::None);
    let converged_s = with
        .iter()
        .rev()
        .find(|e| yaw_error_deg(e).abs() >= 1.0)
        .map_or(with[0].t_s, |e| e.t_s);
    let at = |errors: &[SolutionError], t_s| yaw_error_deg(car_outage_support::at(errors, t_s));
    let end = |errors: &[SolutionError]| yaw_error_deg(errors.last().unwrap());
    println!(
        "parked, configured heading 15 deg off: heading error with the pair {:.3} deg at the \
         first solution (t = {:.1} s), within 1 deg from t = {converged_s:.1} s, {:.3} deg at \
         the end; without it {:.3} deg at the first solution (t = {:.1} s), {:.3} deg at t = \
         10 s, {:.3} deg at 60 s, {:.3} deg at the end",
        yaw_error_deg(&with[0]),
        with[0].t_s,
        end(&with),
        yaw_error_deg(&without[0]),
        without[0].t_s,
        at(&without, 10.0),
        at(&without, 60.0),
        end(&without)
    );
    // Without the pair the heading stays off by more than ten of the pair's σ.
    assert!(end(&without).abs() > 10.0 * HEADING_SIGMA_DEG);
    assert!(end(&with).abs() < 3.0 * HEADING_SIGMA_DEG);
    assert!(converged_s < 30.0, "{converged_s}");
    assert_eq!(counters.count(RejectionReason::BaselineHeadingGated), 0);
}

#[test]
fn the_heading_stays_close_on_a_drive() {
    let drive = |config: Config| run(with_pair(spec(CAR_OUTAGE)), config, Extra::None).errors;
    let with = drive(enabled(consumer_mems_loose()));
    let without = drive(consumer_mems_loose());
    let rms_deg = |errors: &[SolutionError]| {
        (errors.iter().map(|e| yaw_error_deg(e).powi(2)).sum::<f64>() / errors.len() as f64).sqrt()
    };
    let end_of_outage =
        |errors: &[SolutionError]| yaw_error_deg(car_outage_support::at(errors, OUTAGE_END_S));
    println!(
        "drive: heading error with the pair RMS {:.3} deg, max {:.3} deg, at the outage's end \
         {:.3} deg; without RMS {:.3} deg, max {:.3} deg, at the outage's end {:.3} deg",
        rms_deg(&with),
        max_yaw_error_deg(&with),
        end_of_outage(&with),
        rms_deg(&without),
        max_yaw_error_deg(&without),
        end_of_outage(&without),
    );
    assert!(max_yaw_error_deg(&with) < 1.0);
    assert!(rms_deg(&with) < rms_deg(&without));
}

#[test]
fn bad_headings_are_counted_and_never_a_jump() {
    let drive = |extra: Extra| {
        run(
            with_pair(spec(CAR_OUTAGE)),
            enabled(consumer_mems_loose()),
            extra,
        )
    };
    let clean = drive(Extra::None);
    let bad = drive(Extra::Bad);
    assert!(clean.readings > 100, "{}", clean.readings);
    assert_eq!(bad.errors, clean.errors);
    // Each reason as often as it appears among the bad readings of one good one.
    let mut per_reading = std::collections::BTreeMap::new();
    for (_, reason) in bad_readings(&BaselineHeadingReading {
        t_s: 0.0,
        heading_rad: 0.0,
        sigma_rad: 0.01,
        length_m: 1.0,
        carrier: CarrierSolution::Fixed,
    }) {
        *per_reading.entry(reason).or_insert(0u64) += 1;
    }
    let added = |reason| bad.counters.count(reason) - clean.counters.count(reason);
    for (&reason, n) in &per_reading {
        println!("{}: {}", reason.name(), added(reason));
        assert_eq!(added(reason), n * clean.readings, "{}", reason.name());
    }
    // Nothing else was rejected.
    assert_eq!(
        bad.counters.total() - clean.counters.total(),
        7 * clean.readings
    );

    let Run {
        errors: turned,
        counters,
        ..
    } = drive(Extra::Turned);
    let clean = clean.errors;
    let gated = counters.count(RejectionReason::BaselineHeadingGated);
    let worst_deg = clean
        .iter()
        .zip(&turned)
        .map(|(c, t)| (yaw_error_deg(t) - yaw_error_deg(c)).abs())
        .fold(0.0, f64::max);
    println!("headings turned 90 deg: {gated} gated, heading moved by at most {worst_deg:.4} deg");
    assert!(gated > 10, "{gated}");
    assert!(worst_deg < 0.1, "{worst_deg}");
}

/// Without a pair, parked, with a configured heading 20° off and a σ of 20° (above the
/// heading bank's threshold): the bank cannot tell the headings apart at rest and starts
/// at its time limit; its start must stay consistent with the prior it was given (within
/// its 3σ), and its covariance must cover the error (9-dof NEES within the χ² bound of
/// 99.73 %, 25.3). With equally weighted hypotheses the noise chose one 72° off.
#[test]
fn a_heading_bank_at_rest_stays_with_its_prior() {
    let mut config = consumer_mems_loose();
    config.constraints.zupt = true;
    // The scenario's car faces west (compass 270°).
    config.init.heading_rad = Some(290f64.to_radians());
    config.init.heading_sigma_rad = 20f64.to_radians();
    let errors = run(parked_from_start(), config, Extra::None).errors;
    let first = errors.first().expect("the bank starts at its time limit");
    println!(
        "bank at rest: first solution at t = {:.1} s, heading error {:.1} deg, NEES {:.1}",
        first.t_s,
        yaw_error_deg(first),
        first.nees
    );
    assert!(yaw_error_deg(first).abs() < 60.0);
    assert!(first.nees < 25.3);
}
