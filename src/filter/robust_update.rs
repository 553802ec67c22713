//! The measurement update of every measurement model: the base filter (EKF or cubature) and
//! the schemes of the IARF paper (Jiang & Zhang 2018, Sensors 18:695) on top of it — the
//! adaptive factor α of the predicted residual (sections 2.1–2.2), the robust equivalent
//! covariance R̄ (section 3) and the Mahalanobis test that switches them (section 3). It
//! takes plain options and matrices; the caller feeds the correction back.
//!
//! Conventions: the error state is zero before the update (closed-loop feedback), `y` is
//! predicted − measured, and the result is the correction δx̂ and the posterior covariance,
//! which the caller feeds back into its nominal state.
//!
//! The cubature update on the error state: the 2n cubature points are error samples δxᵢ
//! around 0 drawn from N(0, P⁻); for each, [`ErrorStateModel::predict_corrected`] feeds it
//! back into a copy of the nominal state and predicts the measurements from that copy, so
//! the filter sees the full non-linearity of the measurement model. With
//! g(δx) = ŷ(nominal) − ŷ(nominal ⊕ δx) (≈ H δx to first order, the sign convention of the
//! EKF rows) the measurement of the error is `y` itself.
//!
//! Choice (time update of the cubature filter): the covariance is propagated by the same
//! linearized error dynamics as the EKF (the engine's `FilterState::propagate`). The error
//! dynamics are linear to first order in the small error, and an IMU-rate cubature time
//! update would cost 2n = 40 strapdown mechanizations per IMU sample; the IARF paper's
//! non-linearity argument (section 4) concerns models whose linearization is poor, which
//! for an error state in closed loop is the measurement side.
//!
//! Choice (posterior): Joseph's form (I − K̄H)P⁻(I − K̄H)ᵀ + K̄R̄K̄ᵀ with the un-inflated P⁻,
//! the measurements' own noise R̄ and the linearized rows H for both bases (for the
//! cubature base K̄ is the cubature gain P_xz S⁻¹ of the inflated prior): the covariance of
//! the estimate made with the gain K̄ = (P⁻/α)Hᵀ(HP⁻Hᵀ/α + R̄)⁻¹ from a prior P⁻ and
//! measurements of noise R̄, whatever the gain. This departs from the IARF paper's
//! eq. (16), P⁺ = P⁻ − K̄HP⁻ (in Joseph's form (I − K̄H)P⁻(I − K̄H)ᵀ + K̄(αR̄)K̄ᵀ, as
//! this module computed it before issue 11): K̄ is the optimal gain of P⁻ with the noise
//! αR̄, so eq. (16) is the posterior of measurements α times more precise than they are,
//! and every adaptive epoch shrinks P as if they were. Measured on
//! tests/data/consumer_mems_hour.yaml (akf_all, loosely coupled): a street-canyon fix
//! 159 m off gave α = 0.028, the state followed the fix and eq. (16) lowered the vertical
//! σ from 1.0 to 0.58 m; the following fixes, 50–160 m from that over-confident state,
//! again gave α of 0.03–0.1, and the filter stayed up to 75 m off with σ of 0.12–0.5 m
//! (mean NEES 5311 over the hour). With R̄ the σ after such a jump is the fix's own
//! (3–4 m) and the next good fixes bring the state back within seconds (mean NEES 33).
//! Yang's (I − K̄H)P⁻/α, which the adaptive-factor module documents as an alternative,
//! was measured to diverge on the outlier drive of tests/iarf_engine.rs (akf_all, α down
//! to 0.01): it multiplies the variance of every direction the fix does not observe (clock
//! states, parts of the attitude and biases) by 1/α at each adaptive epoch, and P
//! overflowed within 300 s on both bases. With α = 1 the three forms coincide. The plain EKF without a scheme keeps [`ekf::update`] and its
//! `filter.joseph_form` option.
//!
//! Choice (inert states): the EKF, the schemes and the cubature base run on the states that
//! are not inert ([`active_states`]: the optional scale factors when switched off, whose rows of
//! P⁻ are zero); an inert state keeps a zero correction and zero rows of P⁺. The cubature
//! rule needs a positive-definite P⁻, and with the inert states left out the update is,
//! to the bit, the one of the state without them.

