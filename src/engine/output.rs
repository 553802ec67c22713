//! What the engine hands out: navigation solutions, per-epoch measurement reports (the
//! content of the covariance-diagnostic topic) and status events.

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::earth::{self, Llh};
use crate::gnss::SatId;
use crate::ins::error_state::{StateMatrix, DP, DV, N, PHI};
use crate::ins::NavState;

/// One navigation solution at an IMU time.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// The corrected nominal state (position of the IMU, velocity, attitude).
    pub nav: NavState,
    /// Full error-state covariance (units of [`crate::ins::error_state`]).
    pub covariance: StateMatrix,
    /// Estimated gyro bias, constant plus Gauss-Markov part, body FLU (rad/s).
    pub gyro_bias_rad_s: Vector3<f64>,
    /// Estimated accelerometer bias, body FLU (m/s²).
    pub accel_bias_m_s2: Vector3<f64>,
    /// Receiver clock offset c·δt_u (m).
    pub clock_bias_m: f64,
    /// Receiver clock drift c·δt_ru (m/s).
    pub clock_drift_mps: f64,
    /// Angular rate of the body (bias-compensated), for twist outputs (rad/s).
    pub angular_rate_b_rad_s: Vector3<f64>,
}

impl Solution {
    /// Covariance of (E, N, U) position in metres², from the (δL, δλ, δh) block.
    pub fn position_covariance_enu_m2(&self) -> Matrix3<f64> {
        position_covariance_enu_m2(&self.nav.p, &self.covariance)
    }

    /// Adds the outer product of `offset_enu_m` (m) to the position covariance: the
    /// solution may be off by that much beyond its own covariance.
    pub fn widen_position_by(&mut self, offset_enu_m: &Vector3<f64>) {
        self.widen_position_by_covariance(&(offset_enu_m * offset_enu_m.transpose()));
    }

    /// Adds `covariance_enu_m2` (ENU, m²) to the position covariance, as the (δL, δλ, δh)
    /// block holds it.
    pub fn widen_position_by_covariance(&mut self, covariance_enu_m2: &Matrix3<f64>) {
        let (north, east) = earth::metres_per_radian(&self.nav.p);
        #[rustfmt::skip]
        let enu_to_block = Matrix3::new(
            0.0, 1.0 / north, 0.0,
            1.0 / east, 0.0, 0.0,
            0.0, 0.0, 1.0,
        );
        let mut block = self.covariance.fixed_view_mut::<3, 3>(DP, DP);
        block += enu_to_block * covariance_enu_m2 * enu_to_block.transpose();
    }

    /// Widens the position covariance so that it is at least `floor_enu_m2` (ENU, m²) in
    /// every direction (see [`shortfall`]).
    pub fn widen_position_to_at_least(&mut self, floor_enu_m2: &Matrix3<f64>) {
        if let Some(short) = shortfall(floor_enu_m2, &self.position_covariance_enu_m2()) {
            self.widen_position_by_covariance(&short);
        }
    }

    /// Widens the velocity covariance so that it is at least `floor_enu_m2_s2` (ENU,
    /// (m/s)²) in every direction, as [`Self::widen_position_to_at_least`].
    pub fn widen_velocity_to_at_least(&mut self, floor_enu_m2_s2: &Matrix3<f64>) {
        if let Some(short) = shortfall(floor_enu_m2_s2, &self.velocity_covariance_enu_m2_s2()) {
            self.widen_velocity_by_covariance(&short);
        }
    }

    /// Adds `covariance_enu_m2_s2` (ENU, (m/s)²) to the velocity covariance.
    fn widen_velocity_by_covariance(&mut self, covariance_enu_m2_s2: &Matrix3<f64>) {
        let mut block = self.covariance.fixed_view_mut::<3, 3>(DV, DV);
        block += covariance_enu_m2_s2;
    }

