//! The scenario generator: determinism, the IMU against the truth, the pseudo-ranges and
//! rates against an independent prediction at the true state, environment effects, and the
//! receiver-like fixes.
//!
//! Statistical bounds are 5 standard deviations of the estimator under the declared model
//! (a false failure has probability below 1e-6 per check), with the spread written at each
//! check.

use std::collections::hash_map::DefaultHasher;
use std::collections::BTreeMap;
use std::hash::Hasher;

use adaptive_gnss_ins::earth::{enu_to_ecef, llh_to_ecef, llh_to_enu, rot_ecef_to_enu};
use adaptive_gnss_ins::gnss::geometry::predict;
use adaptive_gnss_ins::gnss::{GnssEpoch, SatId};
use adaptive_gnss_ins::ins::mechanization::{integrate, ImuIncrement};
use adaptive_gnss_ins::sim::constellation::{AtmosphereTruth, ObservationNoise, ReceiverTruth};
use adaptive_gnss_ins::sim::environment::{Environment, EnvironmentSegment};
use adaptive_gnss_ins::sim::{
    GnssTruth, ImuErrorSpec, Scenario, ScenarioError, ScenarioSpec, Segment, SimEvent,
};
use nalgebra::Vector3;

fn events(s: &Scenario) -> Vec<SimEvent> {
    s.events().map(|e| e.unwrap()).collect()
}

/// A hash of every number (and name) of an event stream.
fn hash_events(events: &[SimEvent]) -> u64 {
    let mut h = DefaultHasher::new();
    let mut f = |x: f64| h.write_u64(x.to_bits());
    for e in events {
        match e {
            SimEvent::Imu(s) => {
                f(s.t_s);
                s.w_ib_b_rad_s
                    .iter()
                    .chain(s.f_ib_b_m_s2.iter())
                    .for_each(|&x| f(x));
            }
            SimEvent::Truth(s) => {
                f(s.nav.t_s);
                s.nav
                    .p
                    .to_vector()
                    .iter()
                    .chain(s.nav.v_n.iter())
                    .for_each(|&x| f(x));
                s.nav.q_nb.coords.iter().for_each(|&x| f(x));
            }
            SimEvent::Environment { t_s, name, .. } => {
                f(*t_s);
                f(name.len() as f64);
            }
            SimEvent::Gnss {
                epoch,
                truth_sigmas,
                ..
            } => {
                f(epoch.t_s);
                f(epoch.gps_time_of_week_s);
                for o in &epoch.satellites {
                    f(o.sat.prn as f64);
                    f(o.pseudorange_m.unwrap_or(f64::NAN));
                    f(o.pseudorange_rate_mps.unwrap_or(f64::NAN));
                    f(o.cn0_dbhz.unwrap_or(f64::NAN));
                    o.sat_pos_ecef_m.iter().for_each(|&x| f(x));
                }
                for (_, a, b) in truth_sigmas {
                    f(*a);
                    f(*b);
                }
            }
            SimEvent::Fix(fix) => {
                f(fix.t_s);
                fix.position.to_vector().iter().for_each(|&x| f(x));
            }
            SimEvent::BaselineHeading(h) => {
                f(h.t_s);
                f(h.heading_rad);
                f(h.sigma_rad);
            }
        }
    }
    h.finish()
}

#[test]
fn same_seed_gives_the_same_stream_and_another_seed_does_not() {
    let a = Scenario::builtin("default", 7).unwrap();
    let b = Scenario::builtin("default", 7).unwrap();
    let c = Scenario::builtin("default", 8).unwrap();
    let ea = events(&a);
    let h = hash_events(&ea);
    assert_eq!(h, hash_events(&events(&b)));
    assert_eq!(
        h,
        hash_events(&events(&a)),
        "a second pass over the same scenario"
    );
    assert_ne!(h, hash_events(&events(&c)));
    // Time order, and the counts of a 405 s run: 100 Hz IMU, 10 Hz truth, 1 Hz GNSS.
    assert!(ea.windows(2).all(|w| w[0].t_s() <= w[1].t_s()));
    let count = |p: fn(&SimEvent) -> bool| ea.iter().filter(|e| p(e)).count();
    assert_eq!(count(|e| matches!(e, SimEvent::Imu(_))), 40_501);
    assert_eq!(count(|e| matches!(e, SimEvent::Truth(_))), 4_051);
    assert_eq!(count(|e| matches!(e, SimEvent::Environment { .. })), 406);
    assert_eq!(count(|e| matches!(e, SimEvent::Gnss { .. })), 406);
}