use nalgebra::{DMatrix, DVector};

use crate::adaptive::adaptive_factor::AdaptiveFactorOptions;
use crate::adaptive::equivalent_covariance::{
    equivalent_measurement_covariance, EquivalentWeightOptions,
};
use crate::adaptive::mahalanobis::{chi_square_quantile, mahalanobis_squared};
use crate::adaptive::predicted_residual::{predicted_residual_statistic, standardized_residuals};
use crate::filter::cubature::{cubature_measurement_update, Gaussian};
use crate::filter::ekf::{self, FilterError};
use crate::ins::error_state::{active_states, StateMatrix, StateVector, N};
use crate::linalg::{symmetrize, SpdFactor, EIGEN_FLOOR};

/// The predicted measurements of the nominal state, alone and corrected by an error δx:
/// the measurement function the cubature base evaluates at its points.
pub trait ErrorStateModel {
    /// The predictions (m) of the nominal state; None when a prediction fails.
    fn predict_nominal(&self) -> Option<DVector<f64>>;
    /// The predictions (m) of the nominal state with the error `dx` fed back; None when a
    /// prediction fails.
    fn predict_corrected(&self, dx: &StateVector) -> Option<DVector<f64>>;
}

/// The measurements of one update, linearized at the nominal state, and their model.
pub struct MeasurementSet<'a> {
    /// Rows of H (m × N).
    pub h: DMatrix<f64>,
    /// Innovation y = predicted − measured at the nominal state (m).
    pub y: DVector<f64>,
    /// Measurement covariance R (m × m) of the noise strategy.
    pub r: DMatrix<f64>,
    /// The predictions in the order of `y`, used by the cubature base only.
    pub model: &'a dyn ErrorStateModel,
}

/// Which IARF-paper scheme runs on the base filter (section 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// No adaptive factor, no robust step (scheme 1 on the cubature base).
    Plain,
    /// Adaptive factor at every epoch (scheme 2).
    AdaptiveAll,
    /// Adaptive factor at the epochs passing the Mahalanobis test (scheme 3).
    AdaptivePartial,
    /// Robust R̄ at every epoch, adaptive factor at the epochs passing the test (scheme 4).
    AdaptivelyRobust,
}

impl Scheme {
    fn tests_mahalanobis(self) -> bool {
        matches!(self, Self::AdaptivePartial | Self::AdaptivelyRobust)
    }
}

/// The update: base filter, scheme and their constants.
#[derive(Debug, Clone)]
pub struct RobustUpdate {
    /// The cubature base (else the EKF).
    pub cubature: bool,
    pub scheme: Scheme,
    /// The adaptive factor α of the adaptive schemes.
    pub factor: AdaptiveFactorOptions,
    /// The equivalent weights of the robust scheme.
    pub weights: EquivalentWeightOptions,
    /// Confidence of the χ² test of the Mahalanobis distance.
    pub chi2_confidence: f64,
    /// Joseph's form in the plain EKF (the other combinations always use it, see the
    /// module documentation).
    pub joseph: bool,
}

/// What an update produced, for the report and the estimators that learn from it.
#[derive(Debug, Clone)]
pub struct UpdateOutcome {
    /// Innovation ν = y − ḡ (predicted − measured; ḡ = 0 for the EKF) (m).
    pub innovation: DVector<f64>,
    /// Innovation covariance the gain used, H P̄ Hᵀ + R̄ (m × m).
    pub s: DMatrix<f64>,
    /// H P⁻ Hᵀ (or the cubature covariance of the predictions) of the un-inflated prior.
    pub hph: DMatrix<f64>,
    /// R the noise strategy gave (before any robust inflation).
    pub r: DMatrix<f64>,
    /// νᵀ S⁻¹ ν with the S of the gain.
    pub nis: f64,
    /// νᵀ S₀⁻¹ ν and ln det S₀ with S₀ = H P⁻ Hᵀ + R, the un-inflated prior and the noise
    /// strategy's R (equal to `nis` and the gain's S without a scheme).
    pub prior_nis: f64,
    pub prior_log_det_s: f64,
    /// Adaptive factor α applied (NaN: no adaptive scheme).
    pub adaptive_factor: f64,
    /// M² of the nominal innovation covariance (NaN: not tested).
    pub mahalanobis_d2: f64,
    /// χ² quantile M² was tested against (NaN: not tested).
    pub chi2_threshold: f64,
    /// Robust weight 1/λ_ii per row (NaN: no robust step).
    pub robust_weights: DVector<f64>,
}

