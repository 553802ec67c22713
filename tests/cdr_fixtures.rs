//! Byte identity of our CDR encoding with an independent ROS 2 serializer.
//!
//! `tests/data/cdr/*.cdr` were written by `tools/make_cdr_fixtures.py` with the Python
//! library `rosbags` (version pinned in `tools/requirements-test-peers.txt`). Each test
//! builds the same value in Rust and checks that (a) `encode` reproduces the fixture
//! byte for byte and (b) `decode` of the fixture gives the value back (NaN-aware, via
//! `Debug`, which prints every f64 exactly and NaN as "NaN", and via re-encoding, which
//! compares the bits). The values MUST stay in step with the script.

use std::fmt::Debug;
use std::path::PathBuf;

use adaptive_gnss_ins::gnss::{Constellation, GnssEpoch};
use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::ros::cdr::{decode, encode, CdrError};
use adaptive_gnss_ins::ros::msg::*;
use serde::{de::DeserializeOwned, Serialize};

const NAN: f64 = f64::NAN;

fn fixture(name: &str) -> Vec<u8> {
    let path: PathBuf = [env!("CARGO_MANIFEST_DIR"), "tests", "data", "cdr", name]
        .iter()
        .collect();
    std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// `start, start + step, ...` computed as the Python script does.
fn seq<const N: usize>(start: f64, step: f64) -> [f64; N] {
    std::array::from_fn(|i| start + i as f64 * step)
}

fn header(sec: i32, nanosec: u32, frame_id: &str) -> Header {
    Header {
        stamp: Time { sec, nanosec },
        frame_id: frame_id.to_string(),
    }
}

fn vector3(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

fn quaternion(x: f64, y: f64, z: f64, w: f64) -> Quaternion {
    Quaternion { x, y, z, w }
}

/// Encode == fixture, decode(fixture) == value (NaN-aware), for `name.cdr`; also checks
/// the big-endian fixture `name_be.cdr` when `big_endian_too`.
fn check<T: Serialize + DeserializeOwned + Debug>(name: &str, value: &T, big_endian_too: bool) {
    let expected = fixture(&format!("{name}.cdr"));
    let encoded = encode(value).unwrap();
    assert_eq!(
        encoded, expected,
        "{name}: our CDR differs from rosbags'\n ours:   {encoded:02x?}\n theirs: {expected:02x?}"
    );
    let mut files = vec![expected];
    if big_endian_too {
        let be = fixture(&format!("{name}_be.cdr"));
        assert_eq!(&be[..4], &[0, 0, 0, 0], "{name}_be.cdr is not CDR_BE");
        files.push(be);
    }
    for bytes in &files {
        let decoded: T = decode(bytes).unwrap();
        assert_eq!(format!("{decoded:?}"), format!("{value:?}"), "{name}");
        assert_eq!(encode(&decoded).unwrap(), files[0], "{name}: re-encoding");
    }
}

fn imu() -> Imu {
    Imu {
        header: header(1_700_000_123, 456_789_012, "imu_link"),
        orientation: quaternion(0.1, -0.2, 0.3, 0.9),
        orientation_covariance: seq(1.5, 0.25),
        angular_velocity: vector3(0.01, -0.02, 0.5),
        angular_velocity_covariance: seq(1e-6, 1e-7),
        linear_acceleration: vector3(0.3, -0.4, 9.81),
        linear_acceleration_covariance: seq(2e-3, 1e-4),
    }
}

fn nav_sat_fix() -> NavSatFix {
    NavSatFix {
        header: header(1_700_000_200, 5, "gnss"),
        status: NavSatStatus {
            status: NavSatStatus::STATUS_NO_FIX,
            service: NavSatStatus::SERVICE_GPS | NavSatStatus::SERVICE_GALILEO,
        },
        latitude: 48.137154,
        longitude: 11.576124,
        altitude: 519.25,
        position_covariance: seq(0.5, 0.125),
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_DIAGONAL_KNOWN,
    }
}

fn odometry() -> Odometry {
    Odometry {
        header: header(42, 999_999_999, "map"),
        child_frame_id: "base_link".to_string(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Point {
                    x: 12.5,
                    y: -7.25,
                    z: 0.75,
                },
                orientation: quaternion(0.0, 0.0, 0.38268343236508984, 0.9238795325112867),
            },
            covariance: seq(0.01, 0.01),
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: vector3(3.5, 0.25, -0.125),
                angular: vector3(0.0, 0.0, 0.0625),
            },
            covariance: seq(-1.0, 0.5),
        },
    }
}

