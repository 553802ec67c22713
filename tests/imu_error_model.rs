//! The seeded IMU error model: determinism, and sample statistics of the white noise and
//! the Gauss-Markov drift against their configured values.
//!
//! Tolerances are 5 standard deviations of the estimator under the model (a false failure
//! has probability below 1e-6 per check), with the estimator spreads written at each check.

use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::sim::{ImuErrorModel, ImuErrorSpec};
use nalgebra::Vector3;

const RATE_HZ: f64 = 100.0;

fn truth(k: usize) -> ImuSample {
    let t = k as f64 / RATE_HZ;
    ImuSample {
        t_s: t,
        w_ib_b_rad_s: Vector3::new(0.1 * t.sin(), -0.05, 0.2 * (0.3 * t).cos()),
        f_ib_b_m_s2: Vector3::new(0.4 * t.cos(), 0.1, 9.8),
    }
}

#[test]
fn same_seed_gives_identical_samples_and_another_seed_does_not() {
    let spec = ImuErrorSpec::default();
    let run = |seed: u64| {
        let mut m = ImuErrorModel::new(&spec, RATE_HZ, seed).unwrap();
        (0..2000).map(|k| m.corrupt(&truth(k))).collect::<Vec<_>>()
    };
    let a = run(42);
    let b = run(42);
    let c = run(43);
    assert_eq!(a, b);
    assert!(a
        .iter()
        .zip(&c)
        .all(|(x, y)| x.w_ib_b_rad_s != y.w_ib_b_rad_s));
}

/// Per-axis mean, standard deviation and lag-1 autocorrelation of a sequence.
fn stats(xs: &[Vector3<f64>], axis: usize) -> (f64, f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().map(|v| v[axis]).sum::<f64>() / n;
    let var = xs.iter().map(|v| (v[axis] - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let lag1 = xs
        .windows(2)
        .map(|w| match w {
            [a, b] => (a[axis] - mean) * (b[axis] - mean),
            _ => 0.0,
        })
        .sum::<f64>()
        / ((n - 1.0) * var);
    (mean, var.sqrt(), lag1)
}

/// The residual after removing the truth, the scale factor (none here) and the model's own
/// bias + Gauss-Markov bookkeeping is the white noise, with σ = N √f_s.
#[test]
fn white_noise_has_the_configured_sigma() {
    let spec = ImuErrorSpec::default();
    let mut m = ImuErrorModel::new(&spec, RATE_HZ, 7).unwrap();
    let (sigma_g, sigma_a) = m.white_noise_sigma();
    let n = 200_000;
    let mut gyro = Vec::with_capacity(n);
    let mut accel = Vec::with_capacity(n);
    for k in 0..n {
        let t = truth(k);
        let eg = m.gyro_error_rad_s();
        let ea = m.accel_error_m_s2();
        let meas = m.corrupt(&t);
        gyro.push(meas.w_ib_b_rad_s - t.w_ib_b_rad_s - eg);
        accel.push(meas.f_ib_b_m_s2 - t.f_ib_b_m_s2 - ea);
    }
    let nf = n as f64;
    for (xs, sigma, name) in [(&gyro, sigma_g, "gyro"), (&accel, sigma_a, "accel")] {
        for axis in 0..3 {
            let (mean, sd, lag1) = stats(xs, axis);
            println!(
                "{name}[{axis}]: mean {mean:.3e}, σ̂/σ = {:.5}, ρ1 = {lag1:.2e}",
                sd / sigma
            );
            // Mean: spread σ/√N.
            assert!(
                mean.abs() < 5.0 * sigma / nf.sqrt(),
                "{name}[{axis}] mean {mean}"
            );
            // σ̂: relative spread 1/√(2N) for Gaussian samples.
            assert!(
                (sd / sigma - 1.0).abs() < 5.0 / (2.0 * nf).sqrt(),
                "{name}[{axis}] σ̂ {sd} vs {sigma}"
            );
            // Whiteness: ρ̂1 of white noise has spread 1/√N.
            assert!(lag1.abs() < 5.0 / nf.sqrt(), "{name}[{axis}] ρ1 {lag1}");
        }
    }
}

/// A Gauss-Markov drift alone keeps its steady-state σ and has lag-1 autocorrelation
/// e^{−Δt/T}.
#[test]
fn gauss_markov_drift_has_the_configured_sigma_and_correlation() {
    let tau_s = 0.5;
    let spec = ImuErrorSpec {
        gyro_gm_sigma_deg_per_h: 10.0,
        gyro_gm_correlation_time_s: tau_s,
        accel_gm_sigma_ug: 200.0,
        accel_gm_correlation_time_s: tau_s,
        ..ImuErrorSpec::perfect()
    };
    let mut m = ImuErrorModel::new(&spec, RATE_HZ, 11).unwrap();
    let zero = ImuSample {
        t_s: 0.0,
        w_ib_b_rad_s: Vector3::zeros(),
        f_ib_b_m_s2: Vector3::zeros(),
    };
    let n = 400_000;
    let (mut gyro, mut accel) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for _ in 0..n {
        let s = m.corrupt(&zero);
        gyro.push(s.w_ib_b_rad_s);
        accel.push(s.f_ib_b_m_s2);
    }
    let rho = (-1.0 / (RATE_HZ * tau_s)).exp();
    let nf = n as f64;
    // AR(1) estimator spreads: mean σ √((1+ρ)/((1−ρ)N)); σ̂² relative
    // √(2(1+ρ²)/((1−ρ²)N)), so σ̂ relative half of it; ρ̂1 √((1−ρ²)/N).
    let mean_spread = ((1.0 + rho) / ((1.0 - rho) * nf)).sqrt();
    let sd_spread = 0.5 * (2.0 * (1.0 + rho * rho) / ((1.0 - rho * rho) * nf)).sqrt();
    let rho_spread = ((1.0 - rho * rho) / nf).sqrt();
    let sigma_g = 10.0 * std::f64::consts::PI / 180.0 / 3600.0;
    let sigma_a = 200.0e-6 * 9.806_65;
    for (xs, sigma, name) in [(&gyro, sigma_g, "gyro"), (&accel, sigma_a, "accel")] {
        for axis in 0..3 {
            let (mean, sd, lag1) = stats(xs, axis);
            println!(
                "GM {name}[{axis}]: mean/σ {:.3e}, σ̂/σ = {:.4}, ρ1 = {lag1:.5} (expected {rho:.5})",
                mean / sigma,
                sd / sigma
            );
            assert!((mean / sigma).abs() < 5.0 * mean_spread, "{name}[{axis}]");
            assert!((sd / sigma - 1.0).abs() < 5.0 * sd_spread, "{name}[{axis}]");
            assert!((lag1 - rho).abs() < 5.0 * rho_spread, "{name}[{axis}]");
        }
    }
}
