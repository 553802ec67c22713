//! Sample bag content shared by the bag tests: several topics and types at known times.
#![allow(dead_code)]

use std::path::Path;

use adaptive_gnss_ins::ros::bag::{BagError, BagWriteOptions, BagWriter};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{
    DiagnosticArray, GnssMeasurements, Header, Imu, NavSatFix, NavSatStatus, NoiseEstimates,
    Odometry, Quaternion, RosMessage, SatelliteMeasurement, SatelliteNoise, Time,
    TwistWithCovarianceStamped, Vector3,
};
use adaptive_gnss_ins::tools::simulate;

/// Log time of the first message: 2023-11-14T22:13:20Z, in ns.
pub const START_NS: u64 = 1_700_000_000_000_000_000;
/// Spacing of the IMU samples (ns): 100 Hz.
pub const IMU_PERIOD_NS: u64 = 10_000_000;

/// One message as written: what a reader must give back.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    pub topic: String,
    pub type_name: String,
    pub log_time_ns: u64,
    pub data: Vec<u8>,
}

/// The ROS stamp of `t_ns`.
pub fn stamp(t_ns: u64) -> Time {
    Time {
        sec: (t_ns / 1_000_000_000) as i32,
        nanosec: (t_ns % 1_000_000_000) as u32,
    }
}

/// Header stamped `t_ns` in `frame_id`.
pub fn header(t_ns: u64, frame_id: &str) -> Header {
    Header {
        stamp: stamp(t_ns),
        frame_id: frame_id.to_string(),
    }
}

/// IMU sample number `k`.
pub fn imu(k: u64, t_ns: u64) -> Imu {
    let x = k as f64;
    Imu {
        header: header(t_ns, "imu_link"),
        orientation: Quaternion {
            x: 0.0,
            y: 0.0,
            z: (0.001 * x).sin(),
            w: (0.001 * x).cos(),
        },
        orientation_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        angular_velocity: Vector3 {
            x: 1e-4 * x,
            y: -2e-4,
            z: 7.292115e-5,
        },
        angular_velocity_covariance: [1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 1e-6],
        linear_acceleration: Vector3 {
            x: 0.01 * x,
            y: -0.02,
            z: 9.80665,
        },
        linear_acceleration_covariance: [1e-4, 0.0, 0.0, 0.0, 1e-4, 0.0, 0.0, 0.0, 1e-4],
    }
}

/// GNSS epoch number `k` with four satellites.
pub fn gnss(k: u64, t_ns: u64) -> GnssMeasurements {
    let satellites = (0..4_u16)
        .map(|i| SatelliteMeasurement {
            constellation: SatelliteMeasurement::GPS,
            prn: 3 + 5 * i,
            pseudorange_m: 2.1e7 + 1000.0 * f64::from(i) + k as f64,
            pseudorange_rate_mps: -120.5 + f64::from(i),
            pseudorange_sigma_m: 3.0,
            pseudorange_rate_sigma_mps: 0.1,
            cn0_dbhz: 42.5,
            satellite_position_ecef_m: adaptive_gnss_ins::ros::msg::Point {
                x: 1.5e7,
                y: -1.0e7 + 1e6 * f64::from(i),
                z: 2.0e7,
            },
            satellite_velocity_ecef_mps: Vector3 {
                x: 100.0,
                y: 2500.0,
                z: -300.0,
            },
            satellite_clock_bias_s: 1.25e-5,
            satellite_clock_drift_s_s: 1e-12,
            ionosphere_delay_m: 2.5,
            troposphere_delay_m: 2.3,
            carrier_phase_cycles: 1.1e8 + 5250.0 * k as f64,
            carrier_wavelength_m: 0.190_293_672_798,
            carrier_phase_sigma_cycles: 0.008,
            carrier_lock_time_s: k as f64,
            carrier_phase_flags: 0,
        })
        .collect();
    GnssMeasurements {
        header: header(t_ns, "gnss_antenna"),
        gps_week: 2288,
        gps_time_of_week_s: 252_000.0 + k as f64,
        satellites,
        klobuchar_alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -5.9605e-8],
        klobuchar_beta: [90112.0, 0.0, -196_608.0, -65536.0],
    }
}

/// Fix number `k`.
pub fn fix(k: u64, t_ns: u64) -> NavSatFix {
    NavSatFix {
        header: header(t_ns, "gnss_antenna"),
        status: NavSatStatus {
            status: NavSatStatus::STATUS_FIX,
            service: NavSatStatus::SERVICE_GPS,
        },
        latitude: 40.05 + 1e-6 * k as f64,
        longitude: -105.2,
        altitude: 1600.0,
        position_covariance: [4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 9.0],
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_DIAGONAL_KNOWN,
    }
}

/// Odometry number `k`.
pub fn odometry(k: u64, t_ns: u64) -> Odometry {
    let mut odometry = Odometry {
        header: header(t_ns, "map"),
        child_frame_id: "base_link".to_string(),
        ..Odometry::default()
    };
    odometry.pose.pose.position.x = 0.5 * k as f64;
    odometry.pose.covariance[0] = 0.25;
    odometry.twist.twist.linear.x = 5.0;
    odometry.twist.covariance[35] = 0.01;
    odometry
}