fn key_value(key: &str, value: &str) -> KeyValue {
    KeyValue {
        key: key.to_string(),
        value: value.to_string(),
    }
}

fn diagnostic_array() -> DiagnosticArray {
    DiagnosticArray {
        header: header(1_700_000_300, 1, ""),
        status: vec![
            DiagnosticStatus {
                level: DiagnosticStatus::WARN,
                name: "gnss_ins: filter".to_string(),
                message: "innovation gate hit 3×".to_string(),
                hardware_id: "ubx-f9p".to_string(),
                values: vec![
                    key_value("nis", "12.5"),
                    key_value("satellites_used", "7"),
                    key_value("elevation_mask_°", ""),
                ],
            },
            DiagnosticStatus {
                level: DiagnosticStatus::STALE,
                name: "imu".to_string(),
                message: "stale".to_string(),
                hardware_id: String::new(),
                values: vec![],
            },
        ],
    }
}

fn tf_message() -> TFMessage {
    TFMessage {
        transforms: vec![
            TransformStamped {
                header: header(100, 200, "odom"),
                child_frame_id: "base_link".to_string(),
                transform: Transform {
                    translation: vector3(1.0, 2.0, 3.0),
                    rotation: quaternion(0.5, -0.5, 0.5, -0.5),
                },
            },
            TransformStamped {
                header: header(101, 300, "map"),
                child_frame_id: "odom".to_string(),
                transform: Transform {
                    translation: vector3(-4.5, 0.125, 6.0),
                    rotation: Quaternion::default(),
                },
            },
        ],
    }
}

fn clock() -> Clock {
    Clock {
        clock: Time {
            sec: -3,
            nanosec: 750_000_000,
        },
    }
}

fn twist_with_covariance_stamped() -> TwistWithCovarianceStamped {
    TwistWithCovarianceStamped {
        header: header(7, 8, "gnss_antenna"),
        twist: TwistWithCovariance {
            twist: Twist {
                linear: vector3(-1.5, 2.5, 0.05),
                angular: vector3(0.1, 0.2, 0.3),
            },
            covariance: seq(100.0, -2.5),
        },
    }
}

