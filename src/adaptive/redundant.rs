//! Redundant-measurement noise estimator of the ERMAKF paper (section 3), for one scalar
//! observable of one satellite (e.g. the pseudo-range of G05).
//!
//! It is fed the second-order mutual difference ∇Z(k) = ΔZ_GNSS(k) − ΔZ_INS(k) (eq. 14),
//! one value per epoch, and returns the GNSS measurement noise variance R:
//! - Gaussian regime: R̂ = E[∇Z²]/2 (eqs. 17–18), the expectation a window mean over the
//!   last M samples, or its random-weighted form (eq. 19) when enabled;
//! - non-Gaussian regime (entered by the KDE credibility test of section 3.2): the window's
//!   variance corrected by a Burg AR model whose order Akaike's criterion (or, as an
//!   option, Schwarz's) picks (eqs. 25–29), halved: R̂ = σ²_∇Z/2.
//!
//! Math note (the factor 1/2, eq. 17): for white GNSS noise V of variance R and negligible
//! INS noise, ∇Z(k) ≈ V(k) − V(k−1) has variance 2R. The same reasoning is applied to the
//! eq. (29) variance in the non-Gaussian regime. Note that ∇Z is then an MA(1) sequence
//! with lag-1 correlation −1/2, so the eq. (29) factor is above 1 even for white V (it tends
//! to 2 as the AR order grows); for positively correlated V (multipath) the differencing
//! shrinks ∇Z by 1 − ρ_V(1), which eq. (29) on ∇Z only partly restores. Both are properties
//! of the published method, kept as published.
//!
//! The caller must remove the receiver clock change from ∇Z first (see DESIGN.md,
//! "Pitfalls"): it is common to all satellites and is not noise.
//!
//! Beyond the paper, an option ([`RedundantNoiseOptions::correlation_aware`]): the window's
//! differences over several lags identify the variance and the correlation of the error
//! together ([`super::variogram`]), and R̂ is the whole variance, slow part included, in
//! both regimes (the KDE verdict is still given). Off, the estimator is the paper's.

use std::collections::VecDeque;

use super::ar_variance::{ar_corrected_variance, mean_square};
use super::burg::{select_order, OrderCriterion};
use super::error::{check_finite, AdaptiveError};
use super::kde::{credibility_presorted, Credibility};
use super::random_weighting::DirichletWeights;
use super::variogram::fit_variogram;

/// Options of one [`RedundantNoiseEstimator`]; all counts are in epochs (samples).
#[derive(Debug, Clone, PartialEq)]
pub struct RedundantNoiseOptions {
    /// Window length M of eqs. (18)–(20), (29). Default 100.
    pub window_size_m: usize,
    /// Earlier samples needed in the window before any estimate or KDE verdict is given
    /// (a KDE or AR fit on a handful of samples is noise). Default 30; must be at least
    /// `ar_max_order + 2` and at most `window_size_m`.
    pub min_samples: usize,
    /// Use the random-weighted second moment of eq. (19) instead of the plain mean (18) in
    /// the Gaussian regime. Default false.
    pub random_weighting: bool,
    /// Credibility threshold in standard deviations: a new sample is credible when the
    /// window's kernel density there exceeds φ(`kde_threshold`)/σ (see
    /// [`super::kde::credibility`]). Default 3.
    pub kde_threshold: f64,
    /// Consecutive non-credible samples that switch to the non-Gaussian regime, and
    /// consecutive credible samples that switch back. Default 3.
    pub kde_consecutive_epochs: usize,
    /// Highest AR order tried in the non-Gaussian regime. Default 5.
    pub ar_max_order: usize,
    /// Criterion choosing the AR order. Default Akaike's, as in the paper.
    pub ar_order_criterion: OrderCriterion,
    /// Floor of the eq. (29) denominator 1 − Σ a_i β_i, in (0, 1]: caps the AR inflation of
    /// the variance at 1/floor. Default 0.1 (at most ten times the window mean square).
    pub ar_denominator_floor: f64,
    /// Seed of the random-weighting generator (replays are bit-identical). Default 0.
    pub seed: u64,
    /// Run the KDE test and switch to the AR-corrected variance in the non-Gaussian regime
    /// (the enhanced filter). Off, the estimator is the simple RMAE of eqs. (17)–(18) or
    /// (19) (the paper's SRMAKF). Default true.
    pub detect_non_gaussian: bool,
    /// Estimate R as the sill of the white + AR(1) variogram fitted to the window's
    /// differences over lags 1 … `variogram_max_lag` ([`super::variogram`]) instead of the
    /// paper's methods. Default false.
    pub correlation_aware: bool,
    /// Longest lag of the variogram (epochs), at least 1; a third of the window at most is
    /// used. Default 20.
    pub variogram_max_lag: usize,
}