#[test]
fn random_streams_are_independent_per_purpose() {
    // More satellites: the IMU noise and the receiver clock do not change.
    let mut spec = ScenarioSpec::builtin("static").unwrap();
    let base = events(&Scenario::new(spec.clone(), 3).unwrap());
    spec.gnss.extra_satellites_per_plane = 2;
    let more = events(&Scenario::new(spec, 3).unwrap());
    let imu = |ev: &[SimEvent]| {
        ev.iter()
            .filter_map(|e| match e {
                SimEvent::Imu(s) => Some(*s),
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    let clocks = |ev: &[SimEvent]| {
        ev.iter()
            .filter_map(|e| match e {
                SimEvent::Gnss { truth, .. } => Some(truth.clock),
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(imu(&base), imu(&more));
    assert_eq!(clocks(&base), clocks(&more));
    assert_ne!(hash_events(&base), hash_events(&more));
    // Same drive, same seed: the open-sky epochs before the first disturbance (40 s) of
    // the default and the open-sky scenario are identical (common random numbers).
    let d = events(&Scenario::builtin("default", 5).unwrap());
    let o = events(&Scenario::builtin("open_sky", 5).unwrap());
    let early = |ev: &[SimEvent]| {
        ev.iter()
            .filter(|e| e.t_s() < 40.0)
            .cloned()
            .collect::<Vec<_>>()
    };
    assert_eq!(early(&d), early(&o));
    assert_ne!(hash_events(&d), hash_events(&o));
}

/// Budgets of the perfect-IMU run: those of the mechanization test's ten-minute vehicle
/// run (tests/mechanization.rs, derived there from the algorithm's orders), which this
/// 405 s drive with similar turn rates and ramps stays within.
const PERFECT_MAX_POS_ERR_M: f64 = 0.1;
const PERFECT_MAX_VEL_ERR_M_S: f64 = 1e-3;
const PERFECT_MAX_ATT_ERR_RAD: f64 = 5e-6;

#[test]
fn a_perfect_imu_integrates_back_to_the_truth() {
    let mut spec = ScenarioSpec::builtin("open_sky").unwrap();
    spec.imu.errors = ImuErrorSpec::perfect();
    spec.truth_rate_hz = 100.0;
    let scenario = Scenario::new(spec, 11).unwrap();
    let mut nav = None;
    let mut prev_sample = None;
    let mut prev_inc: Option<ImuIncrement> = None;
    let (mut max_p, mut max_v, mut max_a, mut checked) = (0.0f64, 0.0f64, 0.0f64, 0);
    for e in scenario.events() {
        match e.unwrap() {
            SimEvent::Imu(s) => {
                if let (Some(prev), Some(n)) = (prev_sample, nav.as_mut()) {
                    let inc = ImuIncrement::from_samples(&prev, &s).unwrap();
                    *n = integrate(n, prev_inc.as_ref(), &inc).unwrap();
                    prev_inc = Some(inc);
                }
                prev_sample = Some(s);
            }
            SimEvent::Truth(t) => match nav {
                None => nav = Some(t.nav),
                Some(n) => {
                    assert!((n.t_s - t.nav.t_s).abs() < 1e-9);
                    max_p = max_p.max(llh_to_enu(&n.p, &t.nav.p).norm());
                    max_v = max_v.max((n.v_n - t.nav.v_n).norm());
                    max_a = max_a.max(n.q_nb.angle_to(&t.nav.q_nb));
                    checked += 1;
                }
            },
            _ => {}
        }
    }
    println!("perfect IMU: max errors {max_p:.2e} m, {max_v:.2e} m/s, {max_a:.2e} rad");
    assert_eq!(checked, 40_500);
    assert!(max_p < PERFECT_MAX_POS_ERR_M, "{max_p}");
    assert!(max_v < PERFECT_MAX_VEL_ERR_M_S, "{max_v}");
    assert!(max_a < PERFECT_MAX_ATT_ERR_RAD, "{max_a}");
}

/// The antenna position from the truth, computed here independently of the generator.
fn antenna_ecef(scenario: &Scenario, t_s: f64) -> Vector3<f64> {
    let nav = scenario.trajectory().truth_at(t_s).unwrap().nav;
    enu_to_ecef(&(nav.q_nb * scenario.lever_arm_b_m()), &nav.p)
}

/// Per satellite of the epoch: (pseudo-range residual, rate residual), observation minus
/// the independent prediction at the true antenna state with the true clock and the true
/// atmosphere (the models times the spec's truth scales). The antenna velocity is a
/// central difference of true antenna positions (h = 1 ms: truncation far below 1e-6 m/s,
/// rounding ≈ 1e-9 m / 2e-3 s = 5e-7 m/s).
fn residuals(scenario: &Scenario, epoch: &GnssEpoch, truth: &GnssTruth) -> Vec<(SatId, f64, f64)> {
    let t = epoch.t_s;
    let pos = antenna_ecef(scenario, t);
    let h = 1e-3;
    let (t0, t1) = ((t - h).max(0.0), (t + h).min(scenario.duration_s()));
    let vel = (antenna_ecef(scenario, t1) - antenna_ecef(scenario, t0)) / (t1 - t0);
    let atm = &scenario.spec().gnss.atmosphere;
    epoch
        .satellites
        .iter()
        .map(|obs| {
            let pred = predict(
                obs,
                &pos,
                &vel,
                truth.clock.bias_m,
                truth.clock.drift_mps,
                epoch.klobuchar.as_ref(),
                epoch.gps_time_of_week_s,
            )
            .unwrap();
            let mut r = obs.pseudorange_m.unwrap() - pred.pseudorange_m;
            if obs.iono_delay_m.is_none() {
                r -= (atm.iono_truth_scale - 1.0) * pred.iono_m;
            }
            if obs.tropo_delay_m.is_none() {
                r -= (atm.tropo_truth_scale - 1.0) * pred.tropo_m;
            }
            let rr = obs.pseudorange_rate_mps.unwrap() - pred.pseudorange_rate_mps;
            (obs.sat, r, rr)
        })
        .collect()
}

/// One sample of the statistics test.
#[derive(Debug, Clone, Copy)]
struct Sample {
    epoch: u64,
    range_m: f64,
    rate_mps: f64,
    sigma_range_m: f64,
    sigma_rate_mps: f64,
    thermal_only_range_m: f64,
    nlos_bias_m: f64,
    elevation_rad: f64,
    azimuth_rad: f64,
}

/// The declared default environments, on a static receiver for an hour: open sky
/// [0, 1200), foliage [1200, 2400), urban canyon [2400, 3600), with a lever arm.
fn statistics_scenario() -> Scenario {
    let default = ScenarioSpec::builtin("default").unwrap();
    let env = |kind: &str| {
        default
            .environments
            .iter()
            .find(|s| s.environment.name() == kind)
            .unwrap()
            .environment
            .clone()
    };
    let mut spec = ScenarioSpec::builtin("static").unwrap();
    spec.trajectory.segments = vec![Segment::Stationary { duration_s: 3600.0 }];
    spec.imu.rate_hz = 1.0;
    spec.imu.errors = ImuErrorSpec::perfect();
    spec.truth_rate_hz = 1.0;
    spec.gnss.antenna_lever_arm_m = [0.4, -0.2, 1.1];
    spec.environments = vec![
        EnvironmentSegment {
            start_s: 1200.0,
            end_s: 2400.0,
            environment: env("foliage"),
        },
        EnvironmentSegment {
            start_s: 2400.0,
            end_s: 3600.0,
            environment: env("urban_canyon"),
        },
    ];
    Scenario::new(spec, 2024).unwrap()
}

/// Samples per satellite, in epoch order.
type SatSeries = BTreeMap<SatId, Vec<Sample>>;

/// Residual samples per environment name and satellite, in epoch order; checks on the way
/// that the residual equals what the generator says it added (bookkeeping to 1e-4).
fn collect_samples(scenario: &Scenario) -> (BTreeMap<&'static str, SatSeries>, Vec<GnssTruth>) {
    let mut out: BTreeMap<&'static str, SatSeries> = BTreeMap::new();
    let mut truths = Vec::new();
    let rate = scenario.spec().gnss.rate_hz;
    for e in scenario.events() {
        if let SimEvent::Gnss {
            epoch,
            truth_sigmas,
            truth,
        } = e.unwrap()
        {
            let name = scenario.environment_at(epoch.t_s).1.name();
            let res = residuals(scenario, &epoch, &truth);
            for ((sat, r, rr), (st, sig)) in
                res.iter().zip(truth.satellites.iter().zip(&truth_sigmas))
            {
                assert_eq!((*sat, *sat), (st.sat, sig.0));
                assert!(
                    (r - st.pseudorange_error_m).abs() < 1e-4,
                    "{sat} {r} {st:?}"
                );
                assert!(
                    (rr - st.pseudorange_rate_error_mps).abs() < 1e-4,
                    "{sat} {rr} {st:?}"
                );
                out.entry(name)
                    .or_default()
                    .entry(*sat)
                    .or_default()
                    .push(Sample {
                        epoch: (epoch.t_s * rate).round() as u64,
                        range_m: *r,
                        rate_mps: *rr,
                        sigma_range_m: sig.1,
                        sigma_rate_mps: sig.2,
                        thermal_only_range_m: r - st.multipath_m - st.nlos_bias_m - st.outlier_m,
                        nlos_bias_m: st.nlos_bias_m,
                        elevation_rad: st.elevation_rad,
                        azimuth_rad: st.azimuth_rad,
                    });
            }
            truths.push(truth);
        }
    }
    (out, truths)
}

/// Pairs of samples k epochs apart of the same satellite.
fn lag_pairs(series: &SatSeries, k: u64) -> Vec<(Sample, Sample)> {
    let mut pairs = Vec::new();
    for v in series.values() {
        for (i, a) in v.iter().enumerate() {
            if let Some(b) = v[i + 1..]
                .iter()
                .take(k as usize)
                .find(|b| b.epoch == a.epoch + k)
            {
                pairs.push((*a, *b));
            }
        }
    }
    pairs
}

/// AR(2) autocorrelations ρ_0..ρ_n from the Yule-Walker recursion (independent of the
/// generator's step-down code): ρ_1 = φ1 / (1 − φ2), ρ_k = φ1 ρ_{k−1} + φ2 ρ_{k−2}.
fn ar2_autocorrelation(phi: &[f64], n: usize) -> Vec<f64> {
    let (p1, p2) = (phi[0], phi[1]);
    let mut rho = vec![1.0, p1 / (1.0 - p2)];
    for k in 2..=n {
        rho.push(p1 * rho[k - 1] + p2 * rho[k - 2]);
    }
    rho
}

#[test]
fn observations_carry_exactly_the_declared_clock_and_noise() {
    let scenario = statistics_scenario();
    let (samples, truths) = collect_samples(&scenario);

    // --- Receiver clock: the increments have the covariance Q of the TCXO model. ---
    let clock_spec = &scenario.spec().gnss.receiver_clock;
    let (sb, sd) = (
        clock_spec.bias_noise_density_m2_per_s(),
        clock_spec.drift_noise_density_m2_per_s3(),
    );
    let (q11, q22) = (sb + sd / 3.0, sd); // Δt = 1 s
    let inc: Vec<(f64, f64)> = truths
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0].clock, w[1].clock);
            (b.bias_m - a.bias_m - a.drift_mps, b.drift_mps - a.drift_mps)
        })
        .collect();
    let n = inc.len() as f64;
    let v11 = inc.iter().map(|x| x.0 * x.0).sum::<f64>() / n;
    let v22 = inc.iter().map(|x| x.1 * x.1).sum::<f64>() / n;
    // Relative sd of a Gaussian sample variance: √(2/n) ≈ 0.024 for 3599 increments.
    let tol = 5.0 * (2.0 / n).sqrt();
    println!(
        "clock: var ratios {:.3} {:.3} (tol {tol:.3})",
        v11 / q11,
        v22 / q22
    );
    assert!((v11 / q11 - 1.0).abs() < tol);
    assert!((v22 / q22 - 1.0).abs() < tol);

    // --- Open sky: white Gaussian noise of the declared σ. ---
    let open = &samples["open_sky"];
    let all: Vec<Sample> = open.values().flatten().copied().collect();
    let n = all.len() as f64;
    assert!(n > 9000.0, "{n}");
    for (label, z) in [
        (
            "range",
            all.iter()
                .map(|s| s.range_m / s.sigma_range_m)
                .collect::<Vec<_>>(),
        ),
        (
            "rate",
            all.iter()
                .map(|s| s.rate_mps / s.sigma_rate_mps)
                .collect::<Vec<_>>(),
        ),
    ] {
        let mean = z.iter().sum::<f64>() / n;
        let var = z.iter().map(|x| x * x).sum::<f64>() / n;
        // sd of the mean 1/√n; of the mean square √(2/n).
        println!("open sky {label}: mean {mean:.4}, mean square {var:.4}, n {n}");
        assert!(mean.abs() < 5.0 / n.sqrt());
        assert!((var - 1.0).abs() < 5.0 * (2.0 / n).sqrt());
    }
    let pairs = lag_pairs(open, 1);
    let np = pairs.len() as f64;
    let c1 = pairs
        .iter()
        .map(|(a, b)| a.range_m / a.sigma_range_m * b.range_m / b.sigma_range_m)
        .sum::<f64>()
        / np;
    // Independent unit normals: the product has variance 1, so sd 1/√n.
    println!("open sky lag-1 correlation {c1:.4} ({np} pairs)");
    assert!(c1.abs() < 5.0 / np.sqrt());

    // --- Foliage: AR(2) multipath of the declared σ and correlation, heavy tails. ---
    let Environment::Foliage(f) = scenario.spec().environments[0].environment.clone() else {
        panic!("foliage expected");
    };
    let foliage = &samples["foliage"];
    let rho = ar2_autocorrelation(&f.multipath.ar_coefficients, 200);
    let (p, s) = (f.heavy_tail.probability, f.heavy_tail.scale);
    for (label, sigma_m, pick) in [
        (
            "range",
            f.multipath.pseudorange_sigma_m,
            (|x: &Sample| (x.range_m, x.sigma_range_m)) as fn(&Sample) -> (f64, f64),
        ),
        (
            "rate",
            f.multipath.pseudorange_rate_sigma_mps,
            |x: &Sample| (x.rate_mps, x.sigma_rate_mps),
        ),
    ] {
        let sm2 = sigma_m * sigma_m;
        // (a) Mean of z² = e²/σ_tot² is 1. Its variance, with e = w + m (w white
        // contaminated Gaussian of variance σ_w² = σ_th² (1 − p + p s²), m the AR part):
        // Var z_t² = [E w⁴ − σ_w⁴ + 4 σ_w² σ_m² + 2 σ_m⁴] / σ_tot⁴, E w⁴ = 3 σ_th⁴ (1 − p + p s⁴),
        // Cov(z_t², z_u²) = 2 σ_m⁴ ρ²_{t−u} / (σ_tot,t² σ_tot,u²) for the same satellite.
        let mut sum = 0.0;
        let mut var_sum = 0.0;
        let mut count = 0.0;
        for v in foliage.values() {
            for (i, a) in v.iter().enumerate() {
                let (e, st) = pick(a);
                let st2 = st * st;
                let sw2 = st2 - sm2;
                let sth2 = sw2 / (1.0 - p + p * s * s);
                let ew4 = 3.0 * sth2 * sth2 * (1.0 - p + p * s.powi(4));
                sum += e * e / st2;
                count += 1.0;
                var_sum += (ew4 - sw2 * sw2 + 4.0 * sw2 * sm2 + 2.0 * sm2 * sm2) / (st2 * st2);
                for b in &v[i + 1..] {
                    let lag = (b.epoch - a.epoch) as usize;
                    if lag >= rho.len() {
                        break;
                    }
                    let (_, sb) = pick(b);
                    var_sum += 2.0 * 2.0 * sm2 * sm2 * rho[lag] * rho[lag] / (st2 * sb * sb);
                }
            }
        }
        let mean_z2 = sum / count;
        let sd = var_sum.sqrt() / count;
        println!("foliage {label}: mean z² {mean_z2:.4} (sd {sd:.4}, n {count})");
        assert!((mean_z2 - 1.0).abs() < 5.0 * sd);
        // (b) Autocovariance at lags 1, 2, 5: E[e_t e_{t+k}] = σ_m² ρ_k. Bartlett's
        // variance (1/n) Σ_j (γ_j² + γ_{j+k} γ_{j−k}) with γ_j = σ_m² ρ_j + δ_j σ̄_w²; the
        // white part's fourth moment does not enter for k ≥ 1.
        let sw2_mean = foliage
            .values()
            .flatten()
            .map(|x| pick(x).1.powi(2) - sm2)
            .sum::<f64>()
            / count;
        let gamma = |j: i64| {
            let j = j.unsigned_abs() as usize;
            let g = sm2 * rho.get(j).copied().unwrap_or(0.0);
            if j == 0 {
                g + sw2_mean
            } else {
                g
            }
        };
        for k in [1u64, 2, 5] {
            let pairs = lag_pairs(foliage, k);
            let np = pairs.len() as f64;
            let est = pairs
                .iter()
                .map(|(a, b)| pick(a).0 * pick(b).0)
                .sum::<f64>()
                / np;
            let kk = k as i64;
            let var: f64 = (-150i64..=150)
                .map(|j| gamma(j) * gamma(j) + gamma(j + kk) * gamma(j - kk))
                .sum::<f64>()
                / np;
            let expect = sm2 * rho[k as usize];
            println!(
                "foliage {label} lag {k}: {est:.4} vs {expect:.4} (sd {:.4})",
                var.sqrt()
            );
            assert!((est - expect).abs() < 5.0 * var.sqrt());
        }
    }
    // (c) Heavy tails of the white part: P(|w| > 3 σ_th) = (1 − p) P(|N| > 3) + p P(|N| > 3/s).
    let white: Vec<f64> = foliage
        .values()
        .flatten()
        .map(|x| {
            let sw2 = x.sigma_range_m.powi(2) - f.multipath.pseudorange_sigma_m.powi(2);
            x.thermal_only_range_m / (sw2 / (1.0 - p + p * s * s)).sqrt()
        })
        .collect();
    let tail = |c: f64| statrs::function::erf::erfc(c / std::f64::consts::SQRT_2);
    let p_big = (1.0 - p) * tail(3.0) + p * tail(3.0 / s);
    let n = white.len() as f64;
    let big = white.iter().filter(|z| z.abs() > 3.0).count() as f64;
    let sd = (n * p_big * (1.0 - p_big)).sqrt();
    println!(
        "foliage: {big} of {n} beyond 3 σ_th, expected {:.1} (sd {sd:.1})",
        n * p_big
    );
    assert!((big - n * p_big).abs() < 5.0 * sd);

    // --- Urban canyon: the mask, NLOS biases and outliers. ---
    let Environment::UrbanCanyon(u) = scenario.spec().environments[1].environment.clone() else {
        panic!("urban canyon expected");
    };
    let urban = &samples["urban_canyon"];
    let nav = scenario.trajectory().truth_at(3000.0).unwrap().nav;
    let forward = nav.q_nb * Vector3::x();
    let course = forward[0].atan2(forward[1]);
    let mask = |az: f64| {
        (2.0 * u.building_height_m * (az - course).sin().abs() / u.street_width_m)
            .atan()
            .max(u.min_mask_elevation_deg.to_radians())
    };
    for x in urban.values().flatten() {
        assert!(x.elevation_rad >= mask(x.azimuth_rad), "{x:?}");
    }
    // The satellites missing from an urban epoch are exactly those behind the buildings.
    let open_epoch = scenario
        .constellation()
        .simulate_epoch(
            scenario.gps_time_s(3000.0),
            &ReceiverTruth {
                pos_ecef_m: antenna_ecef(&scenario, 3000.0),
                vel_ecef_mps: Vector3::zeros(),
                clock_bias_m: 0.0,
                clock_drift_mps: 0.0,
            },
            &AtmosphereTruth::vacuum(),
            scenario.spec().gnss.elevation_mask_deg.to_radians(),
            |_| ObservationNoise::default(),
        )
        .unwrap();
    let epoch_3000 = 3000;
    let received: Vec<SatId> = urban
        .iter()
        .filter(|(_, v)| v.iter().any(|x| x.epoch == epoch_3000))
        .map(|(sat, _)| *sat)
        .collect();
    let p_llh = adaptive_gnss_ins::earth::ecef_to_llh(&antenna_ecef(&scenario, 3000.0)).unwrap();
    let mut blocked = 0;
    for obs in &open_epoch.satellites {
        let los = (obs.sat_pos_ecef_m - antenna_ecef(&scenario, 3000.0)).normalize();
        let enu = rot_ecef_to_enu(&p_llh) * los;
        let (el, az) = (enu[2].asin(), enu[0].atan2(enu[1]));
        // 0.01° margin for the Sagnac rotation left out of this line of sight.
        if el > mask(az) + 1e-4 {
            assert!(
                received.contains(&obs.sat),
                "{} should be received",
                obs.sat
            );
        } else if el < mask(az) - 1e-4 {
            assert!(
                !received.contains(&obs.sat),
                "{} should be blocked",
                obs.sat
            );
            blocked += 1;
        }
    }
    println!(
        "urban at 3000 s: {} received, {blocked} blocked",
        received.len()
    );
    assert!(blocked > 0 && received.len() >= 4);
    // NLOS: each satellite's residual median is its bias (0 for line of sight), and the
    // biases lie in the declared range. The median of ≥ 100 samples with σ ≤ 3 m and 2 %
    // outliers errs by well under 1 m.
    let mut nlos = 0;
    for (sat, v) in urban {
        if v.len() < 100 {
            continue;
        }
        let bias = v[0].nlos_bias_m;
        assert!(v.iter().all(|x| x.nlos_bias_m == bias));
        let mut r: Vec<f64> = v.iter().map(|x| x.range_m).collect();
        r.sort_by(f64::total_cmp);
        let median = r[r.len() / 2];
        assert!(
            (median - bias).abs() < 1.0,
            "{sat}: median {median}, bias {bias}"
        );
        if bias != 0.0 {
            assert!((u.nlos_bias_min_m..=u.nlos_bias_max_m).contains(&bias));
            nlos += 1;
        }
    }
    println!("urban: {nlos} NLOS satellites of {}", urban.len());
    assert!(nlos > 0);
    // Outliers: |residual − bias| > 15 m happens for an outlier (≥ 20 m) unless the noise
    // (σ ≤ 3 m here) pulls it back by 5 m — about 5 % of outliers at the lowest
    // elevations — and essentially never otherwise.
    let all: Vec<&Sample> = urban.values().flatten().collect();
    let n = all.len() as f64;
    let k = all
        .iter()
        .filter(|x| (x.range_m - x.nlos_bias_m).abs() > 15.0)
        .count() as f64;
    let expect = n * u.outlier_probability;
    let sd = expect.sqrt();
    println!("urban: {k} outliers in {n} (expected ≈ {expect:.1}, sd {sd:.1})");
    assert!(k <= expect + 5.0 * sd && k >= 0.95 * expect - 5.0 * sd);
}

#[test]
fn open_sky_has_eight_or_more_satellites_on_most_epochs() {
    let scenario = Scenario::builtin("default", 1).unwrap();
    let mut env = "";
    let mut counts = Vec::new();
    for e in scenario.events() {
        match e.unwrap() {
            SimEvent::Environment { name, .. } => env = name,
            SimEvent::Gnss { epoch, .. } if env == "open_sky" => {
                counts.push(epoch.satellites.len())
            }
            _ => {}
        }
    }
    let share = counts.iter().filter(|&&n| n >= 8).count() as f64 / counts.len() as f64;
    println!(
        "open sky: {} epochs, {share:.3} with ≥ 8 satellites",
        counts.len()
    );
    assert!(counts.len() > 200);
    assert!(share > 0.9);
}

#[test]
fn an_outage_has_no_gnss() {
    let mut spec = ScenarioSpec::builtin("default").unwrap();
    spec.environments = vec![EnvironmentSegment {
        start_s: 50.0,
        end_s: 80.0,
        environment: Environment::Outage,
    }];
    let ev = events(&Scenario::new(spec, 9).unwrap());
    let inside = |e: &&SimEvent| (50.0..80.0).contains(&e.t_s());
    assert!(!ev
        .iter()
        .filter(inside)
        .any(|e| matches!(e, SimEvent::Gnss { .. } | SimEvent::Fix(_))));
    let env_names: Vec<_> = ev
        .iter()
        .filter(inside)
        .filter_map(|e| match e {
            SimEvent::Environment { name, .. } => Some(*name),
            _ => None,
        })
        .collect();
    assert_eq!(env_names.len(), 30);
    assert!(env_names.iter().all(|n| *n == "outage"));
    assert_eq!(
        ev.iter()
            .filter(inside)
            .filter(|e| matches!(e, SimEvent::Imu(_)))
            .count(),
        3000
    );
    assert!(ev
        .iter()
        .any(|e| e.t_s() == 80.0 && matches!(e, SimEvent::Gnss { .. })));
}

/// Budget of the open-sky fixes: PDOP ≈ 1.5 times range errors of 0.5–2 m (thermal σ over
/// the elevations) plus the 20 % ionosphere mismatch (1–2 m per satellite, largely common
/// and absorbed by the clock): a few metres.
const OPEN_SKY_MAX_FIX_ERR_M: f64 = 10.0;
const OPEN_SKY_MAX_FIX_RMS_M: f64 = 4.0;
const OPEN_SKY_MAX_FIX_VEL_ERR_MPS: f64 = 0.5;

#[test]
fn open_sky_fixes_are_within_a_few_metres_of_the_antenna() {
    let mut spec = ScenarioSpec::builtin("default").unwrap();
    spec.gnss.antenna_lever_arm_m = [0.8, -0.3, 1.5];
    let scenario = Scenario::new(spec, 4).unwrap();
    let mut env = "";
    let (mut n, mut sum2, mut max_err, mut max_vel) = (0, 0.0, 0.0f64, 0.0f64);
    let mut urban_sats = Vec::new();
    for e in scenario.events() {
        match e.unwrap() {
            SimEvent::Environment { name, .. } => env = name,
            SimEvent::Gnss { epoch, .. } if env == "urban_canyon" => {
                urban_sats.push(epoch.satellites.len())
            }
            SimEvent::Fix(fix) if env == "open_sky" => {
                let truth = antenna_ecef(&scenario, fix.t_s);
                let err = (llh_to_ecef(&fix.position) - truth).norm();
                let c = fix.position_covariance_enu_m2.unwrap();
                assert!(c.cholesky().is_some());
                let h = 1e-3;
                let t0 = (fix.t_s - h).max(0.0);
                let t1 = (fix.t_s + h).min(scenario.duration_s());
                let v_ecef =
                    (antenna_ecef(&scenario, t1) - antenna_ecef(&scenario, t0)) / (t1 - t0);
                let v_enu = rot_ecef_to_enu(&fix.position) * v_ecef;
                max_vel = max_vel.max((fix.velocity_enu_mps.unwrap() - v_enu).norm());
                sum2 += err * err;
                max_err = max_err.max(err);
                n += 1;
            }
            _ => {}
        }
    }
    let rms = (sum2 / n as f64).sqrt();
    println!("open-sky fixes: {n}, RMS {rms:.2} m, max {max_err:.2} m, max velocity error {max_vel:.3} m/s");
    assert!(n > 250);
    assert!(max_err < OPEN_SKY_MAX_FIX_ERR_M && rms < OPEN_SKY_MAX_FIX_RMS_M);
    assert!(max_vel < OPEN_SKY_MAX_FIX_VEL_ERR_MPS);
    // The urban canyon leaves fewer satellites than the open sky's 8 or more.
    assert!(urban_sats.iter().all(|&k| k < 8), "{urban_sats:?}");
}

#[test]
fn builtins_load_and_bad_specs_are_typed_errors() {
    assert_eq!(
        ScenarioSpec::builtin_names(),
        vec!["default", "open_sky", "static"]
    );
    for name in ScenarioSpec::builtin_names() {
        let spec = ScenarioSpec::builtin(name).unwrap();
        assert_eq!(spec.name, name);
        assert!(Scenario::new(spec, 0).is_ok());
    }
    let default = ScenarioSpec::builtin("default").unwrap();
    assert!(
        (default
            .trajectory
            .segments
            .iter()
            .map(|s| s.duration_s())
            .sum::<f64>()
            - 405.0)
            .abs()
            < 1e-9
    );
    assert!(matches!(
        Scenario::builtin("nope", 0),
        Err(ScenarioError::UnknownBuiltin { .. })
    ));
    // Unknown keys are refused, with the path in the message.
    let yaml = include_str!("../src/sim/scenarios/static.yaml")
        .replace("rate_hz: 100.0", "rate_hz: 100.0\n  colour: red");
    match ScenarioSpec::from_yaml(&yaml) {
        Err(ScenarioError::Yaml { message }) => assert!(message.contains("imu"), "{message}"),
        other => panic!("{other:?}"),
    }
    let bad = |f: &dyn Fn(&mut ScenarioSpec)| {
        let mut s = default.clone();
        f(&mut s);
        Scenario::new(s, 0).unwrap_err()
    };
    assert!(matches!(
        bad(&|s| s.imu.rate_hz = 2000.0),
        ScenarioError::InvalidSpec { .. }
    ));
    assert!(matches!(
        bad(&|s| s.trajectory.start_t_s = 5.0),
        ScenarioError::InvalidSpec { .. }
    ));
    assert!(matches!(
        bad(&|s| s.environments[1].start_s = 100.0),
        ScenarioError::InvalidSpec { .. }
    ));
    assert!(matches!(
        bad(&|s| {
            if let Environment::Foliage(f) = &mut s.environments[0].environment {
                f.multipath.ar_coefficients = vec![1.2, 0.1];
            }
        }),
        ScenarioError::InvalidSpec { .. }
    ));
    assert!(matches!(
        bad(&|s| s.trajectory.segments.clear()),
        ScenarioError::Trajectory(_)
    ));
    assert!(matches!(
        bad(&|s| s.imu.errors.gyro_arw_deg_per_sqrt_h = -1.0),
        ScenarioError::ImuErrors(_)
    ));
}

/// The carrier phase: between consecutive epochs of a satellite, λΔφ is the change of the
/// noise-free pseudo-range (the observation less the code error added) up to the phase
/// error added and twice the ionosphere's change (millimetres in a second); every track
/// starts with a loss of lock and a lock time of 0, then counts the time.
#[test]
fn carrier_phases_follow_the_range_with_their_own_noise() {
    let scenario = Scenario::builtin("open_sky", 3).unwrap();
    let mut previous: BTreeMap<SatId, (f64, f64, f64, f64)> = BTreeMap::new();
    let (mut pairs, mut starts, mut worst_m) = (0, 0, 0.0f64);
    for event in scenario.events().take_while(|e| {
        e.as_ref()
            .map_or(true, |e| !matches!(e, SimEvent::Imu(s) if s.t_s > 120.0))
    }) {
        let SimEvent::Gnss { epoch, truth, .. } = event.unwrap() else {
            continue;
        };
        for (obs, err) in epoch.satellites.iter().zip(&truth.satellites) {
            let phase = obs.carrier_phase.unwrap();
            let lambda_m = phase.wavelength_m.unwrap();
            let code_m = obs.pseudorange_m.unwrap() - err.pseudorange_error_m;
            let now = (
                epoch.t_s,
                phase.cycles * lambda_m,
                code_m,
                err.carrier_phase_error_m,
            );
            match previous.insert(obs.sat, now) {
                Some(before) if !phase.loss_of_lock => {
                    let d = (now.1 - before.1) - (now.2 - before.2) - (now.3 - before.3);
                    worst_m = worst_m.max(d.abs());
                    assert!(phase.lock_time_s.unwrap() >= epoch.t_s - before.0 - 1e-9);
                    pairs += 1;
                }
                _ => {
                    assert!(phase.loss_of_lock, "{} at {}", obs.sat, epoch.t_s);
                    assert_eq!(phase.lock_time_s, Some(0.0));
                    starts += 1;
                }
            }
        }
    }
    println!("{pairs} epoch pairs, {starts} track starts, worst |λΔφ − Δρ − Δε| {worst_m} m");
    assert!(pairs > 800 && starts >= 8, "{pairs} pairs, {starts} starts");
    assert!(worst_m < 0.01, "{worst_m} m");
}

/// A scenario's dual-antenna pair (`dual_antenna`): one heading per fix, the true
/// baseline's plus an error of the spec's σ; a baseline with no horizontal part or a σ
/// that is not positive is refused.
#[test]
fn a_dual_antenna_pair_reports_its_baselines_heading_with_its_sigma() {
    use adaptive_gnss_ins::sim::DualAntennaSpec;
    const SIGMA_DEG: f64 = 0.5;
    // The static scenario faces north; the rover's antenna 1 m to the right: east.
    let mut spec = ScenarioSpec::builtin("static").unwrap();
    spec.dual_antenna = Some(DualAntennaSpec {
        baseline_m: [0.0, -1.0, 0.0],
        heading_sigma_deg: SIGMA_DEG,
    });
    let scenario = Scenario::new(spec.clone(), 3).unwrap();
    let (mut fixes, mut errors_deg) = (0, Vec::new());
    for event in scenario.events() {
        match event.unwrap() {
            SimEvent::Fix(_) => fixes += 1,
            SimEvent::BaselineHeading(h) => {
                assert_eq!(h.sigma_rad, SIGMA_DEG.to_radians());
                assert_eq!(h.length_m, 1.0);
                errors_deg.push(h.heading_rad.to_degrees() - 90.0);
            }
            _ => {}
        }
    }
    let n = errors_deg.len() as f64;
    let mean = errors_deg.iter().sum::<f64>() / n;
    let sd = (errors_deg.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    println!("{n} headings: error mean {mean:.3} deg, sd {sd:.3} deg (sigma {SIGMA_DEG} deg)");
    assert_eq!(errors_deg.len(), fixes);
    assert!(fixes > 100, "{fixes}");
    // Bounds of about four standard errors.
    assert!(mean.abs() < 4.0 * SIGMA_DEG / n.sqrt(), "{mean}");
    assert!(
        (sd / SIGMA_DEG - 1.0).abs() < 4.0 / (2.0 * n).sqrt(),
        "{sd}"
    );
    for (baseline_m, heading_sigma_deg) in [([0.0, 0.0, 1.0], 0.5), ([1.0, 0.0, 0.0], 0.0)] {
        spec.dual_antenna = Some(DualAntennaSpec {
            baseline_m,
            heading_sigma_deg,
        });
        assert!(Scenario::new(spec.clone(), 3).is_err());
    }
}