    /// Covariance of the ENU velocity ((m/s)²).
    pub fn velocity_covariance_enu_m2_s2(&self) -> Matrix3<f64> {
        self.covariance.fixed_view::<3, 3>(DV, DV).into()
    }

    /// Covariance of the attitude error φ about the E, N, U axes (rad²).
    pub fn attitude_covariance_rad2(&self) -> Matrix3<f64> {
        self.covariance.fixed_view::<3, 3>(PHI, PHI).into()
    }

    /// 6×6 pose covariance (E, N, U, rotation about E, N, U), in the ROS pose order.
    pub fn pose_covariance_enu(&self) -> SMatrix<f64, 6, 6> {
        let (north, east) = earth::metres_per_radian(&self.nav.p);
        let mut t = SMatrix::<f64, 6, N>::zeros();
        t[(0, DP + 1)] = east;
        t[(1, DP)] = north;
        t[(2, DP + 2)] = 1.0;
        for i in 0..3 {
            t[(3 + i, PHI + i)] = 1.0;
        }
        t * self.covariance * t.transpose()
    }
}

/// Covariance of (E, N, U) position in metres² at `p`, from the (δL, δλ, δh) block of
/// the error-state covariance `covariance`.
pub fn position_covariance_enu_m2(p: &Llh, covariance: &StateMatrix) -> Matrix3<f64> {
    let (north, east) = earth::metres_per_radian(p);
    // (E, N, U) = T (δL, δλ, δh) with T = [[0, east, 0], [north, 0, 0], [0, 0, 1]].
    let t = Matrix3::new(0.0, east, 0.0, north, 0.0, 0.0, 0.0, 0.0, 1.0);
    let block: Matrix3<f64> = covariance.fixed_view::<3, 3>(DP, DP).into();
    t * block * t.transpose()
}

/// Why a satellite's measurement was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SatRejection {
    ElevationMask,
    Cn0Mask,
    InnovationGate,
    NotANumber,
    NoSatelliteState,
    Mahalanobis,
    ConstellationDisabled,
}

impl SatRejection {
    /// Stable snake_case name, used for counters and diagnostics.
    pub fn name(self) -> &'static str {
        match self {
            Self::ElevationMask => "elevation_mask",
            Self::Cn0Mask => "cn0_mask",
            Self::InnovationGate => "innovation_gate",
            Self::NotANumber => "not_a_number",
            Self::NoSatelliteState => "no_satellite_state",
            Self::Mahalanobis => "mahalanobis",
            Self::ConstellationDisabled => "constellation_disabled",
        }
    }
}

/// Why a satellite's carrier-phase change was left out of a time-differenced carrier-phase
/// update (the reasons it shares with the pseudo-ranges are [`SatRejection`]s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PhaseRejection {
    /// The phase may have slipped since the previous epoch (loss of lock, lock time
    /// decreased, or a phase change the Doppler does not explain).
    CycleSlip,
    /// The receiver has not resolved the half-cycle ambiguity at either epoch.
    HalfCycleUnresolved,
    /// No valid wavelength, or another one than at the previous epoch.
    NoWavelength,
    /// Too few phase changes passed the other tests for an update that can tell a slip
    /// from the receiver clock's change.
    TooFewPhases,
}

impl PhaseRejection {
    /// Stable snake_case name, used for counters and diagnostics.
    pub fn name(self) -> &'static str {
        match self {
            Self::CycleSlip => "cycle_slip",
            Self::HalfCycleUnresolved => "half_cycle_unresolved",
            Self::NoWavelength => "no_wavelength",
            Self::TooFewPhases => "too_few_phases",
        }
    }
}

