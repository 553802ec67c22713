//! What a pseudo-range measures: one signal, or the dual-frequency ionosphere-free
//! combination of two signals of the same satellite; its coefficients and the group delay
//! it needs from the broadcast clock.
//!
//! Ionosphere-free combination (first-order ionosphere, delay ∝ 1/f²): with
//! γ = (f₁/f₂)², P_IF = a₁ P₁ + a₂ P₂, a₁ = γ/(γ − 1), a₂ = −1/(γ − 1), so a₁ + a₂ = 1
//! (geometry, clocks and troposphere pass unchanged) and a₁ I₁ + a₂ γ I₁ = 0. Each
//! signal's satellite group delay T_s (the correction of [`group_delay_s`]) enters the
//! same way: T_IF = a₁ T₁ + a₂ T₂ (for GPS L1/L2 with T_L2 = γ T_GD this is 0: the LNAV
//! clock refers to that combination). Independent noise: σ_IF² = a₁² σ₁² + a₂² σ₂².

use super::kepler::KeplerianEphemeris;
use super::signal::{group_delay_s, Signal};

/// The observable a pseudo-range stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RangingCode {
    /// One signal.
    Single(Signal),
    /// The ionosphere-free combination of two signals of different frequencies.
    IonoFree {
        /// The first signal (the higher frequency; its Doppler gives the rate).
        first: Signal,
        /// The second signal.
        second: Signal,
    },
}

impl From<Signal> for RangingCode {
    fn from(signal: Signal) -> Self {
        Self::Single(signal)
    }
}

/// Coefficients (a₁, a₂) of the ionosphere-free combination a₁ P₁ + a₂ P₂ of signals at
/// `f1_hz` and `f2_hz`; None when the frequencies are equal or not positive and finite.
pub fn iono_free_coefficients(f1_hz: f64, f2_hz: f64) -> Option<(f64, f64)> {
    let valid = |f: f64| f.is_finite() && f > 0.0;
    if !valid(f1_hz) || !valid(f2_hz) || f1_hz == f2_hz {
        return None;
    }
    let gamma = (f1_hz / f2_hz) * (f1_hz / f2_hz);
    Some((gamma / (gamma - 1.0), -1.0 / (gamma - 1.0)))
}

impl RangingCode {
    /// The signal whose Doppler and C/N0 describe the measurement (the first one).
    pub fn primary(self) -> Signal {
        match self {
            Self::Single(s) => s,
            Self::IonoFree { first, .. } => first,
        }
    }

    /// Coefficients of the signals in the measurement: (1, 0) for one signal.
    pub fn coefficients(self) -> Option<(f64, f64)> {
        match self {
            Self::Single(_) => Some((1.0, 0.0)),
            Self::IonoFree { first, second } => {
                iono_free_coefficients(first.carrier_frequency_hz(), second.carrier_frequency_hz())
            }
        }
    }

    /// The group delay (s) to subtract from the broadcast clock offset for this
    /// measurement; Err names a signal the ephemeris has no correction for.
    pub fn group_delay_s(self, eph: &KeplerianEphemeris) -> Result<f64, Signal> {
        match self {
            Self::Single(s) => group_delay_s(eph, s).ok_or(s),
            Self::IonoFree { first, second } => {
                let (a1, a2) = self.coefficients().ok_or(second)?;
                let t1 = group_delay_s(eph, first).ok_or(first)?;
                let t2 = group_delay_s(eph, second).ok_or(second)?;
                Ok(a1 * t1 + a2 * t2)
            }
        }
    }

    /// The measurement and its σ from the two signals' pseudo-ranges and σ (the second
    /// pair is ignored for one signal); None when a combination is not defined.
    pub fn combine(self, first: (f64, f64), second: Option<(f64, f64)>) -> Option<(f64, f64)> {
        let (a1, a2) = self.coefficients()?;
        match (self, second) {
            (Self::Single(_), _) => Some(first),
            (Self::IonoFree { .. }, Some((p2, s2))) => {
                let (p1, s1) = first;
                Some((
                    a1 * p1 + a2 * p2,
                    (a1 * a1 * s1 * s1 + a2 * a2 * s2 * s2).sqrt(),
                ))
            }
            (Self::IonoFree { .. }, None) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::ephemeris::signal::{FREQ_L1_HZ, FREQ_L2_HZ, FREQ_L5_HZ};
    use crate::gnss::ephemeris::GroupDelay;

    #[test]
    fn combination_removes_a_first_order_delay_and_keeps_the_range() {
        for (f1, f2) in [(FREQ_L1_HZ, FREQ_L2_HZ), (FREQ_L1_HZ, FREQ_L5_HZ)] {
            let (a1, a2) = iono_free_coefficients(f1, f2).unwrap();
            assert!((a1 + a2 - 1.0).abs() < 1e-12);
            // A delay of 40.3 TEC / f² on each frequency.
            let tec = 3.0e17;
            let i = |f: f64| 40.3 * tec / (f * f);
            let range = 2.2e7;
            let p_if = a1 * (range + i(f1)) + a2 * (range + i(f2));
            assert!((p_if - range).abs() < 1e-6, "{}", p_if - range);
        }
        // GPS L1/L2: a₁ = 2.546, a₂ = −1.546.
        let (a1, a2) = iono_free_coefficients(FREQ_L1_HZ, FREQ_L2_HZ).unwrap();
        assert!((a1 - 2.5457).abs() < 1e-3 && (a2 + 1.5457).abs() < 1e-3);
        assert_eq!(iono_free_coefficients(FREQ_L1_HZ, FREQ_L1_HZ), None);
        assert_eq!(iono_free_coefficients(FREQ_L1_HZ, f64::NAN), None);
    }

    #[test]
    fn sigma_propagates_from_both_signals() {
        let code = RangingCode::IonoFree {
            first: Signal::GpsL1Ca,
            second: Signal::GpsL2C,
        };
        let (a1, a2) = code.coefficients().unwrap();
        let (p, s) = code
            .combine((2.0e7, 0.3), Some((2.0e7 + 2.0, 0.4)))
            .unwrap();
        assert!((p - (2.0e7 + 2.0 * a2)).abs() < 1e-6);
        let expected = ((a1 * 0.3).powi(2) + (a2 * 0.4).powi(2)).sqrt();
        assert!((s - expected).abs() < 1e-12);
        assert_eq!(code.combine((2.0e7, 0.3), None), None);
        let single = RangingCode::from(Signal::GpsL1Ca);
        assert_eq!(single.combine((2.0e7, 0.3), None), Some((2.0e7, 0.3)));
    }

    #[test]
    fn gps_l1_l2_combination_needs_no_group_delay() {
        let mut eph = crate::gnss::ephemeris::kepler::tests::g32();
        eph.group_delay = GroupDelay::Gps { tgd_s: 7.0e-9 };
        let single = RangingCode::Single(Signal::GpsL1Ca).group_delay_s(&eph);
        assert_eq!(single, Ok(7.0e-9));
        let l1_l2 = RangingCode::IonoFree {
            first: Signal::GpsL1Ca,
            second: Signal::GpsL2C,
        };
        assert!(l1_l2.group_delay_s(&eph).unwrap().abs() < 1e-20);
        let l1_l5 = RangingCode::IonoFree {
            first: Signal::GpsL1Ca,
            second: Signal::GpsL5,
        };
        assert_eq!(l1_l5.group_delay_s(&eph), Err(Signal::GpsL5));
    }
}