impl Default for RedundantNoiseOptions {
    fn default() -> Self {
        Self {
            window_size_m: 100,
            min_samples: 30,
            random_weighting: false,
            kde_threshold: 3.0,
            kde_consecutive_epochs: 3,
            ar_max_order: 5,
            ar_order_criterion: OrderCriterion::Aic,
            ar_denominator_floor: 0.1,
            seed: 0,
            detect_non_gaussian: true,
            correlation_aware: false,
            variogram_max_lag: 20,
        }
    }
}

impl RedundantNoiseOptions {
    /// Checks the ranges documented on each field.
    pub fn validate(&self) -> Result<(), AdaptiveError> {
        let invalid = |name, value: usize, reason| {
            Err(AdaptiveError::InvalidParameter {
                name,
                value: value as f64,
                reason,
            })
        };
        if self.min_samples < self.ar_max_order + 2 {
            return invalid(
                "min_samples",
                self.min_samples,
                "must be at least ar_max_order + 2",
            );
        }
        if self.window_size_m < self.min_samples {
            return invalid(
                "window_size_m",
                self.window_size_m,
                "must be at least min_samples",
            );
        }
        if self.kde_consecutive_epochs == 0 {
            return invalid("kde_consecutive_epochs", 0, "must be at least 1");
        }
        if self.variogram_max_lag == 0 {
            return invalid("variogram_max_lag", 0, "must be at least 1");
        }
        if !(self.kde_threshold > 0.0 && self.kde_threshold.is_finite()) {
            return Err(AdaptiveError::InvalidParameter {
                name: "kde_threshold",
                value: self.kde_threshold,
                reason: "must be positive and finite",
            });
        }
        if !(self.ar_denominator_floor > 0.0 && self.ar_denominator_floor <= 1.0) {
            return Err(AdaptiveError::InvalidParameter {
                name: "ar_denominator_floor",
                value: self.ar_denominator_floor,
                reason: "must lie in (0, 1]",
            });
        }
        Ok(())
    }
}

/// The noise regime decided by the KDE credibility test.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseRegime {
    /// Samples keep falling inside the window's density: plain (or random-weighted) RMAE.
    Gaussian,
    /// Repeated non-credible samples: AR-corrected variance (Burg + AIC, eq. 29).
    NonGaussian,
}

/// How the variance of a [`RedundantNoiseEstimate`] was computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VarianceMethod {
    /// Window mean square halved, eqs. (17)–(18).
    Rmae,
    /// Random-weighted second moment halved, eqs. (17), (19).
    RandomWeightedRmae,
    /// Eq. (29) variance halved, with the AR order chosen by the configured criterion.
    BurgAr {
        /// AR order p chosen by the criterion (0 means no correlation found).
        order: usize,
        /// 1 − Σ a_i β_i as computed.
        raw_denominator: f64,
        /// The denominator used, clamped into [`RedundantNoiseOptions::ar_denominator_floor`, 1].
        applied_denominator: f64,
    },
    /// Non-Gaussian regime, but no AR model could be fitted because a lower order predicts
    /// the window exactly (zero prediction error, e.g. a frozen measurement): plain RMAE.
    RmaeFallback,
    /// The sill of the white + AR(1) variogram (the correlation-aware option).
    Variogram {
        /// ρ₁ of the fitted error model.
        lag1_correlation: f64,
        /// Longest lag fitted (epochs).
        lags: usize,
    },
}

/// The estimate after one sample, once the window holds enough data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RedundantNoiseEstimate {
    /// Samples in the window the variance was computed from (the newest included).
    pub n_samples: usize,
    /// Estimated GNSS measurement noise variance R (unit of ∇Z, squared).
    pub r_variance: f64,
    /// How `r_variance` was obtained.
    pub method: VarianceMethod,
    /// Regime after this sample.
    pub regime: NoiseRegime,
    /// KDE credibility of this sample against the earlier window; `None` only when the
    /// window has no spread (all samples equal), in which case the regime is left as it was.
    pub credibility: Option<Credibility>,
}

/// Outcome of [`RedundantNoiseEstimator::push`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RedundantEstimate {
    /// Fewer than `min_samples` earlier samples: no estimate, no KDE verdict.
    NotEnoughData {
        /// Samples in the window now (the newest included).
        n_samples: usize,
        /// Earlier samples needed before the first estimate.
        min_samples: usize,
    },
    /// An estimate to use.
    Ready(RedundantNoiseEstimate),
}