/// One satellite's part of an epoch report. NaN marks a value that was not computed.
#[derive(Debug, Clone, PartialEq)]
pub struct SatReport {
    pub sat: SatId,
    pub elevation_rad: f64,
    /// Pseudo-range used in the update.
    pub used_pseudorange: bool,
    /// Pseudo-range rate used in the update.
    pub used_rate: bool,
    /// Why the pseudo-range (or, if only that failed, the rate) was left out.
    pub rejection: Option<SatRejection>,
    /// Why the carrier-phase change was left out (carrier-phase reports only).
    pub phase_rejection: Option<PhaseRejection>,
    /// Innovation measured − predicted of the pseudo-range (m).
    pub innovation_pseudorange_m: f64,
    /// Innovation measured − predicted of the rate (m/s).
    pub innovation_rate_mps: f64,
    /// Innovation divided by √(H P Hᵀ + R) of its own row.
    pub normalized_innovation_pseudorange: f64,
    pub normalized_innovation_rate: f64,
    /// Measurement variance used for the pseudo-range (m²).
    pub r_pseudorange_m2: f64,
    /// Measurement variance used for the rate ((m/s)²).
    pub r_rate_m2_s2: f64,
    /// KDE density of the newest pseudo-range mutual difference (NaN: not computed).
    pub kde_credibility: f64,
    /// Gaussian verdict of the KDE test (None: not computed).
    pub gaussian: Option<bool>,
    /// Order of the AR model in use for the pseudo-range (None: none).
    pub ar_order: Option<u8>,
    /// Weight factor of a robust scheme, 1 = full weight (NaN: no robust scheme).
    pub robust_weight: f64,
}

impl SatReport {
    pub fn new(sat: SatId) -> Self {
        Self {
            sat,
            elevation_rad: f64::NAN,
            used_pseudorange: false,
            used_rate: false,
            rejection: None,
            phase_rejection: None,
            innovation_pseudorange_m: f64::NAN,
            innovation_rate_mps: f64::NAN,
            normalized_innovation_pseudorange: f64::NAN,
            normalized_innovation_rate: f64::NAN,
            r_pseudorange_m2: f64::NAN,
            r_rate_m2_s2: f64::NAN,
            kde_credibility: f64::NAN,
            gaussian: None,
            ar_order: None,
            robust_weight: f64::NAN,
        }
    }
}

/// Kind of measurement an epoch report describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeasurementKind {
    /// Raw pseudo-ranges and rates (tightly coupled).
    Pseudoranges,
    /// A position (and optional velocity) fix (loosely coupled).
    Fix,
    /// Zero velocity at a standstill (ZUPT).
    ZeroVelocity,
    /// Zero angular rate (the earth's only) at a standstill (ZARU).
    ZeroRate,
    /// No lateral or vertical velocity of a wheeled vehicle (NHC).
    NonHolonomic,
    /// The forward speed of a wheeled vehicle from its wheels (wheel odometry).
    WheelSpeed,
    /// The heading of a dual-antenna (moving-base) receiver pair's baseline.
    BaselineHeading,
    /// Time-differenced carrier phases: each satellite's phase change since the previous
    /// epoch (tightly coupled; its satellites' pseudo-range fields report the phase change,
    /// in m, and its rate fields are unused).
    CarrierPhaseDeltas,
}

