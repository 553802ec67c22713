use nalgebra::Vector3;

/// GNSS constellations, numbered as the `SatelliteMeasurement.msg` constants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Constellation {
    Gps = 1,
    Glonass = 2,
    Galileo = 3,
    Beidou = 4,
    Qzss = 5,
    Sbas = 6,
}

impl Constellation {
    pub fn from_code(code: u8) -> Option<Self> {
        Some(match code {
            1 => Self::Gps,
            2 => Self::Glonass,
            3 => Self::Galileo,
            4 => Self::Beidou,
            5 => Self::Qzss,
            6 => Self::Sbas,
            _ => return None,
        })
    }

    pub fn code(self) -> u8 {
        self as u8
    }

    /// One-letter RINEX system identifier.
    pub fn rinex_letter(self) -> char {
        match self {
            Self::Gps => 'G',
            Self::Glonass => 'R',
            Self::Galileo => 'E',
            Self::Beidou => 'C',
            Self::Qzss => 'J',
            Self::Sbas => 'S',
        }
    }
}

/// A satellite: constellation and PRN (slot) number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SatId {
    pub constellation: Constellation,
    pub prn: u16,
}

impl std::fmt::Display for SatId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}{:02}", self.constellation.rinex_letter(), self.prn)
    }
}

/// One satellite's measurements and broadcast state at one receiver epoch.
/// Fields that may be absent are `None` (NaN on the wire).
#[derive(Debug, Clone, PartialEq)]
pub struct SatObservation {
    pub sat: SatId,
    /// The pseudo-range (m); None for a satellite kept only for its carrier phase and
    /// rate: one without a range of the epoch's kind (a single-frequency satellite beside
    /// ionosphere-free ranges, whose range would bring the ionosphere back as a bias).
    pub pseudorange_m: Option<f64>,
    pub pseudorange_rate_mps: Option<f64>,
    /// Receiver-reported 1σ of the pseudo-range (m).
    pub pseudorange_sigma_m: Option<f64>,
    /// Receiver-reported 1σ of the pseudo-range rate (m/s).
    pub pseudorange_rate_sigma_mps: Option<f64>,
    pub cn0_dbhz: Option<f64>,
    /// Satellite position at signal transmission time, in the ECEF frame of that time (m).
    pub sat_pos_ecef_m: Vector3<f64>,
    /// Satellite velocity in ECEF (m/s).
    pub sat_vel_ecef_mps: Vector3<f64>,
    /// Satellite clock offset, relativistic term included (s).
    pub sat_clock_bias_s: f64,
    /// Satellite clock drift (s/s).
    pub sat_clock_drift_s_s: f64,
    /// Ionospheric delay on this pseudo-range (m), if the source provides it.
    pub iono_delay_m: Option<f64>,
    /// Tropospheric delay on this pseudo-range (m), if the source provides it.
    pub tropo_delay_m: Option<f64>,
    /// The carrier phase, when tracked.
    pub carrier_phase: Option<CarrierPhase>,
}

/// A carrier-phase measurement: the phase counted in cycles of its carrier, with the sign
/// of the pseudo-range (it grows with the range) and an unknown, arbitrary integer
/// ambiguity that stays constant while the receiver keeps lock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarrierPhase {
    /// The phase (cycles).
    pub cycles: f64,
    /// Wavelength of the carrier (m); None: unknown, and the phase cannot be used.
    pub wavelength_m: Option<f64>,
    /// Receiver-reported 1σ of the phase (cycles).
    pub sigma_cycles: Option<f64>,
    /// Time the receiver has kept lock on the carrier (s).
    pub lock_time_s: Option<f64>,
    /// Lock was lost since the previous epoch: a cycle slip is possible.
    pub loss_of_lock: bool,
    /// The half-cycle ambiguity is not resolved: the phase may still jump by half a cycle.
    pub half_cycle_unresolved: bool,
}

/// Klobuchar broadcast ionosphere coefficients (α in s, s/sc, ...; β in s, s/sc, ...).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Klobuchar {
    pub alpha: [f64; 4],
    pub beta: [f64; 4],
}

/// All satellites measured at one receiver epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssEpoch {
    /// Receiver measurement time (s) on the engine's time axis.
    pub t_s: f64,
    /// GPS time of week of the measurement (s); the ionosphere model needs local time.
    pub gps_time_of_week_s: f64,
    pub satellites: Vec<SatObservation>,
    pub klobuchar: Option<Klobuchar>,
}