/// Windowed RMAE / ERMAKF estimator of one scalar observable (one satellite, one
/// observable).
#[derive(Debug, Clone)]
pub struct RedundantNoiseEstimator {
    options: RedundantNoiseOptions,
    window: VecDeque<f64>,
    /// The window's values in ascending order ([`f64::total_cmp`]), kept as samples come
    /// and go so that the KDE's quartiles need no sort per sample.
    sorted: Vec<f64>,
    weights: DirichletWeights,
    regime: NoiseRegime,
    /// Consecutive samples that argue for leaving the current regime.
    streak: usize,
}

impl RedundantNoiseEstimator {
    /// A new estimator with an empty window, in the Gaussian regime.
    pub fn new(options: RedundantNoiseOptions) -> Result<Self, AdaptiveError> {
        options.validate()?;
        Ok(Self {
            window: VecDeque::with_capacity(options.window_size_m),
            sorted: Vec::with_capacity(options.window_size_m),
            weights: DirichletWeights::new(options.seed),
            regime: NoiseRegime::Gaussian,
            streak: 0,
            options,
        })
    }

    /// The options in force.
    pub fn options(&self) -> &RedundantNoiseOptions {
        &self.options
    }

    /// Samples in the window.
    pub fn n_samples(&self) -> usize {
        self.window.len()
    }

    /// Current regime.
    pub fn regime(&self) -> NoiseRegime {
        self.regime
    }

    /// Back to the state right after [`Self::new`], the random-weighting generator re-seeded.
    pub fn reset(&mut self) {
        self.window.clear();
        self.sorted.clear();
        self.weights = DirichletWeights::new(self.options.seed);
        self.regime = NoiseRegime::Gaussian;
        self.streak = 0;
    }

    /// Marks an interruption of the ∇Z sequence (a missed epoch, loss of lock, a cycle
    /// of the satellite out of view).
    ///
    /// Choice: the window is emptied and the regime returns to Gaussian, because the AR
    /// model (lags) and the KDE window assume one contiguous, stationary stretch of data;
    /// estimates resume after `min_samples` new samples. The random-weighting stream goes
    /// on (no re-seed), so replays stay deterministic. The caller must also not form
    /// ∇Z across the gap: it needs two consecutive epochs of both GNSS and INS.
    pub fn push_gap(&mut self) {
        self.window.clear();
        self.sorted.clear();
        self.regime = NoiseRegime::Gaussian;
        self.streak = 0;
    }

    /// Adds the newest mutual difference ∇Z (eq. 14) and returns the estimate.
    ///
    /// Order of work: (1) judge the new sample's credibility against the earlier window
    /// (it is excluded, as in section 3.2); (2) update the regime; (3) append the sample,
    /// dropping the oldest beyond M; (4) estimate R on the window with the regime's method.
    ///
    /// Errors: a non-finite `nabla_z` (the estimator is left unchanged). The AR-fit
    /// failures are handled inside (see [`VarianceMethod::RmaeFallback`]).
    pub fn push(&mut self, nabla_z: f64) -> Result<RedundantEstimate, AdaptiveError> {
        check_finite("redundant noise estimator input", &[nabla_z])?;
        let ready = self.window.len() >= self.options.min_samples;
        let verdict = if ready && self.options.detect_non_gaussian {
            self.judge(nabla_z)?
        } else {
            None
        };

        if self.window.len() == self.options.window_size_m {
            if let Some(oldest) = self.window.pop_front() {
                if let Ok(at) = self.sorted.binary_search_by(|v| v.total_cmp(&oldest)) {
                    self.sorted.remove(at);
                }
            }
        }
        self.window.push_back(nabla_z);
        let at = self
            .sorted
            .partition_point(|v| v.total_cmp(&nabla_z).is_lt());
        self.sorted.insert(at, nabla_z);

        if !ready {
            return Ok(RedundantEstimate::NotEnoughData {
                n_samples: self.window.len(),
                min_samples: self.options.min_samples,
            });
        }
        let (r_variance, method) = self.estimate_variance()?;
        Ok(RedundantEstimate::Ready(RedundantNoiseEstimate {
            n_samples: self.window.len(),
            r_variance,
            method,
            regime: self.regime,
            credibility: verdict,
        }))
    }