/// The diagnostics of one measurement update.
#[derive(Debug, Clone, PartialEq)]
pub struct EpochReport {
    pub t_s: f64,
    pub kind: MeasurementKind,
    /// Filter variant name (as in the parameters).
    pub variant: &'static str,
    pub satellites: Vec<SatReport>,
    /// Number of scalar measurements used.
    pub measurements_used: usize,
    /// Normalized innovation squared of the update (NaN without an update).
    pub nis: f64,
    /// νᵀ(H P⁻ Hᵀ + R)⁻¹ν with the prior and the noise strategy's R before any robust
    /// inflation or adaptive factor (NaN without an update; equal to `nis` for the plain
    /// filters).
    pub prior_nis: f64,
    /// ln det(H P⁻ Hᵀ + R) of the same matrix (NaN without an update): with `prior_nis`,
    /// the measurement's log-likelihood (what the heading bank scores).
    pub prior_log_det_s: f64,
    /// A receiver clock jump absorbed in this epoch (m), 0 if none.
    pub clock_jump_m: f64,
    /// Adaptive factor α of an adaptive scheme (NaN: none).
    pub adaptive_factor: f64,
    /// Mahalanobis distance² of the innovation vector (NaN: not tested).
    pub mahalanobis_d2: f64,
    /// χ² threshold the distance was tested against (NaN: not tested).
    pub chi2_threshold: f64,
    /// Process-noise scale in use (1 = the configured Q).
    pub q_scale: f64,
    /// Robust weight 1/λ_ii per row of a loosely-coupled fix (E, N, U position, then the
    /// velocity rows); empty without a robust scheme and in tight coupling, where the
    /// weights are per satellite.
    pub fix_robust_weights: Vec<f64>,
    /// The position (velocity) of a loosely-coupled fix lay beyond
    /// `loose.fix_outlier_sigma` and was deweighted.
    pub fix_position_outlier: bool,
    pub fix_velocity_outlier: bool,
    /// The factors on a loosely-coupled fix's claimed position covariance, then on its
    /// velocity's, from the fixes before (`loose.fix_consistency`; 1: taken as claimed);
    /// empty in tight coupling.
    pub fix_scales: Vec<f64>,
    /// The fix was held back by a GNSS leap (`loose.leap_hold_s`).
    pub fix_held_back: bool,
    /// Pseudo-ranges and rates whose variance the error-correlation judge inflated.
    pub correlated_measurements: usize,
    /// The report of the epoch's time-differenced carrier-phase update, applied before the
    /// pseudo-ranges (`gnss.tdcp`; None when off or without a previous epoch's phases).
    pub carrier_phase_deltas: Option<Box<EpochReport>>,
}

impl EpochReport {
    /// An empty report of the variant named `variant`.
    pub fn new(t_s: f64, kind: MeasurementKind, variant: &'static str) -> Self {
        Self {
            t_s,
            kind,
            variant,
            satellites: Vec::new(),
            measurements_used: 0,
            nis: f64::NAN,
            prior_nis: f64::NAN,
            prior_log_det_s: f64::NAN,
            clock_jump_m: 0.0,
            adaptive_factor: f64::NAN,
            mahalanobis_d2: f64::NAN,
            chi2_threshold: f64::NAN,
            q_scale: 1.0,
            fix_robust_weights: Vec::new(),
            fix_position_outlier: false,
            fix_velocity_outlier: false,
            fix_scales: Vec::new(),
            fix_held_back: false,
            correlated_measurements: 0,
            carrier_phase_deltas: None,
        }
    }
}

/// The measurements deweighted so far (shown on /diagnostics): receiver fixes whose
/// position or velocity was an outlier (`loose.fix_outlier_sigma`), whose claimed
/// position or velocity covariance was scaled (`loose.fix_consistency`) or which were held
/// back by a GNSS leap (`loose.leap_hold_s`), and pseudo-ranges
/// and rates whose variance was inflated for their errors' time correlation
/// (`gnss.error_correlation`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Deweighted {
    pub position: u64,
    pub velocity: u64,
    pub position_rescaled: u64,
    pub velocity_rescaled: u64,
    pub held_back: u64,
    pub correlated: u64,
}

impl Deweighted {
    /// Counts the deweighted measurements of the update `report`.
    pub fn count(&mut self, report: &EpochReport) {
        self.correlated += report.correlated_measurements as u64;
        self.position += u64::from(report.fix_position_outlier);
        self.velocity += u64::from(report.fix_velocity_outlier);
        let rescaled =
            |block: usize| u64::from(report.fix_scales.get(block).is_some_and(|&s| s > 1.0));
        self.position_rescaled += rescaled(0);
        self.velocity_rescaled += rescaled(1);
        self.held_back += u64::from(report.fix_held_back);
    }
}