fn gnss_measurements() -> GnssMeasurements {
    GnssMeasurements {
        header: header(1_700_000_400, 100_000_000, "gnss_antenna"),
        gps_week: 2288,
        gps_time_of_week_s: 345_618.1,
        satellites: vec![
            SatelliteMeasurement {
                constellation: SatelliteMeasurement::GPS,
                prn: 5,
                pseudorange_m: 21_456_789.125,
                pseudorange_rate_mps: -345.5,
                pseudorange_sigma_m: 2.5,
                pseudorange_rate_sigma_mps: 0.125,
                cn0_dbhz: 45.25,
                satellite_position_ecef_m: Point {
                    x: 15_600_000.5,
                    y: -7_540_000.25,
                    z: 20_140_000.75,
                },
                satellite_velocity_ecef_mps: vector3(-1_200.5, 2_300.25, 850.125),
                satellite_clock_bias_s: 1.234e-4,
                satellite_clock_drift_s_s: -5.6e-12,
                ionosphere_delay_m: NAN,
                troposphere_delay_m: 2.375,
                carrier_phase_cycles: 112_755_213.375,
                carrier_wavelength_m: 0.190_293_672_798,
                carrier_phase_sigma_cycles: 0.012,
                carrier_lock_time_s: 12.5,
                carrier_phase_flags: SatelliteMeasurement::CARRIER_HALF_CYCLE_UNRESOLVED,
            },
            SatelliteMeasurement {
                constellation: SatelliteMeasurement::GALILEO,
                prn: 27,
                pseudorange_m: 23_987_654.5,
                pseudorange_rate_mps: NAN,
                pseudorange_sigma_m: NAN,
                pseudorange_rate_sigma_mps: NAN,
                cn0_dbhz: f32::NAN,
                satellite_position_ecef_m: Point {
                    x: -12_000_000.0,
                    y: 18_500_000.0,
                    z: -17_250_000.5,
                },
                satellite_velocity_ecef_mps: vector3(2_100.0, -300.75, -1_500.5),
                satellite_clock_bias_s: -3.21e-5,
                satellite_clock_drift_s_s: 1.5e-12,
                ionosphere_delay_m: NAN,
                troposphere_delay_m: NAN,
                carrier_phase_cycles: NAN,
                carrier_wavelength_m: NAN,
                carrier_phase_sigma_cycles: NAN,
                carrier_lock_time_s: NAN,
                carrier_phase_flags: SatelliteMeasurement::CARRIER_LOSS_OF_LOCK,
            },
        ],
        klobuchar_alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -5.9605e-8],
        klobuchar_beta: [90112.0, 0.0, -196608.0, -65536.0],
    }
}

fn noise_estimates() -> NoiseEstimates {
    NoiseEstimates {
        header: header(1_700_000_400, 100_000_000, "gnss_antenna"),
        filter_variant: "ermakf".to_string(),
        satellites: vec![
            SatelliteNoise {
                constellation: SatelliteMeasurement::GPS,
                prn: 5,
                elevation_deg: 43.5,
                used: true,
                rejection_reason: SatelliteNoise::REJECTION_NONE,
                innovation_pseudorange_m: 1.75,
                innovation_pseudorange_rate_mps: -0.0625,
                normalized_innovation_pseudorange: 0.7,
                normalized_innovation_pseudorange_rate: -0.5,
                r_pseudorange_m2: 6.25,
                r_pseudorange_rate_m2_s2: 0.015625,
                kde_credibility: 0.0123,
                gaussian: true,
                ar_order: 3,
                robust_weight: 1.0,
            },
            SatelliteNoise {
                constellation: SatelliteMeasurement::GALILEO,
                prn: 27,
                elevation_deg: 7.25,
                used: false,
                rejection_reason: SatelliteNoise::REJECTION_ELEVATION_MASK,
                innovation_pseudorange_m: NAN,
                innovation_pseudorange_rate_mps: NAN,
                normalized_innovation_pseudorange: NAN,
                normalized_innovation_pseudorange_rate: NAN,
                r_pseudorange_m2: NAN,
                r_pseudorange_rate_m2_s2: NAN,
                kde_credibility: NAN,
                gaussian: false,
                ar_order: 0,
                robust_weight: NAN,
            },
        ],
        adaptive_factor: 0.85,
        mahalanobis_d2: 9.5,
        chi2_threshold: 15.507,
        q_scale: 1.25,
        nis: 7.75,
    }
}

#[test]
fn imu_matches_rosbags_little_and_big_endian() {
    check("imu", &imu(), true);
    assert_eq!(decode::<Imu>(&fixture("imu.cdr")).unwrap(), imu());
}

#[test]
fn nav_sat_fix_matches_rosbags() {
    check("nav_sat_fix", &nav_sat_fix(), false);
    assert_eq!(
        decode::<NavSatFix>(&fixture("nav_sat_fix.cdr")).unwrap(),
        nav_sat_fix()
    );
}