/// The result of an update: the correction to feed back and the posterior covariance.
#[derive(Debug, Clone)]
pub struct Correction {
    /// Error-state estimate δx̂.
    pub dx: StateVector,
    /// Posterior covariance.
    pub p: StateMatrix,
    pub outcome: UpdateOutcome,
}

/// Innovation, its covariance and the cross covariance of a prior.
struct Moments {
    innovation: DVector<f64>,
    s: DMatrix<f64>,
    pxz: DMatrix<f64>,
}

impl RobustUpdate {
    /// Updates the prior covariance `p` with `set`: the correction and the posterior, or an
    /// error (then nothing is to be fed back).
    pub fn update(&self, p: &StateMatrix, set: &MeasurementSet) -> Result<Correction, FilterError> {
        let m = set.y.len();
        if set.h.nrows() != m || set.h.ncols() != N || set.r.nrows() != m || set.r.ncols() != m {
            return Err(FilterError::DimensionMismatch {
                h_rows: set.h.nrows(),
                h_cols: set.h.ncols(),
                y_len: m,
                r_rows: set.r.nrows(),
                r_cols: set.r.ncols(),
            });
        }
        if !self.cubature && self.scheme == Scheme::Plain {
            return self.plain_ekf(p, set);
        }
        let sub = Subspace(active_states(p));
        let n = sub.0.len();
        let reduced = MeasurementSet {
            h: sub.columns(&set.h),
            y: set.y.clone(),
            r: set.r.clone(),
            model: set.model,
        };
        let set = &reduced;
        let mut prior = sub.matrix(p);
        if self.cubature {
            prior = covariance_for_cubature(&prior)?;
        }
        let nominal = self.moments(&prior, set, &set.r, &sub)?;
        let hph = symmetrize(&(&nominal.s - &set.r));
        let (prior_nis, prior_log_det_s) = normalized_squared(&nominal.innovation, &nominal.s);
        let mut outcome = UpdateOutcome {
            innovation: nominal.innovation.clone(),
            s: nominal.s.clone(),
            hph,
            r: set.r.clone(),
            nis: f64::NAN,
            prior_nis,
            prior_log_det_s,
            adaptive_factor: f64::NAN,
            mahalanobis_d2: f64::NAN,
            chi2_threshold: f64::NAN,
            robust_weights: DVector::from_element(m, f64::NAN),
        };
        let passes = if self.scheme.tests_mahalanobis() {
            let (d2, _) = mahalanobis_squared(&nominal.innovation, &nominal.s)?;
            let threshold = chi_square_quantile(self.chi2_confidence, m)?;
            outcome.mahalanobis_d2 = d2;
            outcome.chi2_threshold = threshold;
            d2 <= threshold
        } else {
            true
        };
        let alpha = match self.scheme {
            Scheme::Plain => 1.0,
            Scheme::AdaptiveAll | Scheme::AdaptivePartial | Scheme::AdaptivelyRobust => {
                let a = if passes {
                    let statistic = predicted_residual_statistic(&nominal.innovation, &nominal.s)?;
                    self.factor.adaptive_factor(statistic)?
                } else {
                    1.0
                };
                outcome.adaptive_factor = a;
                a
            }
        };
        let r_bar = if self.scheme == Scheme::AdaptivelyRobust {
            let standardized = standardized_residuals(&nominal.innovation, &nominal.s)?;
            let eq = equivalent_measurement_covariance(&set.r, &standardized, &self.weights)?;
            outcome.robust_weights = eq.inflation.map(|l| 1.0 / l);
            Some(eq.covariance)
        } else {
            None
        };
        let r_bar_used = r_bar.clone();
        let moments = if alpha == 1.0 && r_bar.is_none() {
            nominal
        } else {
            // Math note: P⁻/α of a symmetric positive-definite P⁻ stays so (α ≥ α_floor > 0),
            // and R̄ = D R D is a congruence of R; both are symmetrised before use.
            let inflated = symmetrize(&prior) / alpha;
            let r_used = r_bar.unwrap_or_else(|| set.r.clone());
            self.moments(&inflated, set, &r_used, &sub)?
        };
        let factor = SpdFactor::new("innovation covariance", &moments.s)?;
        let gain = factor.solve(&moments.pxz.transpose()).transpose();
        let dx = &gain * &moments.innovation;
        // Joseph's form with the measurements' noise R̄ (not the paper's αR̄, see the
        // module's "Choice (posterior)"): the covariance of the estimate of the gain K̄
        // from the prior P⁻, never below the optimal posterior of P⁻ and R̄.
        let a = DMatrix::identity(n, n) - &gain * &set.h;
        let r_used = r_bar_used.unwrap_or_else(|| set.r.clone());
        let posterior = symmetrize(
            &(&a * &prior * a.transpose() + &gain * symmetrize(&r_used) * gain.transpose()),
        );
        let nis = moments
            .innovation
            .dot(&factor.solve_vector(&moments.innovation));
        let dx = sub.full_vector(&dx);
        let posterior = sub.full_matrix(&posterior);
        if !(dx.iter().all(|v| v.is_finite())
            && posterior.iter().all(|v| v.is_finite())
            && nis.is_finite())
        {
            return Err(FilterError::NonFinite);
        }
        outcome.s = moments.s;
        outcome.innovation = moments.innovation;
        outcome.nis = nis;
        Ok(Correction {
            dx,
            p: posterior,
            outcome,
        })
    }

