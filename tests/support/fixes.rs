//! Receiver fixes in open sky as a real receiver reports them: a slow Gauss–Markov error
//! (one minute) plus white noise, and that σ in their covariance; positions only (no
//! receiver velocity), as KF-GINS takes them.

use adaptive_gnss_ins::earth;
use adaptive_gnss_ins::engine::GnssFix;
use adaptive_gnss_ins::ins::NavState;
use nalgebra::{Matrix3, Vector3};
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// The σ of the slow and the white part of the fix error, horizontal and vertical (m).
#[derive(Debug, Clone, Copy)]
pub struct FixNoise {
    pub gm_sigma_m: [f64; 2],
    pub white_sigma_m: [f64; 2],
}

impl FixNoise {
    /// A driving car's receiver: 0.6 m horizontally and 1 m vertically, a third of the
    /// variance slow.
    pub const DRIVE: Self = Self {
        gm_sigma_m: [0.35, 0.6],
        white_sigma_m: [0.5, 0.8],
    };
    /// A parked car's receiver of issue 11: 1.5 m horizontally, most of it a slow error.
    pub const SLOW_1_5_M: Self = Self {
        gm_sigma_m: [1.4, 2.5],
        white_sigma_m: [0.55, 1.0],
    };

    /// An RTK receiver with its ambiguities fixed: 1 cm horizontally, 2 cm vertically.
    pub const RTK: Self = Self {
        gm_sigma_m: [0.005, 0.01],
        white_sigma_m: [0.01, 0.02],
    };

    fn total(&self, i: usize) -> f64 {
        self.gm_sigma_m[i].hypot(self.white_sigma_m[i])
    }
}

/// Correlation time of the slow part of the fix error (s).
const FIX_GM_TIME_S: f64 = 60.0;

/// Fixes of the antenna, one per call (1 Hz).
pub struct Fixes {
    noise: FixNoise,
    rng: ChaCha8Rng,
    /// Gauss–Markov part of the error, ENU, in units of its σ.
    gm: Vector3<f64>,
}

impl Fixes {
    pub fn new(noise: FixNoise, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let unit = Normal::new(0.0, 1.0).unwrap();
        let gm = Vector3::from_fn(|_, _| unit.sample(&mut rng));
        Self { noise, rng, gm }
    }

    /// The fix of the antenna at the true state `nav`.
    pub fn fix(&mut self, nav: &NavState) -> GnssFix {
        let unit = Normal::new(0.0, 1.0).unwrap();
        let phi = (-1.0 / FIX_GM_TIME_S).exp();
        let drive = (1.0 - phi * phi).sqrt();
        for i in 0..3 {
            self.gm[i] = phi * self.gm[i] + drive * unit.sample(&mut self.rng);
        }
        let white = Vector3::from_fn(|_, _| unit.sample(&mut self.rng));
        let axis = |i: usize| usize::from(i == 2);
        let n = self.noise;
        let error = Vector3::from_fn(|i, _| {
            n.gm_sigma_m[axis(i)] * self.gm[i] + n.white_sigma_m[axis(i)] * white[i]
        });
        let sigma = Vector3::from_fn(|i, _| n.total(axis(i)));
        GnssFix {
            t_s: nav.t_s,
            position: earth::enu_to_llh(&error, &nav.p).unwrap(),
            position_covariance_enu_m2: Some(Matrix3::from_diagonal(&sigma.map(|s| s * s))),
            velocity_enu_mps: None,
            velocity_covariance_enu_m2_s2: None,
        }
    }
}