#[test]
fn odometry_matches_rosbags() {
    check("odometry", &odometry(), false);
    assert_eq!(
        decode::<Odometry>(&fixture("odometry.cdr")).unwrap(),
        odometry()
    );
}

#[test]
fn diagnostic_array_matches_rosbags() {
    check("diagnostic_array", &diagnostic_array(), false);
    assert_eq!(
        decode::<DiagnosticArray>(&fixture("diagnostic_array.cdr")).unwrap(),
        diagnostic_array()
    );
}

#[test]
fn tf_message_matches_rosbags() {
    check("tf_message", &tf_message(), false);
    assert_eq!(
        decode::<TFMessage>(&fixture("tf_message.cdr")).unwrap(),
        tf_message()
    );
}

#[test]
fn clock_matches_rosbags() {
    check("clock", &clock(), false);
    assert_eq!(decode::<Clock>(&fixture("clock.cdr")).unwrap(), clock());
}

#[test]
fn twist_with_covariance_stamped_matches_rosbags() {
    check(
        "twist_with_covariance_stamped",
        &twist_with_covariance_stamped(),
        false,
    );
    assert_eq!(
        decode::<TwistWithCovarianceStamped>(&fixture("twist_with_covariance_stamped.cdr"))
            .unwrap(),
        twist_with_covariance_stamped()
    );
}

#[test]
fn gnss_measurements_match_rosbags_little_and_big_endian() {
    check("gnss_measurements", &gnss_measurements(), true);
}

#[test]
fn noise_estimates_match_rosbags() {
    check("noise_estimates", &noise_estimates(), false);
}

fn ubx_rxm_rawx() -> UbxRxmRawx {
    UbxRxmRawx {
        header: header(1_756_402_257, 31_000_123, "ubx"),
        rcv_tow: 408_657.001,
        week: 2381,
        leap_s: -18,
        num_meas: 2,
        rec_stat: RecStat {
            leap_sec: true,
            clk_reset: false,
        },
        version: 1,
        rawx_data: vec![
            RawxData {
                pr_mes: 21_456_789.125,
                cp_mes: -112_752_345.5,
                do_mes: -1234.5,
                gnss_id: 0,
                sv_id: 32,
                sig_id: 0,
                freq_id: 7,
                locktime: 64_500,
                c_no: 45,
                pr_stdev: 0x15,
                cp_stdev: 3,
                do_stdev: 7,
                trk_stat: TrkStat {
                    pr_valid: true,
                    cp_valid: false,
                    half_cyc: true,
                    sub_half_cyc: false,
                },
            },
            RawxData {
                pr_mes: 23_987_654.5,
                cp_mes: NAN,
                do_mes: 2.25,
                gnss_id: 3,
                sv_id: 44,
                sig_id: 4,
                freq_id: 0,
                locktime: 1,
                c_no: 31,
                pr_stdev: 9,
                cp_stdev: 15,
                do_stdev: 0,
                trk_stat: TrkStat {
                    pr_valid: false,
                    cp_valid: true,
                    half_cyc: false,
                    sub_half_cyc: true,
                },
            },
        ],
    }
}

fn ubx_rxm_sfrbx() -> UbxRxmSfrbx {
    UbxRxmSfrbx {
        header: header(1_756_402_257, 5, "ubx"),
        gnss_id: 2,
        sv_id: 7,
        sig_id: 1,
        freq_id: 0,
        num_words: 3,
        chn: 17,
        version: 2,
        dwrd: vec![0x8B00_0001, 0xFFFF_FFFF, 0x0000_2A00],
    }
}

fn uint8_multi_array() -> UInt8MultiArray {
    UInt8MultiArray {
        layout: MultiArrayLayout {
            dim: vec![MultiArrayDimension {
                label: "raw_data_stream".to_string(),
                size: 7,
                stride: 1,
            }],
            data_offset: 0,
        },
        data: vec![0xB5, 0x62, 0x02, 0x15, 0x10, 0x00, 0xFF],
    }
}

