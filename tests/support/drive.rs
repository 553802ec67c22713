//! The simulated vehicle drive shared by the engine tests, and its GPS epochs.

use adaptive_gnss_ins::gnss::GnssEpoch;
use adaptive_gnss_ins::ins::NavState;
use adaptive_gnss_ins::sim::constellation::GpsConstellation;
use adaptive_gnss_ins::sim::{Segment, TrajectorySpec};
use rand_chacha::ChaCha8Rng;

/// The drive's receiver clock: its bias at the start (m) and its constant drift (m/s).
const CLOCK_BIAS_AT_START_M: f64 = 3_000.0;
const CLOCK_DRIFT_MPS: f64 = -25.0;

/// The GPS epoch of the drive at the true state `nav`: the noisy ranges of
/// [`super::noisy_epoch`] for a receiver with the drive's drifting clock.
pub fn drive_epoch(
    constellation: &GpsConstellation,
    rng: &mut ChaCha8Rng,
    nav: &NavState,
) -> GnssEpoch {
    let receiver = super::Receiver {
        p: &nav.p,
        v_n: nav.v_n,
        clock_bias_m: CLOCK_BIAS_AT_START_M + CLOCK_DRIFT_MPS * nav.t_s,
        clock_drift_mps: CLOCK_DRIFT_MPS,
    };
    super::noisy_epoch(constellation, rng, nav.t_s, &receiver)
}

/// A vehicle drive (accelerations, turns, a stop, a hill) after 10 s at rest, its moving
/// part repeated `laps` times.
pub fn drive(laps: usize) -> TrajectorySpec {
    use Segment::*;
    let lap = vec![
        SpeedTo {
            duration_s: 12.0,
            speed_m_s: 12.0,
        },
        Cruise { duration_s: 30.0 },
        Turn {
            duration_s: 10.0,
            yaw_change_deg: 90.0,
        },
        Cruise { duration_s: 20.0 },
        Climb {
            duration_s: 20.0,
            climb_angle_deg: 4.0,
        },
        Climb {
            duration_s: 20.0,
            climb_angle_deg: -4.0,
        },
        SpeedTo {
            duration_s: 10.0,
            speed_m_s: 18.0,
        },
        Turn {
            duration_s: 12.0,
            yaw_change_deg: -120.0,
        },
        Cruise { duration_s: 30.0 },
        SpeedTo {
            duration_s: 10.0,
            speed_m_s: 0.0,
        },
        Stationary { duration_s: 10.0 },
        SpeedTo {
            duration_s: 10.0,
            speed_m_s: 10.0,
        },
        Turn {
            duration_s: 15.0,
            yaw_change_deg: 180.0,
        },
        Cruise { duration_s: 40.0 },
        Turn {
            duration_s: 10.0,
            yaw_change_deg: 60.0,
        },
        Cruise { duration_s: 30.0 },
        SpeedTo {
            duration_s: 10.0,
            speed_m_s: 0.0,
        },
    ];
    let mut segments = vec![Stationary { duration_s: 10.0 }];
    for _ in 0..laps {
        segments.extend(lap.iter().cloned());
    }
    TrajectorySpec {
        start_t_s: 0.0,
        start_lat_deg: 39.1,
        start_lon_deg: 117.2,
        start_height_m: 20.0,
        start_yaw_deg: 30.0,
        start_speed_m_s: 0.0,
        transition_s: 2.0,
        segments,
    }
}