    /// KDE verdict on `z` against the current window, and the regime update it implies.
    ///
    /// Choice (state machine): Gaussian → non-Gaussian after `kde_consecutive_epochs`
    /// consecutive non-credible samples; non-Gaussian → Gaussian after the same number of
    /// consecutive credible ones. A sample that agrees with the current regime resets the
    /// streak. A window without spread gives no verdict and leaves the streak unchanged.
    fn judge(&mut self, z: f64) -> Result<Option<Credibility>, AdaptiveError> {
        let window = self.window.make_contiguous();
        let verdict =
            match credibility_presorted(window, &self.sorted, z, self.options.kde_threshold) {
                Ok(c) => c,
                Err(AdaptiveError::ZeroVariance { .. }) => return Ok(None),
                Err(e) => return Err(e),
            };
        let argues_for_switch = match self.regime {
            NoiseRegime::Gaussian => !verdict.credible,
            NoiseRegime::NonGaussian => verdict.credible,
        };
        if argues_for_switch {
            self.streak += 1;
            if self.streak >= self.options.kde_consecutive_epochs {
                self.regime = match self.regime {
                    NoiseRegime::Gaussian => NoiseRegime::NonGaussian,
                    NoiseRegime::NonGaussian => NoiseRegime::Gaussian,
                };
                self.streak = 0;
            }
        } else {
            self.streak = 0;
        }
        Ok(Some(verdict))
    }