#[test]
fn ublox_driver_messages_match_rosbags() {
    check("ubx_rxm_rawx", &ubx_rxm_rawx(), true);
    check("ubx_rxm_sfrbx", &ubx_rxm_sfrbx(), false);
}

fn ubx_nav_rel_pos_ned() -> UbxNavRelPosNed {
    UbxNavRelPosNed {
        header: header(1_756_402_257, 200_000_000, "rover"),
        version: 1,
        ref_station_id: 4095,
        itow: 408_657_200,
        rel_pos_n: -87,
        rel_pos_e: 49,
        rel_pos_d: -3,
        rel_pos_length: 100,
        rel_pos_heading: 15_063_719,
        rel_pos_hp_n: -42,
        rel_pos_hp_e: 17,
        rel_pos_hp_d: -99,
        rel_pos_hp_length: 5,
        acc_n: 123,
        acc_e: 456,
        acc_d: 789,
        acc_length: 101,
        acc_heading: 2_500_000,
        gnss_fix_ok: true,
        diff_soln: false,
        rel_pos_valid: true,
        carr_soln: CarrSoln {
            status: CarrSoln::PHASE_WITH_FIXED_AMBIGUITIES,
        },
        is_moving: true,
        ref_pos_miss: false,
        ref_obs_miss: true,
        rel_pos_heading_valid: true,
        rel_pos_normalized: false,
    }
}

#[test]
fn ubx_nav_rel_pos_ned_matches_rosbags_little_and_big_endian() {
    check("ubx_nav_rel_pos_ned", &ubx_nav_rel_pos_ned(), true);
}

#[test]
fn uint8_multi_array_matches_rosbags() {
    check("uint8_multi_array", &uint8_multi_array(), false);
}

#[test]
fn gnss_fixture_converts_to_the_core_epoch() {
    let msg: GnssMeasurements = decode(&fixture("gnss_measurements.cdr")).unwrap();
    let epoch = GnssEpoch::try_from(&msg).unwrap();
    assert_eq!(epoch.t_s, 1_700_000_400.1);
    assert_eq!(epoch.gps_time_of_week_s, 345_618.1);
    assert_eq!(epoch.satellites.len(), 2);
    let gps = &epoch.satellites[0];
    assert_eq!(gps.sat.constellation, Constellation::Gps);
    assert_eq!(gps.sat.prn, 5);
    assert_eq!(gps.pseudorange_m, Some(21_456_789.125));
    assert_eq!(gps.pseudorange_rate_mps, Some(-345.5));
    assert_eq!(gps.pseudorange_sigma_m, Some(2.5));
    assert_eq!(gps.cn0_dbhz, Some(45.25));
    assert_eq!(gps.iono_delay_m, None);
    assert_eq!(gps.tropo_delay_m, Some(2.375));
    assert_eq!(gps.sat_vel_ecef_mps.y, 2_300.25);
    let galileo = &epoch.satellites[1];
    assert_eq!(galileo.sat.constellation, Constellation::Galileo);
    assert_eq!(galileo.sat.prn, 27);
    assert_eq!(galileo.pseudorange_rate_mps, None);
    assert_eq!(galileo.pseudorange_sigma_m, None);
    assert_eq!(galileo.pseudorange_rate_sigma_mps, None);
    assert_eq!(galileo.cn0_dbhz, None);
    assert_eq!(galileo.sat_pos_ecef_m.z, -17_250_000.5);
    let klobuchar = epoch.klobuchar.unwrap();
    assert_eq!(klobuchar.alpha[2], -5.9605e-8);
    assert_eq!(klobuchar.beta[0], 90112.0);
}

