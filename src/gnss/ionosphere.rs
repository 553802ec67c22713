//! How a measurement source treats the ionosphere: which pseudo-range it forms per
//! satellite and what it tells the engine in `SatObservation::iono_delay_m`.

use crate::gnss::ephemeris::Signal;
use crate::gnss::Constellation;

/// The ionosphere treatment of the pseudo-ranges built from raw multi-frequency data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IonosphereMode {
    /// The dual-frequency ionosphere-free combination where a satellite has a pair of
    /// [`iono_free_pairs`]; its ionospheric delay is reported as 0 so no model is added.
    /// Satellites without such a pair are left out: a single-frequency range next to
    /// ionosphere-free ones would bring back metres of delay as a bias.
    ///
    /// The default: the first-order ionosphere (metres at solar maximum, and no
    /// broadcast model may be at hand, as in a short log) cancels exactly; the price is
    /// about three times the code noise.
    #[default]
    IonoFree,
    /// One signal per satellite; the ionospheric delay is left unset so the engine
    /// applies the broadcast Klobuchar model when the epoch carries its coefficients
    /// (and nothing otherwise).
    Broadcast,
    /// One signal per satellite, the ionospheric delay reported as 0: no correction.
    None,
}

/// The ionosphere-free pairs (first, second) of a constellation, best first: those whose
/// group delays the broadcast ephemeris defines (see [`crate::gnss::ephemeris::group_delay_s`]).
///
/// - GPS: L1 C/A + L2C, the pair the LNAV clock refers to (L5 needs CNAV's ISC_L5).
/// - Galileo: E1 + E5a, then E1 + E5b (I/NAV broadcasts both BGDs).
/// - BeiDou: B1I + B3I, then B1I + B2I (D1/D2 give T_GD1 and T_GD2 against the B3I
///   clock; B1C and B2a need the B-CNAV group delays).
/// - QZSS, GLONASS, SBAS: none.
pub fn iono_free_pairs(constellation: Constellation) -> &'static [(Signal, Signal)] {
    match constellation {
        Constellation::Gps => &[(Signal::GpsL1Ca, Signal::GpsL2C)],
        Constellation::Galileo => &[
            (Signal::GalileoE1, Signal::GalileoE5a),
            (Signal::GalileoE1, Signal::GalileoE5b),
        ],
        Constellation::Beidou => &[
            (Signal::BeidouB1I, Signal::BeidouB3I),
            (Signal::BeidouB1I, Signal::BeidouB2I),
        ],
        Constellation::Qzss | Constellation::Glonass | Constellation::Sbas => &[],
    }
}