    /// R̂ on the current window with the current regime's method.
    fn estimate_variance(&mut self) -> Result<(f64, VarianceMethod), AdaptiveError> {
        let window = self.window.make_contiguous();
        if self.options.correlation_aware {
            let fit = fit_variogram(window, self.options.variogram_max_lag)?;
            return Ok((
                fit.variance(),
                VarianceMethod::Variogram {
                    lag1_correlation: fit.lag1_correlation(),
                    lags: fit.lags,
                },
            ));
        }
        match self.regime {
            NoiseRegime::Gaussian if self.options.random_weighting => {
                let moment = self.weights.second_moment(window)?;
                Ok((moment / 2.0, VarianceMethod::RandomWeightedRmae))
            }
            NoiseRegime::Gaussian => Ok((mean_square(window)? / 2.0, VarianceMethod::Rmae)),
            NoiseRegime::NonGaussian => match select_order(
                window,
                self.options.ar_max_order,
                self.options.ar_order_criterion,
            ) {
                Ok(model) => {
                    let corrected = ar_corrected_variance(
                        window,
                        &model.coefficients,
                        self.options.ar_denominator_floor,
                    )?;
                    Ok((
                        corrected.variance / 2.0,
                        VarianceMethod::BurgAr {
                            order: model.order(),
                            raw_denominator: corrected.raw_denominator,
                            applied_denominator: corrected.applied_denominator,
                        },
                    ))
                }
                Err(AdaptiveError::ZeroVariance { .. }) => {
                    Ok((mean_square(window)? / 2.0, VarianceMethod::RmaeFallback))
                }
                Err(e) => Err(e),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_options() -> RedundantNoiseOptions {
        RedundantNoiseOptions {
            window_size_m: 10,
            min_samples: 5,
            ar_max_order: 2,
            ..RedundantNoiseOptions::default()
        }
    }

    #[test]
    fn not_enough_data_until_min_samples_earlier_samples() {
        let mut est = RedundantNoiseEstimator::new(small_options()).unwrap();
        for i in 0..5 {
            let out = est.push(if i % 2 == 0 { 1.0 } else { -1.0 }).unwrap();
            assert_eq!(
                out,
                RedundantEstimate::NotEnoughData {
                    n_samples: i + 1,
                    min_samples: 5
                }
            );
        }
        match est.push(1.0).unwrap() {
            RedundantEstimate::Ready(e) => {
                assert_eq!(e.n_samples, 6);
                assert_eq!(e.method, VarianceMethod::Rmae);
                assert!((e.r_variance - 0.5).abs() < 1e-15);
            }
            other => panic!("expected an estimate, got {other:?}"),
        }
    }

    #[test]
    fn sorted_copy_follows_the_window() {
        let mut est = RedundantNoiseEstimator::new(small_options()).unwrap();
        for i in 0..60 {
            // Repeated values, and both signed zeros, exercise removal of equal values.
            let z = match i % 7 {
                0 => 0.0,
                1 => -0.0,
                _ => ((i * 37) % 13) as f64 - 6.0,
            };
            est.push(z).unwrap();
            let mut expected: Vec<f64> = est.window.iter().copied().collect();
            expected.sort_by(f64::total_cmp);
            assert_eq!(
                est.sorted.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                expected.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
            if i == 30 {
                est.push_gap();
                assert!(est.sorted.is_empty());
            }
        }
    }

    #[test]
    fn window_is_bounded_and_gap_or_reset_empty_it() {
        let mut est = RedundantNoiseEstimator::new(small_options()).unwrap();
        for i in 0..25 {
            est.push((i as f64).sin()).unwrap();
        }
        assert_eq!(est.n_samples(), 10);
        est.push_gap();
        assert_eq!(est.n_samples(), 0);
        est.push(1.0).unwrap();
        est.reset();
        assert_eq!(est.n_samples(), 0);
        assert_eq!(est.regime(), NoiseRegime::Gaussian);
    }

    #[test]
    fn non_finite_input_is_rejected_and_changes_nothing() {
        let mut est = RedundantNoiseEstimator::new(small_options()).unwrap();
        est.push(1.0).unwrap();
        assert!(matches!(
            est.push(f64::INFINITY),
            Err(AdaptiveError::NonFinite { .. })
        ));
        assert_eq!(est.n_samples(), 1);
    }

    #[test]
    fn invalid_options_are_rejected() {
        let mut o = small_options();
        o.min_samples = 3; // < ar_max_order + 2 = 4
        assert!(RedundantNoiseEstimator::new(o).is_err());
        let mut o = small_options();
        o.window_size_m = 4;
        assert!(RedundantNoiseEstimator::new(o).is_err());
        let mut o = small_options();
        o.kde_consecutive_epochs = 0;
        assert!(RedundantNoiseEstimator::new(o).is_err());
        let mut o = small_options();
        o.variogram_max_lag = 0;
        assert!(RedundantNoiseEstimator::new(o).is_err());
    }

    #[test]
    fn correlation_aware_option_sees_the_slow_part_the_papers_estimate_misses() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        // Differences of an AR(1) error with σ = 2 and ρ₁ = 0.9 (variance 4). A window of
        // 100 epochs of an error correlated over ten holds few independent samples, so
        // single estimates scatter: the median over 20 000 epochs (200 windows) is compared.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let (phi, sigma) = (0.9, 2.0);
        let mut v = sigma * normal();
        let differences: Vec<f64> = (0..20_000)
            .map(|_| {
                let next = phi * v + sigma * (1.0f64 - phi * phi).sqrt() * normal();
                let d = next - v;
                v = next;
                d
            })
            .collect();
        let run = |options: RedundantNoiseOptions| {
            let mut est = RedundantNoiseEstimator::new(options).unwrap();
            let mut estimates = Vec::new();
            for &d in &differences {
                if let RedundantEstimate::Ready(e) = est.push(d).unwrap() {
                    estimates.push(e);
                }
            }
            let last = estimates[estimates.len() - 1];
            let mut r: Vec<f64> = estimates.into_iter().map(|e| e.r_variance).collect();
            r.sort_by(f64::total_cmp);
            (r[r.len() / 2], last)
        };
        let (paper, _) = run(RedundantNoiseOptions {
            detect_non_gaussian: false,
            ..RedundantNoiseOptions::default()
        });
        let (aware_median, aware) = run(RedundantNoiseOptions {
            correlation_aware: true,
            ..RedundantNoiseOptions::default()
        });
        assert!(paper < 0.25 * 4.0, "{paper}");
        assert!((aware_median / 4.0 - 1.0).abs() < 0.2, "{aware_median}");
        match aware.method {
            VarianceMethod::Variogram {
                lag1_correlation,
                lags,
            } => {
                assert_eq!(lags, 20);
                assert!(lag1_correlation > 0.7, "{lag1_correlation}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn random_weighting_replays_identically() {
        let opts = RedundantNoiseOptions {
            random_weighting: true,
            seed: 42,
            ..small_options()
        };
        let run = |opts: RedundantNoiseOptions| {
            let mut est = RedundantNoiseEstimator::new(opts).unwrap();
            (0..30)
                .map(|i| match est.push(((i * 7) % 11) as f64 - 5.0).unwrap() {
                    RedundantEstimate::Ready(e) => e.r_variance,
                    RedundantEstimate::NotEnoughData { .. } => -1.0,
                })
                .collect::<Vec<f64>>()
        };
        let a = run(opts.clone());
        assert_eq!(a, run(opts.clone()));
        assert!(a.iter().any(|r| *r > 0.0));
        let b = run(RedundantNoiseOptions { seed: 43, ..opts });
        assert_ne!(a, b);
    }
}