#[test]
fn imu_fixture_converts_to_a_core_sample() {
    let msg: Imu = decode(&fixture("imu_be.cdr")).unwrap();
    let sample = ImuSample::try_from(&msg).unwrap();
    // 1_700_000_123.456789012 s: the nearest f64 (spacing 2^-22 s near 1.7e9 s).
    assert!((sample.t_s - 1_700_000_123.456_789).abs() < 2.4e-7);
    assert_eq!(sample.w_ib_b_rad_s.as_slice(), &[0.01, -0.02, 0.5]);
    assert_eq!(sample.f_ib_b_m_s2.as_slice(), &[0.3, -0.4, 9.81]);
}

#[test]
fn type_names_follow_ros_2_conventions() {
    assert_eq!(Imu::TYPE_NAME, "sensor_msgs/msg/Imu");
    assert_eq!(Imu::DDS_TYPE_NAME, "sensor_msgs::msg::dds_::Imu_");
    assert_eq!(TFMessage::TYPE_NAME, "tf2_msgs/msg/TFMessage");
    assert_eq!(Clock::DDS_TYPE_NAME, "rosgraph_msgs::msg::dds_::Clock_");
    assert_eq!(
        GnssMeasurements::TYPE_NAME,
        "adaptive_gnss_ins/msg/GnssMeasurements"
    );
    assert_eq!(
        NoiseEstimates::DDS_TYPE_NAME,
        "adaptive_gnss_ins::msg::dds_::NoiseEstimates_"
    );
    assert!(GNSS_MEASUREMENTS_MSG.contains("SatelliteMeasurement[] satellites"));
    assert!(NOISE_ESTIMATES_MSG.contains("SatelliteNoise[] satellites"));
    assert!(SATELLITE_MEASUREMENT_MSG.contains("uint8 GPS=1"));
    assert!(SATELLITE_NOISE_MSG.contains("uint8 REJECTION_MAHALANOBIS=6"));
    assert_eq!(UbxRxmRawx::TYPE_NAME, "ublox_ubx_msgs/msg/UBXRxmRawx");
    assert_eq!(
        UbxNavRelPosNed::DDS_TYPE_NAME,
        "ublox_ubx_msgs::msg::dds_::UBXNavRelPosNED_"
    );
    assert_eq!(
        UbxRxmSfrbx::DDS_TYPE_NAME,
        "ublox_ubx_msgs::msg::dds_::UBXRxmSfrbx_"
    );
    assert_eq!(
        UInt8MultiArray::DDS_TYPE_NAME,
        "std_msgs::msg::dds_::UInt8MultiArray_"
    );
}

#[test]
fn header_too_short_is_an_error() {
    for len in 0..4 {
        let err = decode::<Clock>(&fixture("clock.cdr")[..len]).unwrap_err();
        assert!(matches!(err, CdrError::MissingHeader { len: l, .. } if l == len));
    }
}

#[test]
fn other_encapsulations_are_rejected() {
    let mut bytes = fixture("clock.cdr");
    for identifier in [[0x00, 0x02], [0x00, 0x03], [0x00, 0x07], [0x01, 0x01]] {
        bytes[..2].copy_from_slice(&identifier);
        let err = decode::<Clock>(&bytes).unwrap_err();
        assert!(
            matches!(err, CdrError::UnsupportedEncapsulation { identifier: id, .. } if id == identifier)
        );
    }
}