    /// The EKF of [`ekf::update`], unchanged (with its Joseph option), on the states that
    /// are not inert.
    fn plain_ekf(&self, p: &StateMatrix, set: &MeasurementSet) -> Result<Correction, FilterError> {
        let sub = Subspace(active_states(p));
        let result = ekf::update(
            &sub.matrix(p),
            &sub.columns(&set.h),
            &set.y,
            &set.r,
            self.joseph,
        )?;
        let m = set.y.len();
        let (_, prior_log_det_s) = normalized_squared(&set.y, &result.s);
        let outcome = UpdateOutcome {
            innovation: set.y.clone(),
            hph: symmetrize(&(&result.s - &set.r)),
            s: result.s,
            r: set.r.clone(),
            nis: result.nis,
            prior_nis: result.nis,
            prior_log_det_s,
            adaptive_factor: f64::NAN,
            mahalanobis_d2: f64::NAN,
            chi2_threshold: f64::NAN,
            robust_weights: DVector::from_element(m, f64::NAN),
        };
        Ok(Correction {
            dx: sub.full_vector(&result.dx),
            p: sub.full_matrix(&result.p),
            outcome,
        })
    }

    /// Innovation, S and P_xz of the prior covariance `p` and the noise `r`, on the states
    /// of `sub`.
    fn moments(
        &self,
        p: &DMatrix<f64>,
        set: &MeasurementSet,
        r: &DMatrix<f64>,
        sub: &Subspace,
    ) -> Result<Moments, FilterError> {
        if !self.cubature {
            let pxz = p * set.h.transpose();
            let s = symmetrize(&(&set.h * &pxz + r));
            return Ok(Moments {
                innovation: set.y.clone(),
                s,
                pxz,
            });
        }
        let m = set.y.len();
        let nominal = set.model.predict_nominal().ok_or(FilterError::NonFinite)?;
        if nominal.len() != m {
            return Err(FilterError::NonFinite);
        }
        let g = |e: &DVector<f64>| {
            let dx = sub.full_vector(e);
            match set.model.predict_corrected(&dx) {
                Some(predicted) if predicted.len() == m => &nominal - predicted,
                _ => DVector::from_element(m, f64::NAN),
            }
        };
        let prior = Gaussian {
            mean: DVector::zeros(sub.0.len()),
            covariance: p.clone(),
        };
        let u = cubature_measurement_update(&prior, &set.y, r, g)?;
        Ok(Moments {
            innovation: u.innovation,
            s: u.innovation_covariance,
            pxz: u.cross_covariance,
        })
    }
}

