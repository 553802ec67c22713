//! The time-differenced carrier-phase update (`gnss.tdcp`) on the simulated open-sky drive
//! (carrier phase with 2 mm zenith noise, pseudo-range rates with the nominal noise): the
//! tightly-coupled EKF with and without it, and with phase input that must all be refused.
//!
//! Asserted: with TDCP the velocity RMSE is at most 0.02 m/s and the heading RMSE at most
//! 0.2° (and the filter without it misses the velocity figure, so the test fails when the
//! update is switched off); bad phases (a slip at every epoch, unresolved half cycles, no
//! wavelength, phase on some satellites only) are every one refused and counted, and the
//! solution is then the one without phases, bit for bit; satellites that come without a
//! pseudo-range (as single-frequency ones beside ionosphere-free ranges do) still give
//! their phase changes and rates, and no range.

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::engine::{EpochReport, Output, PhaseRejection, SatRejection};
use adaptive_gnss_ins::eval::ErrorSummary;
use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::sim::Scenario;
use adaptive_gnss_ins::tools::scenario_inputs::scenario_inputs;
use adaptive_gnss_ins::tools::session::{Session, SessionInput};

/// The scenario's seed (one realization).
const SEED: u64 = 3;

/// Scored from here: after the 20 s standing start and the alignment.
const SCORED_FROM_S: f64 = 30.0;

/// What a run gives: its error summary, its solutions' positions, the carrier-phase
/// reports and the pseudo-range reports.
struct Run {
    summary: ErrorSummary,
    positions: Vec<(f64, f64, f64)>,
    phase_reports: Vec<EpochReport>,
    range_reports: Vec<EpochReport>,
}

fn run(tdcp: bool, corrupt: impl Fn(&mut GnssEpoch, usize)) -> Run {
    let scenario = Scenario::builtin("open_sky", SEED).unwrap();
    let mut config = Config::default();
    config.gnss.tdcp = tdcp;
    let mut session = Session::new(config, 0.0, None);
    let mut positions = Vec::new();
    let mut phase_reports = Vec::new();
    let mut range_reports = Vec::new();
    let mut epoch_index = 0;
    for input in scenario_inputs(&scenario) {
        let input = match input.unwrap() {
            SessionInput::Gnss(mut epoch) => {
                corrupt(&mut epoch, epoch_index);
                epoch_index += 1;
                SessionInput::Gnss(epoch)
            }
            other => other,
        };
        for output in session.push(input) {
            match output {
                Output::Solution(s) => {
                    positions.push((s.nav.p.lat_rad, s.nav.p.lon_rad, s.nav.p.height_m))
                }
                Output::Epoch(mut report) => {
                    phase_reports.extend(report.carrier_phase_deltas.take().map(|r| *r));
                    range_reports.push(report);
                }
                Output::Status(_) => {}
            }
        }
    }
    Run {
        summary: session.finish().summary(SCORED_FROM_S),
        positions,
        phase_reports,
        range_reports,
    }
}

/// Phase changes used per TDCP update.
fn phases_per_update(run: &Run) -> f64 {
    let used: usize = run.phase_reports.iter().map(|r| r.measurements_used).sum();
    used as f64 / run.phase_reports.len() as f64
}

fn print(name: &str, s: &ErrorSummary) {
    println!(
        "{name:<22} pos3d {:.3} m  vel3d {:.4} m/s  yaw {:.3} deg  NEES {:.2}  epochs {}",
        s.pos_rmse_3d_m, s.vel_rmse_3d_mps, s.att_rmse_yaw_deg, s.nees_mean, s.epochs
    );
}

fn count(reports: &[EpochReport], reason: PhaseRejection) -> usize {
    reports
        .iter()
        .flat_map(|r| &r.satellites)
        .filter(|s| s.phase_rejection == Some(reason))
        .count()
}

#[test]
fn tdcp_reaches_the_velocity_and_heading_figures_in_open_sky() {
    let without = run(false, |_, _| {});
    let with = run(true, |_, _| {});
    print("pseudo-range rates", &without.summary);
    print("with TDCP", &with.summary);
    let per_update = phases_per_update(&with);
    println!(
        "TDCP: {} updates, {per_update:.2} phase changes used per update",
        with.phase_reports.len(),
    );
    assert!(with.summary.epochs > 3000, "{} epochs", with.summary.epochs);
    assert!(!with.phase_reports.is_empty() && per_update > 0.0);
    assert!(
        with.summary.vel_rmse_3d_mps <= 0.02,
        "velocity RMSE {} m/s with TDCP",
        with.summary.vel_rmse_3d_mps
    );
    assert!(
        with.summary.att_rmse_yaw_deg <= 0.2,
        "heading RMSE {}° with TDCP",
        with.summary.att_rmse_yaw_deg
    );
    assert!(
        without.summary.vel_rmse_3d_mps > 0.02,
        "the rate-only filter {} m/s: the figure does not need TDCP",
        without.summary.vel_rmse_3d_mps
    );
}