/// Every strict prefix of every fixture is an error (all fixtures end on data).
#[test]
fn truncated_payloads_are_errors() {
    fn all_prefixes_fail<T: DeserializeOwned + Debug>(name: &str) {
        let bytes = fixture(name);
        for len in 0..bytes.len() {
            let result = decode::<T>(&bytes[..len]);
            assert!(result.is_err(), "{name} cut to {len} bytes decoded");
        }
    }
    all_prefixes_fail::<Imu>("imu.cdr");
    all_prefixes_fail::<Imu>("imu_be.cdr");
    all_prefixes_fail::<NavSatFix>("nav_sat_fix.cdr");
    all_prefixes_fail::<Odometry>("odometry.cdr");
    all_prefixes_fail::<DiagnosticArray>("diagnostic_array.cdr");
    all_prefixes_fail::<TFMessage>("tf_message.cdr");
    all_prefixes_fail::<Clock>("clock.cdr");
    all_prefixes_fail::<TwistWithCovarianceStamped>("twist_with_covariance_stamped.cdr");
    all_prefixes_fail::<GnssMeasurements>("gnss_measurements.cdr");
    all_prefixes_fail::<NoiseEstimates>("noise_estimates.cdr");
    all_prefixes_fail::<UbxRxmRawx>("ubx_rxm_rawx.cdr");
    all_prefixes_fail::<UbxRxmSfrbx>("ubx_rxm_sfrbx.cdr");
    all_prefixes_fail::<UInt8MultiArray>("uint8_multi_array.cdr");
}

#[test]
fn padding_is_accepted_but_extra_bytes_are_not() {
    let mut bytes = fixture("clock.cdr");
    bytes.extend_from_slice(&[0, 0, 0]);
    assert_eq!(decode::<Clock>(&bytes).unwrap(), clock());
    bytes.push(0);
    let err = decode::<Clock>(&bytes).unwrap_err();
    assert!(matches!(err, CdrError::TrailingBytes { trailing: 4, .. }));
}

#[test]
fn garbled_fields_are_errors() {
    // NoiseEstimates: "used" of the first satellite (a bool) set to 2.
    let mut bytes = encode(&noise_estimates()).unwrap();
    let good = bytes.clone();
    let used_offset = 4 + 8 + (4 + 13 + 3) + (4 + 7) + 1 + 4 + 2 + 2 + 8;
    assert_eq!(bytes[used_offset], 1, "offset of `used` moved");
    bytes[used_offset] = 2;
    assert!(matches!(
        decode::<NoiseEstimates>(&bytes).unwrap_err(),
        CdrError::MalformedBody { .. }
    ));
    // Invalid UTF-8 in the frame id ("gnss_antenna" starts after sec, nanosec, length).
    let mut bytes = good.clone();
    bytes[4 + 8 + 4] = 0xff;
    assert!(matches!(
        decode::<NoiseEstimates>(&bytes).unwrap_err(),
        CdrError::MalformedBody { .. }
    ));
    // A string length far beyond the payload.
    let mut bytes = good.clone();
    bytes[4 + 8..4 + 12].copy_from_slice(&0xffff_fff0_u32.to_le_bytes());
    assert!(decode::<NoiseEstimates>(&bytes).is_err());
    // A sequence count of 2^32 - 1 satellites: an error, not a huge allocation.
    let mut bytes = good;
    let count_offset = 4 + 8 + (4 + 13 + 3) + (4 + 7) + 1;
    assert_eq!(
        &bytes[count_offset..count_offset + 4],
        &2u32.to_le_bytes(),
        "offset of the satellite count moved"
    );
    bytes[count_offset..count_offset + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(decode::<NoiseEstimates>(&bytes).is_err());
}

/// Overwriting any single byte of the body with any of a few values never panics.
#[test]
fn corrupted_bytes_never_panic() {
    fn corrupt<T: DeserializeOwned + Debug>(name: &str) {
        let good = fixture(name);
        for index in 4..good.len() {
            for value in [0x00, 0x01, 0x7f, 0x80, 0xff] {
                let mut bytes = good.clone();
                bytes[index] = value;
                let _ = decode::<T>(&bytes);
            }
        }
    }
    corrupt::<DiagnosticArray>("diagnostic_array.cdr");
    corrupt::<TFMessage>("tf_message.cdr");
    corrupt::<GnssMeasurements>("gnss_measurements.cdr");
    corrupt::<NoiseEstimates>("noise_estimates.cdr");
    corrupt::<Odometry>("odometry.cdr");
}
