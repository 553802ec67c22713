//! A minimal scenario for engine tests: a receiver at rest with a perfect IMU and
//! simulated GPS pseudo-ranges with white noise of the filter's own σ model.
#![allow(dead_code)]

pub mod drive;
pub mod fixes;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::earth::{self, Llh};
use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::sim::constellation::{
    AtmosphereTruth, GpsConstellation, ObservationNoise, ReceiverTruth,
};
use nalgebra::{UnitQuaternion, Vector3};
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// A receiver at rest with a perfect IMU (levelled, heading `yaw_rad` in ENU).
pub struct StaticScenario {
    pub position: Llh,
    pub q_nb: UnitQuaternion<f64>,
    pub imu_rate_hz: f64,
    pub clock_bias_m: f64,
    pub clock_drift_mps: f64,
    pub constellation: GpsConstellation,
    rng: ChaCha8Rng,
}

impl StaticScenario {
    pub fn new(seed: u64) -> Self {
        Self {
            position: Llh::from_degrees(40.05, -105.2, 1600.0),
            q_nb: UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7),
            imu_rate_hz: 100.0,
            clock_bias_m: 12_345.0,
            clock_drift_mps: 40.0,
            constellation: GpsConstellation::augmented(1),
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// The perfect IMU at rest at time `t_s`: f^b = C_n^b (0, 0, γ), ω^b = C_n^b ω_ie^n.
    pub fn imu(&self, t_s: f64) -> ImuSample {
        let c_nb = self.q_nb.inverse();
        let gamma = earth::normal_gravity_m_s2(self.position.lat_rad, self.position.height_m);
        ImuSample {
            t_s,
            w_ib_b_rad_s: c_nb * earth::earth_rate_enu_rad_s(self.position.lat_rad),
            f_ib_b_m_s2: c_nb * Vector3::new(0.0, 0.0, gamma),
        }
    }

    /// A GNSS epoch at `t_s` with noise of the default σ model (3 m, 0.1 m/s at zenith).
    pub fn gnss(&mut self, t_s: f64) -> GnssEpoch {
        let clock_bias_m = self.clock_bias_m + self.clock_drift_mps * t_s;
        let receiver = Receiver {
            p: &self.position,
            v_n: Vector3::zeros(),
            clock_bias_m,
            clock_drift_mps: self.clock_drift_mps,
        };
        noisy_epoch(&self.constellation, &mut self.rng, t_s, &receiver)
    }
}

/// The true receiver state behind a simulated epoch.
pub struct Receiver<'a> {
    pub p: &'a Llh,
    /// ENU velocity (m/s).
    pub v_n: Vector3<f64>,
    pub clock_bias_m: f64,
    pub clock_drift_mps: f64,
}

/// A GPS epoch at `t_s` above a 10° mask with white noise of the filter's default σ model
/// (3 m and 0.1 m/s at the zenith, divided by the sine of the elevation). No atmosphere,
/// and the observations say so (delays present and zero), so the filter applies none.
pub fn noisy_epoch(
    constellation: &GpsConstellation,
    rng: &mut ChaCha8Rng,
    t_s: f64,
    receiver: &Receiver,
) -> GnssEpoch {
    let truth = ReceiverTruth {
        pos_ecef_m: earth::llh_to_ecef(receiver.p),
        vel_ecef_mps: earth::rot_ecef_to_enu(receiver.p).transpose() * receiver.v_n,
        clock_bias_m: receiver.clock_bias_m,
        clock_drift_mps: receiver.clock_drift_mps,
    };
    let unit = Normal::new(0.0, 1.0).unwrap();
    let atmosphere = AtmosphereTruth {
        report_delays: true,
        ..AtmosphereTruth::vacuum()
    };
    let mut epoch = constellation
        .simulate_epoch(t_s, &truth, &atmosphere, 10f64.to_radians(), |_| {
            ObservationNoise::default()
        })
        .unwrap();
    for sat in &mut epoch.satellites {
        let up = earth::rot_ecef_to_enu(receiver.p)
            * (sat.sat_pos_ecef_m - truth.pos_ecef_m).normalize();
        let scale = 1.0 / up[2].asin().max(10f64.to_radians()).sin();
        if let Some(p) = sat.pseudorange_m.as_mut() {
            *p += 3.0 * scale * unit.sample(rng);
        }
        if let Some(r) = sat.pseudorange_rate_mps.as_mut() {
            *r += 0.1 * scale * unit.sample(rng);
        }
    }
    epoch
}

/// The default configuration with the heading given (a static receiver cannot find it)
/// for the ENU yaw `yaw_rad`.
pub fn static_config(yaw_rad: f64) -> Config {
    let mut config = Config::default();
    config.init.heading_rad = Some(std::f64::consts::FRAC_PI_2 - yaw_rad);
    config
}
