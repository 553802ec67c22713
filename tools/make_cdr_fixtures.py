#!/usr/bin/env python3
"""Writes tests/data/cdr/*.cdr: one ROS 2 CDR payload per message type, serialized by
the independent pure-Python `rosbags` library (ROS 2 Jazzy type store plus this
package's msg/ definitions and the u-blox driver's ublox_ubx_msgs definitions below). tests/cdr_fixtures.rs builds the same values in Rust and
checks that our encoder reproduces these bytes exactly and our decoder reads them back.

Usage (from the crate root, in a throw-away virtual environment outside the repo):
    python3 -m venv "$HOME/venv_fixtures"
    "$HOME/venv_fixtures/bin/pip" install -r tools/requirements-test-peers.txt
    "$HOME/venv_fixtures/bin/python" tools/make_cdr_fixtures.py

The values are distinctive (no zeros where a field could be confused with padding, odd
string lengths, a negative int8, NaN where the contract allows it) and MUST stay in step
with tests/cdr_fixtures.rs.
"""

from pathlib import Path

import numpy as np
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

CRATE_ROOT = Path(__file__).resolve().parent.parent
MSG_DIR = CRATE_ROOT / "msg"
OUT_DIR = CRATE_ROOT / "tests" / "data" / "cdr"
PACKAGE = "adaptive_gnss_ins"
OWN_MESSAGES = ["SatelliteMeasurement", "GnssMeasurements", "SatelliteNoise", "NoiseEstimates"]
NAN = float("nan")

# The u-blox ROS 2 driver's message definitions, as in its repository
# (github.com/aussierobots/ublox_dgnss, ublox_ubx_msgs/msg/, commit 67178ed36dbb): the
# reference our src/ros/msg/ublox.rs structs are checked against.
UBLOX_MESSAGES = {
    "RecStat": """
bool leap_sec       # Leap seconds have been determined
bool clk_reset      # Clock reset applied
""",
    "TrkStat": """
bool pr_valid       # Pseudorange valid
bool cp_valid       # Carrier phase valid
bool half_cyc       # Half cycle valid
bool sub_half_cyc   # Half cycle subtracted from phase
""",
    "RawxData": """
float64 pr_mes      # m - Pseudorange measurement
float64 cp_mes      # cycles - Carrier phase measurement
float32 do_mes      # Hz - Doppler measurement
uint8 gnss_id       # GNSS identifier
uint8 sv_id         # Satellite identifier
uint8 sig_id        # Signal identifier
uint8 freq_id       # Frequency slot for GLONASS
uint16 locktime     # ms - Carrier phase locktime counter
uint8 c_no          # dBHz - Carrier-to-noise density ratio
uint8 pr_stdev      # 0.01*2^n m - Estimated pseudorange standard deviation
uint8 cp_stdev      # 0.004 cycles - Estimated carrier phase standard deviation
uint8 do_stdev      # 0.002*2^n Hz - Estimated Doppler standard deviation
TrkStat trk_stat      # Tracking status bitfield
# uint8 reserved1     # Reserved
""",
    "UBXRxmRawx": """
std_msgs/Header header  # Header timestamp should be acquisition time

# Fields
float64 rcv_tow      # s - Measurement time of week
uint16 week          # weeks - GPS week number
int8 leap_s          # s - GPS leap seconds
uint8 num_meas       # Number of measurements
RecStat rec_stat       # Receiver tracking status bitfield
uint8 version        # Message version
# uint8[2] reserved0   # Reserved

RawxData[] rawx_data # Repeated group of data for each satellite
""",
    "UBXRxmSfrbx": """
std_msgs/Header header  # Header timestamp should be acquisition time

# Fields
uint8 gnss_id       # GNSS identifier (see Satellite Numbering)
uint8 sv_id         # Satellite identifier (see Satellite Numbering)
uint8 sig_id        # Signal identifier (see Signal Identifiers)
uint8 freq_id       # Only used for GLONASS: frequency slot + 7 (range 0 to 13)
uint8 num_words     # Number of data words contained in this message (up to 16)
uint8 chn           # Tracking channel number the message was received on
uint8 version       # Message version (0x02 for this version)

uint32[] dwrd       # Data words (numWords entries)
""",
    # The moving-base pair's relative position (UBX-NAV-RELPOSNED), field for field as in
    # the driver's UBXNavRelPosNED.msg and CarrSoln.msg (comments ours).
    "CarrSoln": """
uint8 CARRIER_SOLUTION_NO_CARRIER_RANGE_SOLUTION = 0
uint8 CARRIER_SOLUTION_PHASE_WITH_FLOATING_AMBIGUITIES = 1
uint8 CARRIER_SOLUTION_PHASE_WITH_FIXED_AMBIGUITIES = 2
uint8 status
""",
    "UBXNavRelPosNED": """
std_msgs/Header header
uint8 version
uint16 ref_station_id
uint32 itow               # ms
int32 rel_pos_n           # cm
int32 rel_pos_e           # cm
int32 rel_pos_d           # cm
int32 rel_pos_length      # cm
int32 rel_pos_heading     # 1e-5 deg
int8 rel_pos_hp_n         # 0.1 mm
int8 rel_pos_hp_e         # 0.1 mm
int8 rel_pos_hp_d         # 0.1 mm
int8 rel_pos_hp_length    # 0.1 mm
uint32 acc_n              # 0.1 mm
uint32 acc_e              # 0.1 mm
uint32 acc_d              # 0.1 mm
uint32 acc_length         # 0.1 mm
uint32 acc_heading        # 1e-5 deg
bool gnss_fix_ok
bool diff_soln
bool rel_pos_valid
CarrSoln carr_soln
bool is_moving
bool ref_pos_miss
bool ref_obs_miss
bool rel_pos_heading_valid
bool rel_pos_normalized
""",
}