#[test]
fn bad_phases_are_refused_and_counted_without_a_jump() {
    // Every satellite's phase is bad in one way, by PRN: a slip of 3–40 cycles at every
    // epoch (with the loss-of-lock flag on every other epoch), the half cycle unresolved,
    // no wavelength, or no phase at all.
    let corrupt = |epoch: &mut GnssEpoch, index: usize| {
        for obs in &mut epoch.satellites {
            let prn = usize::from(obs.sat.prn);
            match prn % 4 {
                0 => {
                    if let Some(phase) = &mut obs.carrier_phase {
                        let slipped: usize = (0..=index).map(|i| 3 + (i * 7 + prn) % 38).sum();
                        phase.cycles += slipped as f64;
                        phase.loss_of_lock = index % 2 == 0;
                    }
                }
                1 => {
                    if let Some(phase) = &mut obs.carrier_phase {
                        phase.half_cycle_unresolved = true;
                    }
                }
                2 => {
                    if let Some(phase) = &mut obs.carrier_phase {
                        phase.wavelength_m = None;
                    }
                }
                _ => obs.carrier_phase = None,
            }
        }
    };
    let without = run(false, corrupt);
    let with = run(true, corrupt);
    print("pseudo-range rates", &without.summary);
    print("TDCP, bad phases", &with.summary);
    let slips = count(&with.phase_reports, PhaseRejection::CycleSlip);
    let half = count(&with.phase_reports, PhaseRejection::HalfCycleUnresolved);
    let no_wavelength = count(&with.phase_reports, PhaseRejection::NoWavelength);
    let too_few = count(&with.phase_reports, PhaseRejection::TooFewPhases);
    let used: usize = with.phase_reports.iter().map(|r| r.measurements_used).sum();
    println!(
        "{} TDCP reports: {slips} slips, {half} half cycles, {no_wavelength} without \
         wavelength, {too_few} too few refused, {used} used",
        with.phase_reports.len()
    );
    assert!(with.phase_reports.len() > 300);
    assert!(slips > 300 && half > 300 && no_wavelength > 300);
    assert_eq!(used, 0);
    // Nothing was used: the solution is the one without phases, to the bit.
    assert_eq!(with.positions, without.positions);
}

#[test]
fn satellites_without_a_range_give_their_phase_changes_and_rates() {
    // Every satellite of even PRN comes without its pseudo-range, as a single-frequency
    // satellite beside ionosphere-free ranges does (`gnss_ins convert`, default mode), or
    // is not there at all.
    let drop_ranges = |epoch: &mut GnssEpoch, _: usize| {
        for obs in &mut epoch.satellites {
            if obs.sat.prn % 2 == 0 {
                obs.pseudorange_m = None;
                obs.pseudorange_sigma_m = None;
            }
        }
    };
    let drop_satellites = |epoch: &mut GnssEpoch, _: usize| {
        epoch.satellites.retain(|obs| obs.sat.prn % 2 != 0);
    };
    let all = run(true, |_, _| {});
    let rangeless = run(true, drop_ranges);
    let fewer = run(true, drop_satellites);
    print("TDCP, every range", &all.summary);
    print("TDCP, half the ranges", &rangeless.summary);
    print("TDCP, half the sats", &fewer.summary);
    let sats = || rangeless.range_reports.iter().flat_map(|r| &r.satellites);
    let (mut seen, mut rates_used, mut ranges_used) = (0, 0, 0);
    for sat in sats().filter(|s| s.sat.prn % 2 == 0 && s.rejection.is_none()) {
        seen += 1;
        rates_used += usize::from(sat.used_rate);
        ranges_used += usize::from(sat.used_pseudorange);
    }
    let not_a_number = sats()
        .filter(|s| s.rejection == Some(SatRejection::NotANumber))
        .count();
    let (per_update_all, per_update_rangeless) =
        (phases_per_update(&all), phases_per_update(&rangeless));
    println!(
        "phase changes per update {per_update_all:.2} -> {per_update_rangeless:.2}; \
         satellites without a range: {seen} seen, {rates_used} rates and {ranges_used} ranges \
         used, {not_a_number} refused as not a number"
    );
    // A missing range is no bad input: nothing refused, no range used, the rate used.
    assert_eq!(not_a_number, 0);
    assert!(seen > 1000, "{seen}");
    assert_eq!(ranges_used, 0);
    assert!(rates_used * 10 > seen * 9, "{rates_used} of {seen}");
    // Their phase changes are used as when the ranges are there, and they are worth
    // having: the velocity is better than without those satellites.
    assert!(per_update_rangeless > 0.95 * per_update_all);
    assert!(
        rangeless.summary.vel_rmse_3d_mps < 0.6 * fewer.summary.vel_rmse_3d_mps,
        "velocity RMSE {} m/s, {} m/s without those satellites",
        rangeless.summary.vel_rmse_3d_mps,
        fewer.summary.vel_rmse_3d_mps
    );
}