/// Noise estimates of GNSS epoch `k`.
pub fn noise(k: u64, t_ns: u64) -> NoiseEstimates {
    NoiseEstimates {
        header: header(t_ns, "gnss_antenna"),
        filter_variant: "ermakf".to_string(),
        satellites: vec![SatelliteNoise {
            constellation: SatelliteMeasurement::GPS,
            prn: 3,
            elevation_deg: 35.0,
            used: true,
            rejection_reason: SatelliteNoise::REJECTION_NONE,
            innovation_pseudorange_m: 0.5,
            innovation_pseudorange_rate_mps: -0.01,
            normalized_innovation_pseudorange: 0.2,
            normalized_innovation_pseudorange_rate: -0.1,
            r_pseudorange_m2: 9.0,
            r_pseudorange_rate_m2_s2: 0.01,
            kde_credibility: 0.3,
            gaussian: true,
            ar_order: 2,
            robust_weight: 1.0,
        }],
        adaptive_factor: 1.0,
        mahalanobis_d2: 3.5 + k as f64,
        chi2_threshold: 9.49,
        q_scale: 1.0,
        nis: 2.0,
    }
}

/// Collects what is written, for comparison with what is read.
pub struct Recorder {
    pub writer: BagWriter,
    pub written: Vec<Written>,
}

impl Recorder {
    pub fn create(path: &Path, options: BagWriteOptions) -> Self {
        Self {
            writer: BagWriter::create_with_options(path, options).unwrap(),
            written: Vec::new(),
        }
    }

    pub fn write<T: RosMessage>(&mut self, topic: &str, message: &T, t_ns: u64) {
        self.writer.write(topic, message, t_ns).unwrap();
        self.written.push(Written {
            topic: topic.to_string(),
            type_name: T::TYPE_NAME.to_string(),
            log_time_ns: t_ns,
            data: cdr::encode(message).unwrap(),
        });
    }

    pub fn finish(self) -> Result<Vec<Written>, BagError> {
        self.writer.finish()?;
        Ok(self.written)
    }
}

/// Topics of the sample bag, in the order they are added.
pub const TOPICS: [(&str, &str); 5] = [
    ("/imu/data", "sensor_msgs/msg/Imu"),
    (
        "/gnss/measurements",
        "adaptive_gnss_ins/msg/GnssMeasurements",
    ),
    ("/gnss/fix", "sensor_msgs/msg/NavSatFix"),
    ("/odometry/filtered", "nav_msgs/msg/Odometry"),
    ("/diagnostics/noise", "adaptive_gnss_ins/msg/NoiseEstimates"),
];

/// Writes `seconds` s of sample data in time order: IMU at 100 Hz, GNSS, fix and noise
/// estimates at 1 Hz, odometry at 10 Hz (several topics share time stamps).
pub fn write_sample_bag(path: &Path, options: BagWriteOptions, seconds: u64) -> Vec<Written> {
    let mut recorder = Recorder::create(path, options);
    recorder.writer.add_topic::<Imu>(TOPICS[0].0).unwrap();
    recorder
        .writer
        .add_topic::<GnssMeasurements>(TOPICS[1].0)
        .unwrap();
    recorder.writer.add_topic::<NavSatFix>(TOPICS[2].0).unwrap();
    recorder.writer.add_topic::<Odometry>(TOPICS[3].0).unwrap();
    recorder
        .writer
        .add_topic::<NoiseEstimates>(TOPICS[4].0)
        .unwrap();
    for k in 0..seconds * 100 {
        let t_ns = START_NS + k * IMU_PERIOD_NS;
        recorder.write(TOPICS[0].0, &imu(k, t_ns), t_ns);
        if k % 100 == 0 {
            let epoch = k / 100;
            recorder.write(TOPICS[1].0, &gnss(epoch, t_ns), t_ns);
            recorder.write(TOPICS[2].0, &fix(epoch, t_ns), t_ns);
            recorder.write(TOPICS[4].0, &noise(epoch, t_ns), t_ns);
        }
        if k % 10 == 5 {
            recorder.write(TOPICS[3].0, &odometry(k / 10, t_ns), t_ns);
        }
    }
    recorder.finish().unwrap()
}

/// Adds the topics `gnss_ins simulate` writes (with `--velocity`) to `writer`, for a copy
/// of a simulated bag.
pub fn add_simulated_topics(writer: &mut BagWriter) {
    writer.add_topic::<Imu>(simulate::IMU_TOPIC).unwrap();
    writer
        .add_topic::<GnssMeasurements>(simulate::GNSS_TOPIC)
        .unwrap();
    writer.add_topic::<NavSatFix>(simulate::FIX_TOPIC).unwrap();
    writer
        .add_topic::<TwistWithCovarianceStamped>(simulate::VELOCITY_TOPIC)
        .unwrap();
    writer.add_topic::<Odometry>(simulate::TRUTH_TOPIC).unwrap();
    writer
        .add_topic::<NavSatFix>(simulate::TRUTH_DATUM_TOPIC)
        .unwrap();
    writer
        .add_topic::<NoiseEstimates>(simulate::TRUTH_NOISE_TOPIC)
        .unwrap();
    writer
        .add_topic::<DiagnosticArray>(simulate::TRUTH_ENVIRONMENT_TOPIC)
        .unwrap();
}