def make_typestore():
    """ROS 2 Jazzy types plus this package's messages read from msg/ and the u-blox
    driver's."""
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for name in OWN_MESSAGES:
        text = (MSG_DIR / f"{name}.msg").read_text(encoding="utf-8")
        types.update(get_types_from_msg(text, f"{PACKAGE}/msg/{name}"))
    for name, text in UBLOX_MESSAGES.items():
        types.update(get_types_from_msg(text, f"ublox_ubx_msgs/msg/{name}"))
    store.register(types)
    return store


def seq(start, count, step):
    """float64 array start, start + step, ... (count elements)."""
    return np.array([start + i * step for i in range(count)], dtype=np.float64)


def build_messages(ts):
    """(fixture name, ROS type name, message) for every fixture."""
    T = ts.types
    Time = T["builtin_interfaces/msg/Time"]
    Header = T["std_msgs/msg/Header"]
    Point = T["geometry_msgs/msg/Point"]
    Vector3 = T["geometry_msgs/msg/Vector3"]
    Quaternion = T["geometry_msgs/msg/Quaternion"]
    Pose = T["geometry_msgs/msg/Pose"]
    Twist = T["geometry_msgs/msg/Twist"]
    Transform = T["geometry_msgs/msg/Transform"]

    imu = T["sensor_msgs/msg/Imu"](
        header=Header(stamp=Time(sec=1_700_000_123, nanosec=456_789_012), frame_id="imu_link"),
        orientation=Quaternion(x=0.1, y=-0.2, z=0.3, w=0.9),
        orientation_covariance=seq(1.5, 9, 0.25),
        angular_velocity=Vector3(x=0.01, y=-0.02, z=0.5),
        angular_velocity_covariance=seq(1e-6, 9, 1e-7),
        linear_acceleration=Vector3(x=0.3, y=-0.4, z=9.81),
        linear_acceleration_covariance=seq(2e-3, 9, 1e-4),
    )

    nav_sat_status = T["sensor_msgs/msg/NavSatStatus"]
    nav_sat_fix = T["sensor_msgs/msg/NavSatFix"](
        header=Header(stamp=Time(sec=1_700_000_200, nanosec=5), frame_id="gnss"),
        status=nav_sat_status(status=-1, service=1 | 8),
        latitude=48.137154,
        longitude=11.576124,
        altitude=519.25,
        position_covariance=seq(0.5, 9, 0.125),
        position_covariance_type=2,
    )

    odometry = T["nav_msgs/msg/Odometry"](
        header=Header(stamp=Time(sec=42, nanosec=999_999_999), frame_id="map"),
        child_frame_id="base_link",
        pose=T["geometry_msgs/msg/PoseWithCovariance"](
            pose=Pose(
                position=Point(x=12.5, y=-7.25, z=0.75),
                orientation=Quaternion(x=0.0, y=0.0, z=0.38268343236508984, w=0.9238795325112867),
            ),
            covariance=seq(0.01, 36, 0.01),
        ),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=Twist(linear=Vector3(x=3.5, y=0.25, z=-0.125), angular=Vector3(x=0.0, y=0.0, z=0.0625)),
            covariance=seq(-1.0, 36, 0.5),
        ),
    )

    KeyValue = T["diagnostic_msgs/msg/KeyValue"]
    DiagnosticStatus = T["diagnostic_msgs/msg/DiagnosticStatus"]
    diagnostic_array = T["diagnostic_msgs/msg/DiagnosticArray"](
        header=Header(stamp=Time(sec=1_700_000_300, nanosec=1), frame_id=""),
        status=[
            DiagnosticStatus(
                level=1,
                name="gnss_ins: filter",
                message="innovation gate hit 3×",
                hardware_id="ubx-f9p",
                values=[
                    KeyValue(key="nis", value="12.5"),
                    KeyValue(key="satellites_used", value="7"),
                    KeyValue(key="elevation_mask_°", value=""),
                ],
            ),
            DiagnosticStatus(level=3, name="imu", message="stale", hardware_id="", values=[]),
        ],
    )

    TransformStamped = T["geometry_msgs/msg/TransformStamped"]
    tf_message = T["tf2_msgs/msg/TFMessage"](
        transforms=[
            TransformStamped(
                header=Header(stamp=Time(sec=100, nanosec=200), frame_id="odom"),
                child_frame_id="base_link",
                transform=Transform(
                    translation=Vector3(x=1.0, y=2.0, z=3.0),
                    rotation=Quaternion(x=0.5, y=-0.5, z=0.5, w=-0.5),
                ),
            ),
            TransformStamped(
                header=Header(stamp=Time(sec=101, nanosec=300), frame_id="map"),
                child_frame_id="odom",
                transform=Transform(
                    translation=Vector3(x=-4.5, y=0.125, z=6.0),
                    rotation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                ),
            ),
        ]
    )

    clock = T["rosgraph_msgs/msg/Clock"](clock=Time(sec=-3, nanosec=750_000_000))

    twist_stamped = T["geometry_msgs/msg/TwistWithCovarianceStamped"](
        header=Header(stamp=Time(sec=7, nanosec=8), frame_id="gnss_antenna"),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=Twist(linear=Vector3(x=-1.5, y=2.5, z=0.05), angular=Vector3(x=0.1, y=0.2, z=0.3)),
            covariance=seq(100.0, 36, -2.5),
        ),
    )

    Sat = T[f"{PACKAGE}/msg/SatelliteMeasurement"]
    gnss_measurements = T[f"{PACKAGE}/msg/GnssMeasurements"](
        header=Header(stamp=Time(sec=1_700_000_400, nanosec=100_000_000), frame_id="gnss_antenna"),
        gps_week=2288,
        gps_time_of_week_s=345_618.1,
        satellites=[
            Sat(
                constellation=1,
                prn=5,
                pseudorange_m=21_456_789.125,
                pseudorange_rate_mps=-345.5,
                pseudorange_sigma_m=2.5,
                pseudorange_rate_sigma_mps=0.125,
                cn0_dbhz=45.25,
                satellite_position_ecef_m=Point(x=15_600_000.5, y=-7_540_000.25, z=20_140_000.75),
                satellite_velocity_ecef_mps=Vector3(x=-1_200.5, y=2_300.25, z=850.125),
                satellite_clock_bias_s=1.234e-4,
                satellite_clock_drift_s_s=-5.6e-12,
                ionosphere_delay_m=NAN,
                troposphere_delay_m=2.375,
                carrier_phase_cycles=112_755_213.375,
                carrier_wavelength_m=0.190_293_672_798,
                carrier_phase_sigma_cycles=0.012,
                carrier_lock_time_s=12.5,
                carrier_phase_flags=2,
            ),
            Sat(
                constellation=3,
                prn=27,
                pseudorange_m=23_987_654.5,
                pseudorange_rate_mps=NAN,
                pseudorange_sigma_m=NAN,
                pseudorange_rate_sigma_mps=NAN,
                cn0_dbhz=NAN,
                satellite_position_ecef_m=Point(x=-12_000_000.0, y=18_500_000.0, z=-17_250_000.5),
                satellite_velocity_ecef_mps=Vector3(x=2_100.0, y=-300.75, z=-1_500.5),
                satellite_clock_bias_s=-3.21e-5,
                satellite_clock_drift_s_s=1.5e-12,
                ionosphere_delay_m=NAN,
                troposphere_delay_m=NAN,
                carrier_phase_cycles=NAN,
                carrier_wavelength_m=NAN,
                carrier_phase_sigma_cycles=NAN,
                carrier_lock_time_s=NAN,
                carrier_phase_flags=1,
            ),
        ],
        klobuchar_alpha=np.array([1.1176e-8, 7.4506e-9, -5.9605e-8, -5.9605e-8]),
        klobuchar_beta=np.array([90112.0, 0.0, -196608.0, -65536.0]),
    )

    Noise = T[f"{PACKAGE}/msg/SatelliteNoise"]
    noise_estimates = T[f"{PACKAGE}/msg/NoiseEstimates"](
        header=Header(stamp=Time(sec=1_700_000_400, nanosec=100_000_000), frame_id="gnss_antenna"),
        filter_variant="ermakf",
        satellites=[
            Noise(
                constellation=1,
                prn=5,
                elevation_deg=43.5,
                used=True,
                rejection_reason=0,
                innovation_pseudorange_m=1.75,
                innovation_pseudorange_rate_mps=-0.0625,
                normalized_innovation_pseudorange=0.7,
                normalized_innovation_pseudorange_rate=-0.5,
                r_pseudorange_m2=6.25,
                r_pseudorange_rate_m2_s2=0.015625,
                kde_credibility=0.0123,
                gaussian=True,
                ar_order=3,
                robust_weight=1.0,
            ),
            Noise(
                constellation=3,
                prn=27,
                elevation_deg=7.25,
                used=False,
                rejection_reason=1,
                innovation_pseudorange_m=NAN,
                innovation_pseudorange_rate_mps=NAN,
                normalized_innovation_pseudorange=NAN,
                normalized_innovation_pseudorange_rate=NAN,
                r_pseudorange_m2=NAN,
                r_pseudorange_rate_m2_s2=NAN,
                kde_credibility=NAN,
                gaussian=False,
                ar_order=0,
                robust_weight=NAN,
            ),
        ],
        adaptive_factor=0.85,
        mahalanobis_d2=9.5,
        chi2_threshold=15.507,
        q_scale=1.25,
        nis=7.75,
    )

    U = "ublox_ubx_msgs/msg/"
    TrkStat = T[U + "TrkStat"]
    RawxData = T[U + "RawxData"]
    ubx_rxm_rawx = T[U + "UBXRxmRawx"](
        header=Header(stamp=Time(sec=1_756_402_257, nanosec=31_000_123), frame_id="ubx"),
        rcv_tow=408_657.001,
        week=2381,
        leap_s=-18,
        num_meas=2,
        rec_stat=T[U + "RecStat"](leap_sec=True, clk_reset=False),
        version=1,
        rawx_data=[
            RawxData(
                pr_mes=21_456_789.125,
                cp_mes=-112_752_345.5,
                do_mes=-1234.5,
                gnss_id=0,
                sv_id=32,
                sig_id=0,
                freq_id=7,
                locktime=64_500,
                c_no=45,
                pr_stdev=0x15,
                cp_stdev=3,
                do_stdev=7,
                trk_stat=TrkStat(pr_valid=True, cp_valid=False, half_cyc=True, sub_half_cyc=False),
            ),
            RawxData(
                pr_mes=23_987_654.5,
                cp_mes=NAN,
                do_mes=2.25,
                gnss_id=3,
                sv_id=44,
                sig_id=4,
                freq_id=0,
                locktime=1,
                c_no=31,
                pr_stdev=9,
                cp_stdev=15,
                do_stdev=0,
                trk_stat=TrkStat(pr_valid=False, cp_valid=True, half_cyc=False, sub_half_cyc=True),
            ),
        ],
    )
    ubx_rxm_sfrbx = T[U + "UBXRxmSfrbx"](
        header=Header(stamp=Time(sec=1_756_402_257, nanosec=5), frame_id="ubx"),
        gnss_id=2,
        sv_id=7,
        sig_id=1,
        freq_id=0,
        num_words=3,
        chn=17,
        version=2,
        dwrd=np.array([0x8B00_0001, 0xFFFF_FFFF, 0x0000_2A00], dtype=np.uint32),
    )

    ubx_nav_rel_pos_ned = T[U + "UBXNavRelPosNED"](
        header=Header(stamp=Time(sec=1_756_402_257, nanosec=200_000_000), frame_id="rover"),
        version=1,
        ref_station_id=4095,
        itow=408_657_200,
        rel_pos_n=-87,
        rel_pos_e=49,
        rel_pos_d=-3,
        rel_pos_length=100,
        rel_pos_heading=15_063_719,
        rel_pos_hp_n=-42,
        rel_pos_hp_e=17,
        rel_pos_hp_d=-99,
        rel_pos_hp_length=5,
        acc_n=123,
        acc_e=456,
        acc_d=789,
        acc_length=101,
        acc_heading=2_500_000,
        gnss_fix_ok=True,
        diff_soln=False,
        rel_pos_valid=True,
        carr_soln=T[U + "CarrSoln"](status=2),
        is_moving=True,
        ref_pos_miss=False,
        ref_obs_miss=True,
        rel_pos_heading_valid=True,
        rel_pos_normalized=False,
    )

    MultiArrayDimension = T["std_msgs/msg/MultiArrayDimension"]
    uint8_multi_array = T["std_msgs/msg/UInt8MultiArray"](
        layout=T["std_msgs/msg/MultiArrayLayout"](
            dim=[MultiArrayDimension(label="raw_data_stream", size=7, stride=1)],
            data_offset=0,
        ),
        data=np.array([0xB5, 0x62, 0x02, 0x15, 0x10, 0x00, 0xFF], dtype=np.uint8),
    )

    return [
        ("imu", "sensor_msgs/msg/Imu", imu),
        ("nav_sat_fix", "sensor_msgs/msg/NavSatFix", nav_sat_fix),
        ("odometry", "nav_msgs/msg/Odometry", odometry),
        ("diagnostic_array", "diagnostic_msgs/msg/DiagnosticArray", diagnostic_array),
        ("tf_message", "tf2_msgs/msg/TFMessage", tf_message),
        ("clock", "rosgraph_msgs/msg/Clock", clock),
        ("twist_with_covariance_stamped", "geometry_msgs/msg/TwistWithCovarianceStamped", twist_stamped),
        ("gnss_measurements", f"{PACKAGE}/msg/GnssMeasurements", gnss_measurements),
        ("noise_estimates", f"{PACKAGE}/msg/NoiseEstimates", noise_estimates),
        ("ubx_rxm_rawx", U + "UBXRxmRawx", ubx_rxm_rawx),
        ("ubx_rxm_sfrbx", U + "UBXRxmSfrbx", ubx_rxm_sfrbx),
        ("ubx_nav_rel_pos_ned", U + "UBXNavRelPosNED", ubx_nav_rel_pos_ned),
        ("uint8_multi_array", "std_msgs/msg/UInt8MultiArray", uint8_multi_array),
    ]


# Fixtures also written big-endian (CDR_BE), to prove the decoder reads that encapsulation.
BIG_ENDIAN_TOO = {"imu", "gnss_measurements", "ubx_rxm_rawx", "ubx_nav_rel_pos_ned"}


def main():
    ts = make_typestore()
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    for name, typename, message in build_messages(ts):
        payload = bytes(ts.serialize_cdr(message, typename, little_endian=True))
        (OUT_DIR / f"{name}.cdr").write_bytes(payload)
        print(f"{name}.cdr: {typename}, {len(payload)} bytes")
        if name in BIG_ENDIAN_TOO:
            payload_be = bytes(ts.serialize_cdr(message, typename, little_endian=False))
            (OUT_DIR / f"{name}_be.cdr").write_bytes(payload_be)
            print(f"{name}_be.cdr: {typename}, {len(payload_be)} bytes (CDR_BE)")


if __name__ == "__main__":
    main()
