//! Signals, their carrier frequencies, and the group-delay correction each needs from the
//! broadcast clock.

use super::kepler::{GroupDelay, KeplerianEphemeris};
use crate::gnss::Constellation;

/// GPS/QZSS L1, Galileo E1, BeiDou B1C carrier (Hz).
pub const FREQ_L1_HZ: f64 = 1_575.42e6;
/// GPS/QZSS L2 carrier (Hz).
pub const FREQ_L2_HZ: f64 = 1_227.60e6;
/// GPS L5, Galileo E5a, BeiDou B2a carrier (Hz).
pub const FREQ_L5_HZ: f64 = 1_176.45e6;
/// Galileo E5b, BeiDou B2I carrier (Hz).
pub const FREQ_E5B_HZ: f64 = 1_207.14e6;
/// Galileo E6 carrier (Hz).
pub const FREQ_E6_HZ: f64 = 1_278.75e6;
/// BeiDou B1I carrier (Hz).
pub const FREQ_B1I_HZ: f64 = 1_561.098e6;
/// BeiDou B3I carrier (Hz).
pub const FREQ_B3I_HZ: f64 = 1_268.52e6;

/// A ranging signal (constellation and band/code).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Signal {
    /// GPS L1 C/A.
    GpsL1Ca,
    /// GPS L2C (CL or CM).
    GpsL2C,
    /// GPS L5 (I or Q).
    GpsL5,
    /// Galileo E1 (B or C).
    GalileoE1,
    /// Galileo E5a (I or Q).
    GalileoE5a,
    /// Galileo E5b (I or Q).
    GalileoE5b,
    /// Galileo E6 (B or C).
    GalileoE6,
    /// BeiDou B1I.
    BeidouB1I,
    /// BeiDou B2I.
    BeidouB2I,
    /// BeiDou B3I.
    BeidouB3I,
    /// BeiDou B1C.
    BeidouB1C,
    /// BeiDou B2a.
    BeidouB2a,
    /// QZSS L1 C/A.
    QzssL1Ca,
    /// SBAS L1.
    SbasL1,
}

impl Signal {
    /// The constellation transmitting the signal.
    pub fn constellation(self) -> Constellation {
        match self {
            Self::GpsL1Ca | Self::GpsL2C | Self::GpsL5 => Constellation::Gps,
            Self::GalileoE1 | Self::GalileoE5a | Self::GalileoE5b | Self::GalileoE6 => {
                Constellation::Galileo
            }
            Self::BeidouB1I
            | Self::BeidouB2I
            | Self::BeidouB3I
            | Self::BeidouB1C
            | Self::BeidouB2a => Constellation::Beidou,
            Self::QzssL1Ca => Constellation::Qzss,
            Self::SbasL1 => Constellation::Sbas,
        }
    }

    /// Carrier frequency (Hz).
    pub fn carrier_frequency_hz(self) -> f64 {
        match self {
            Self::GpsL1Ca | Self::GalileoE1 | Self::BeidouB1C | Self::QzssL1Ca | Self::SbasL1 => {
                FREQ_L1_HZ
            }
            Self::GpsL2C => FREQ_L2_HZ,
            Self::GpsL5 | Self::GalileoE5a | Self::BeidouB2a => FREQ_L5_HZ,
            Self::GalileoE5b | Self::BeidouB2I => FREQ_E5B_HZ,
            Self::GalileoE6 => FREQ_E6_HZ,
            Self::BeidouB1I => FREQ_B1I_HZ,
            Self::BeidouB3I => FREQ_B3I_HZ,
        }
    }

    /// Carrier wavelength (m).
    pub fn wavelength_m(self) -> f64 {
        crate::earth::SPEED_OF_LIGHT_M_S / self.carrier_frequency_hz()
    }
}

/// The group delay (s) to subtract from the broadcast clock offset for a single-frequency
/// user of `signal`: Δt_sv(signal) = Δt_sv − T(signal). None when the ephemeris carries
/// no correction for that signal (then the signal should not be used with it).
///
/// - GPS/QZSS LNAV (IS-GPS-200 20.3.3.3.3.2): L1 C/A T_GD; L2C γ·T_GD, the L2 P(Y)
///   correction. Choice: the CNAV inter-signal corrections ISC_L1C/A and ISC_L2C, which
///   LNAV does not carry, are taken as zero (the C/A–P(Y) and L2C–P(Y) biases, typically
///   below 1 ns). L5 needs ISC_L5, which LNAV has no stand-in for: None.
/// - Galileo (OS SIS ICD 5.1.5): I/NAV clock (E1,E5b): E1 BGD(E1,E5b), E5b γ·BGD(E1,E5b);
///   F/NAV clock (E1,E5a): E1 BGD(E1,E5a), E5a γ·BGD(E1,E5a); γ = (f_E1/f_E5)². I/NAV also
///   broadcasts BGD(E1,E5a), so E5a against the I/NAV clock is E1's correction plus the
///   E5a−E1 delay difference of the F/NAV relations: BGD(E1,E5b) + (γ_E5a − 1)·BGD(E1,E5a).
/// - BeiDou D1/D2 (BDS ICD 5.2.4.10): clock refers to B3I: B1I T_GD1, B2I T_GD2, B3I 0.
///   B1C and B2a need the B-CNAV group delays, which D1/D2 do not carry: None.
pub fn group_delay_s(eph: &KeplerianEphemeris, signal: Signal) -> Option<f64> {
    use super::kepler::NavSource;
    if signal.constellation() != eph.sat.constellation {
        return None;
    }
    let gamma = |f: f64| (FREQ_L1_HZ / f) * (FREQ_L1_HZ / f);
    match (eph.group_delay, signal) {
        (GroupDelay::Gps { tgd_s }, Signal::GpsL1Ca | Signal::QzssL1Ca) => Some(tgd_s),
        (GroupDelay::Gps { tgd_s }, Signal::GpsL2C) => Some(gamma(FREQ_L2_HZ) * tgd_s),
        (
            GroupDelay::Galileo {
                bgd_e1_e5a_s,
                bgd_e1_e5b_s,
            },
            _,
        ) if eph.source == NavSource::GalileoInav => {
            let bgd = bgd_e1_e5b_s?;
            match signal {
                Signal::GalileoE1 => Some(bgd),
                Signal::GalileoE5b => Some(gamma(FREQ_E5B_HZ) * bgd),
                Signal::GalileoE5a => Some(bgd + (gamma(FREQ_L5_HZ) - 1.0) * bgd_e1_e5a_s),
                _ => None,
            }
        }
        (GroupDelay::Galileo { bgd_e1_e5a_s, .. }, Signal::GalileoE1) => Some(bgd_e1_e5a_s),
        (GroupDelay::Galileo { bgd_e1_e5a_s, .. }, Signal::GalileoE5a) => {
            Some(gamma(FREQ_L5_HZ) * bgd_e1_e5a_s)
        }
        (GroupDelay::Beidou { tgd1_s, .. }, Signal::BeidouB1I) => Some(tgd1_s),
        (GroupDelay::Beidou { tgd2_s, .. }, Signal::BeidouB2I) => Some(tgd2_s),
        (GroupDelay::Beidou { .. }, Signal::BeidouB3I) => Some(0.0),
        _ => None,
    }
}