/// Life-cycle events.
#[derive(Debug, Clone, PartialEq)]
pub enum StatusEvent {
    /// The filter started; `heading_from_motion` tells how the heading was found.
    Initialized { t_s: f64, heading_from_motion: bool },
    /// The filter was reset and waits for a new initialization.
    Reset { t_s: f64, reason: ResetReason },
}

/// Why the filter was reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResetReason {
    /// The IMU stream had a gap longer than `engine.max_imu_gap_s`.
    ImuGap,
    /// Time went backwards (a bag played in a loop), handled by the caller.
    TimeJumpBackwards,
    /// A measurement update produced a non-finite state.
    Diverged,
    /// The IMU stream moved to another `frame_id` (another sensor), handled by the caller.
    ImuFrameChanged,
    /// The filter disagreed with independent GNSS positions beyond their combined σ for
    /// a sustained time (see [`super::divergence`]).
    DivergedFromGnss,
}

/// Everything the engine emits.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    Solution(Box<Solution>),
    Epoch(EpochReport),
    Status(StatusEvent),
}

/// What `covariance` lacks of `floor` in every direction: the positive part of the floor
/// less the covariance. None for a zero floor, or a covariance that is not finite or has
/// a negative eigenvalue beyond rounding: a broken covariance is left as it is, for the
/// outputs to count and refuse, not repaired by a floor.
fn shortfall(floor: &Matrix3<f64>, covariance: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    if floor.iter().all(|&v| v == 0.0) || !covariance.iter().all(|v| v.is_finite()) {
        return None;
    }
    let eigenvalues = (0.5 * (covariance + covariance.transpose())).symmetric_eigenvalues();
    if eigenvalues.min() < -1e-9 * eigenvalues.amax() {
        return None;
    }
    Some(positive_part(&(floor - covariance)))
}

/// The positive semi-definite part of the symmetric part of `m`: its negative
/// eigenvalues set to zero.
fn positive_part(m: &Matrix3<f64>) -> Matrix3<f64> {
    let mut eigen = (0.5 * (m + m.transpose())).symmetric_eigen();
    eigen.eigenvalues.iter_mut().for_each(|v| *v = v.max(0.0));
    eigen.recompose()
}

#[cfg(test)]
mod tests {
    use super::super::filter_state::FilterState;
    use super::*;

    #[test]
    fn a_floor_widens_only_the_directions_it_exceeds() {
        let mut state = FilterState::moving(1e-12);
        let (north, east) = earth::metres_per_radian(&state.nav.p);
        state.p[(DP, DP)] = 4.0 / (north * north);
        state.p[(DP + 1, DP + 1)] = 1.0 / (east * east);
        state.p[(DP + 2, DP + 2)] = 9.0;
        let mut solution = state.solution();
        // East 1 → 2 m², north stays 4 m² (the floor's 3 is less), up stays 9 m².
        solution.widen_position_to_at_least(&Matrix3::from_diagonal(&Vector3::new(2.0, 3.0, 0.0)));
        let c = solution.position_covariance_enu_m2();
        let expected = Matrix3::from_diagonal(&Vector3::new(2.0, 4.0, 9.0));
        assert!((c - expected).norm() < 1e-9, "{c}");
        solution.widen_velocity_to_at_least(&(Matrix3::identity() * 0.25));
        let v = solution.velocity_covariance_enu_m2_s2();
        assert!((v - Matrix3::identity() * 0.25).norm() < 1e-9, "{v}");
    }

    #[test]
    fn a_floor_does_not_repair_a_broken_covariance() {
        let mut state = FilterState::moving(1e-12);
        state.p[(DP + 2, DP + 2)] = -1.0;
        let mut solution = state.solution();
        solution.widen_position_to_at_least(&Matrix3::zeros());
        assert_eq!(solution.position_covariance_enu_m2()[(2, 2)], -1.0);
        solution.widen_position_to_at_least(&(Matrix3::identity() * 4.0));
        assert_eq!(solution.position_covariance_enu_m2()[(2, 2)], -1.0);
    }
}
