//! The simulated receiver clock: bias b = c·δt_u (m) and drift d = c·δṫ_u (m/s) of a free-
//! running oscillator, with the two-state model of Brown & Hwang (Introduction to Random
//! Signals and Applied Kalman Filtering, the "clock model" section):
//!
//! ḃ = d + w_b,  ḋ = w_d,  with white-noise densities S_b = c² h₀ / 2 (white frequency
//! noise) and S_d = 2π² c² h₋₂ (random-walk frequency noise), h_α the Allan-variance
//! (power-law) coefficients of the fractional frequency. Flicker noise (h₋₁) is left out, as
//! in that model.
//!
//! Math note: the exact discretisation over Δt is Φ = [[1, Δt], [0, 1]] and
//! Q = [[S_b Δt + S_d Δt³/3, S_d Δt²/2], [S_d Δt²/2, S_d Δt]], drawn through its 2×2
//! Cholesky factor, so the statistics do not depend on the GNSS rate.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::earth::SPEED_OF_LIGHT_M_S;

/// Receiver clock parameters. The default is a typical TCXO (Brown & Hwang's table of
/// oscillator h-parameters: h₀ = 2·10⁻¹⁹ s, h₋₂ = 2·10⁻²⁰ s⁻¹), i.e. S_b ≈ 0.009 m²/s and
/// S_d ≈ 0.035 m²/s³, with an offset of 10 µs (3 km) and a frequency error of 0.15 ppm
/// (45 m/s), both well inside a TCXO's specification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReceiverClockSpec {
    /// Clock bias c·δt_u at t = 0 (m).
    pub initial_bias_m: f64,
    /// Clock drift c·δṫ_u at t = 0 (m/s).
    pub initial_drift_mps: f64,
    /// White-frequency-noise coefficient h₀ of the fractional frequency (s).
    pub white_frequency_h0_s: f64,
    /// Random-walk-frequency-noise coefficient h₋₂ of the fractional frequency (1/s).
    pub random_walk_frequency_h_minus2_per_s: f64,
}

impl Default for ReceiverClockSpec {
    fn default() -> Self {
        Self {
            initial_bias_m: 3000.0,
            initial_drift_mps: 45.0,
            white_frequency_h0_s: 2e-19,
            random_walk_frequency_h_minus2_per_s: 2e-20,
        }
    }
}

impl ReceiverClockSpec {
    /// S_b = c² h₀ / 2, the bias noise density (m²/s).
    pub fn bias_noise_density_m2_per_s(&self) -> f64 {
        0.5 * SPEED_OF_LIGHT_M_S * SPEED_OF_LIGHT_M_S * self.white_frequency_h0_s
    }

    /// S_d = 2π² c² h₋₂, the drift noise density (m²/s³).
    pub fn drift_noise_density_m2_per_s3(&self) -> f64 {
        2.0 * std::f64::consts::PI.powi(2)
            * SPEED_OF_LIGHT_M_S
            * SPEED_OF_LIGHT_M_S
            * self.random_walk_frequency_h_minus2_per_s
    }

    /// The first field that is not finite (or, for the h-coefficients, negative).
    pub fn invalid_field(&self) -> Option<(&'static str, f64)> {
        let finite = [
            ("initial_bias_m", self.initial_bias_m),
            ("initial_drift_mps", self.initial_drift_mps),
        ];
        let non_negative = [
            ("white_frequency_h0_s", self.white_frequency_h0_s),
            (
                "random_walk_frequency_h_minus2_per_s",
                self.random_walk_frequency_h_minus2_per_s,
            ),
        ];
        finite
            .into_iter()
            .find(|(_, v)| !v.is_finite())
            .or_else(|| {
                non_negative
                    .into_iter()
                    .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
            })
    }
}

/// True receiver clock state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceiverClockState {
    /// Bias c·δt_u (m).
    pub bias_m: f64,
    /// Drift c·δṫ_u (m/s).
    pub drift_mps: f64,
}

/// A running receiver clock.
#[derive(Debug, Clone)]
pub struct ReceiverClock {
    state: ReceiverClockState,
    bias_density: f64,
    drift_density: f64,
}

impl ReceiverClock {
    /// The clock of `spec` at t = 0 (the spec is assumed validated).
    pub fn new(spec: &ReceiverClockSpec) -> Self {
        Self {
            state: ReceiverClockState {
                bias_m: spec.initial_bias_m,
                drift_mps: spec.initial_drift_mps,
            },
            bias_density: spec.bias_noise_density_m2_per_s(),
            drift_density: spec.drift_noise_density_m2_per_s3(),
        }
    }

    /// The current state.
    pub fn state(&self) -> ReceiverClockState {
        self.state
    }

    /// Moves the clock `dt_s` ≥ 0 seconds on (exact discretisation, see the module notes).
    pub fn advance(&mut self, dt_s: f64, rng: &mut ChaCha8Rng) {
        if dt_s.is_nan() || dt_s <= 0.0 {
            return;
        }
        let q11 = self.bias_density * dt_s + self.drift_density * dt_s.powi(3) / 3.0;
        let q12 = 0.5 * self.drift_density * dt_s * dt_s;
        let q22 = self.drift_density * dt_s;
        // Cholesky of [[q11, q12], [q12, q22]]: l11 = √q11, l21 = q12 / l11,
        // l22 = √(q22 − l21²); with S_b = 0 the factor degenerates gracefully.
        let l11 = q11.max(0.0).sqrt();
        let l21 = if l11 > 0.0 { q12 / l11 } else { 0.0 };
        let l22 = (q22 - l21 * l21).max(0.0).sqrt();
        let xi1: f64 = StandardNormal.sample(rng);
        let xi2: f64 = StandardNormal.sample(rng);
        self.state.bias_m += self.state.drift_mps * dt_s + l11 * xi1;
        self.state.drift_mps += l21 * xi1 + l22 * xi2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::rand_core::SeedableRng;

    #[test]
    fn densities_of_the_default_tcxo() {
        let spec = ReceiverClockSpec::default();
        // c² = 8.987 551 787 368 176 4e16 m²/s².
        assert!((spec.bias_noise_density_m2_per_s() - 8.987_551_787e-3).abs() < 1e-12);
        let s_d = 2.0 * std::f64::consts::PI.powi(2) * 8.987_551_787_368_176e16 * 2e-20;
        assert!((spec.drift_noise_density_m2_per_s3() - s_d).abs() < 1e-15);
        assert!(spec.invalid_field().is_none());
        let bad = ReceiverClockSpec {
            white_frequency_h0_s: -1.0,
            ..spec
        };
        assert_eq!(
            bad.invalid_field().map(|f| f.0),
            Some("white_frequency_h0_s")
        );
    }

    #[test]
    fn a_noise_free_clock_drifts_linearly() {
        let spec = ReceiverClockSpec {
            white_frequency_h0_s: 0.0,
            random_walk_frequency_h_minus2_per_s: 0.0,
            ..ReceiverClockSpec::default()
        };
        let mut clock = ReceiverClock::new(&spec);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..10 {
            clock.advance(0.5, &mut rng);
        }
        clock.advance(0.0, &mut rng);
        clock.advance(f64::NAN, &mut rng);
        let s = clock.state();
        assert_eq!(s.drift_mps, 45.0);
        assert!((s.bias_m - (3000.0 + 45.0 * 5.0)).abs() < 1e-9);
    }
}