/// The states an update runs on, in increasing order, and the maps between them and the
/// whole error state (the others are zero).
struct Subspace(Vec<usize>);

impl Subspace {
    /// The rows and columns of `p` on the subspace.
    fn matrix(&self, p: &StateMatrix) -> DMatrix<f64> {
        let n = self.0.len();
        DMatrix::from_fn(n, n, |i, j| p[(self.0[i], self.0[j])])
    }

    /// The columns of `h` (m × N) on the subspace.
    fn columns(&self, h: &DMatrix<f64>) -> DMatrix<f64> {
        h.select_columns(&self.0)
    }

    /// A vector of the subspace in the whole state.
    fn full_vector(&self, v: &DVector<f64>) -> StateVector {
        let mut full = StateVector::zeros();
        for (k, &i) in self.0.iter().enumerate() {
            full[i] = v[k];
        }
        full
    }

    /// A matrix of the subspace in the whole state.
    fn full_matrix(&self, m: &DMatrix<f64>) -> StateMatrix {
        let mut full = StateMatrix::zeros();
        for (a, &i) in self.0.iter().enumerate() {
            for (b, &j) in self.0.iter().enumerate() {
                full[(i, j)] = m[(a, b)];
            }
        }
        full
    }
}

/// νᵀ S⁻¹ ν and ln det S of an innovation and its covariance; NaN when S has no factor
/// (they are diagnostics: the update itself reports its own failures).
fn normalized_squared(innovation: &DVector<f64>, s: &DMatrix<f64>) -> (f64, f64) {
    SpdFactor::new("innovation covariance", s).map_or((f64::NAN, f64::NAN), |factor| {
        (
            innovation.dot(&factor.solve_vector(innovation)),
            factor.log_det(),
        )
    })
}

/// The prior covariance as the cubature rule needs it: `p` itself when its Cholesky factor
/// exists, else its nearest positive-definite neighbour on the correlation scale.
///
/// Choice: the 20-state error covariance has directions that the measurements never
/// separate (the constant gyro bias and the Gauss-Markov drift, observable only as a sum;
/// the clock states in loose coupling), whose correlation eigenvalues sit near zero and
/// drift to about −1e-5 by rounding in the propagation and the updates (measured on the
/// drives of tests/iarf_engine.rs). The EKF never factors P and does not notice; the
/// cubature points need its square root. The correlation matrix C = D⁻¹PD⁻¹ is
/// eigen-decomposed and its eigenvalues raised to [`EIGEN_FLOOR`]; the variances change by
/// at most that relative amount plus the size of the negative eigenvalues. A matrix with a
/// non-positive or non-finite variance is an error.
fn covariance_for_cubature(p: &DMatrix<f64>) -> Result<DMatrix<f64>, FilterError> {
    let p = symmetrize(p);
    if p.clone().cholesky().is_some() {
        return Ok(p);
    }
    let d = p.diagonal();
    if let Some((index, &value)) = d
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(FilterError::Linalg(
            crate::linalg::LinalgError::NonPositiveVariance {
                what: "prior covariance",
                index,
                value,
            },
        ));
    }
    let scale = d.map(f64::sqrt);
    let n = p.nrows();
    let c = DMatrix::from_fn(n, n, |i, j| p[(i, j)] / (scale[i] * scale[j]));
    let eigen =
        nalgebra::SymmetricEigen::try_new(c, f64::EPSILON, 10_000).ok_or(FilterError::NonFinite)?;
    let values = eigen.eigenvalues.map(|v| v.max(EIGEN_FLOOR));
    let c = &eigen.eigenvectors * DMatrix::from_diagonal(&values) * eigen.eigenvectors.transpose();
    Ok(symmetrize(&DMatrix::from_fn(n, n, |i, j| {
        c[(i, j)] * scale[i] * scale[j]
    })))
}
