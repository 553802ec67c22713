"""ROS 2 Jazzy message types as Cyclone DDS (PyPI `cyclonedds`) IDL structs.

Written by hand from the .msg definitions (ROS 2 Jazzy and this repository's msg/), so that
an implementation independent of the node's Rust structs reads and writes the same bytes.
DDS type names follow the ROS 2 convention `pkg::msg::dds_::Name_`; topics are `rt/...`,
service request and reply topics `rq/...Request` and `rr/...Reply`. Every struct is final
(plain CDR, no member headers), and writers must use XCDR1 (`cyclonedds_setup.xcdr1_qos`),
which is what ROS 2 peers and ros2-client speak.
"""

from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
import cyclonedds.idl.annotations as annotate
from cyclonedds.idl.types import array, float32, float64, int8, int32, int64, sequence
from cyclonedds.idl.types import uint8, uint16, uint32, uint64


def _name(package: str, kind: str, name: str) -> str:
    return f'{package}::{kind}::dds_::{name}_'


def _zeros(n: int):
    return field(default_factory=lambda: [0.0] * n)


@dataclass
@annotate.final
class Time(IdlStruct, typename=_name('builtin_interfaces', 'msg', 'Time')):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
@annotate.final
class Header(IdlStruct, typename=_name('std_msgs', 'msg', 'Header')):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ''


@dataclass
@annotate.final
class Point(IdlStruct, typename=_name('geometry_msgs', 'msg', 'Point')):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
@annotate.final
class Vector3(IdlStruct, typename=_name('geometry_msgs', 'msg', 'Vector3')):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
@annotate.final
class Quaternion(IdlStruct, typename=_name('geometry_msgs', 'msg', 'Quaternion')):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
@annotate.final
class Pose(IdlStruct, typename=_name('geometry_msgs', 'msg', 'Pose')):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
@annotate.final
class PoseWithCovariance(IdlStruct, typename=_name('geometry_msgs', 'msg', 'PoseWithCovariance')):
    pose: Pose = field(default_factory=Pose)
    covariance: array[float64, 36] = _zeros(36)


@dataclass
@annotate.final
class Twist(IdlStruct, typename=_name('geometry_msgs', 'msg', 'Twist')):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
@annotate.final
class TwistWithCovariance(IdlStruct,
                          typename=_name('geometry_msgs', 'msg', 'TwistWithCovariance')):
    twist: Twist = field(default_factory=Twist)
    covariance: array[float64, 36] = _zeros(36)


@dataclass
@annotate.final
class Imu(IdlStruct, typename=_name('sensor_msgs', 'msg', 'Imu')):
    header: Header = field(default_factory=Header)
    orientation: Quaternion = field(default_factory=Quaternion)
    orientation_covariance: array[float64, 9] = _zeros(9)
    angular_velocity: Vector3 = field(default_factory=Vector3)
    angular_velocity_covariance: array[float64, 9] = _zeros(9)
    linear_acceleration: Vector3 = field(default_factory=Vector3)
    linear_acceleration_covariance: array[float64, 9] = _zeros(9)


@dataclass
@annotate.final
class NavSatStatus(IdlStruct, typename=_name('sensor_msgs', 'msg', 'NavSatStatus')):
    status: int8 = 0
    service: uint16 = 0


@dataclass
@annotate.final
class NavSatFix(IdlStruct, typename=_name('sensor_msgs', 'msg', 'NavSatFix')):
    header: Header = field(default_factory=Header)
    status: NavSatStatus = field(default_factory=NavSatStatus)
    latitude: float64 = 0.0
    longitude: float64 = 0.0
    altitude: float64 = 0.0
    position_covariance: array[float64, 9] = _zeros(9)
    position_covariance_type: uint8 = 0


@dataclass
@annotate.final
class Odometry(IdlStruct, typename=_name('nav_msgs', 'msg', 'Odometry')):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ''
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@dataclass
@annotate.final
class KeyValue(IdlStruct, typename=_name('diagnostic_msgs', 'msg', 'KeyValue')):
    key: str = ''
    value: str = ''


@dataclass
@annotate.final
class DiagnosticStatus(IdlStruct, typename=_name('diagnostic_msgs', 'msg', 'DiagnosticStatus')):
    level: uint8 = 0
    name: str = ''
    message: str = ''
    hardware_id: str = ''
    values: sequence[KeyValue] = field(default_factory=list)


@dataclass
@annotate.final
class DiagnosticArray(IdlStruct, typename=_name('diagnostic_msgs', 'msg', 'DiagnosticArray')):
    header: Header = field(default_factory=Header)
    status: sequence[DiagnosticStatus] = field(default_factory=list)


@dataclass
@annotate.final
class Clock(IdlStruct, typename=_name('rosgraph_msgs', 'msg', 'Clock')):
    clock: Time = field(default_factory=Time)


@dataclass
@annotate.final
class Log(IdlStruct, typename=_name('rcl_interfaces', 'msg', 'Log')):
    stamp: Time = field(default_factory=Time)
    level: uint8 = 0
    name: str = ''
    msg: str = ''
    file: str = ''
    function: str = ''
    line: uint32 = 0


# --- adaptive_gnss_ins/msg (this repository's msg/) ---

@dataclass
@annotate.final
class SatelliteMeasurement(IdlStruct,
                           typename=_name('adaptive_gnss_ins', 'msg', 'SatelliteMeasurement')):
    constellation: uint8 = 0
    prn: uint16 = 0
    pseudorange_m: float64 = 0.0
    pseudorange_rate_mps: float64 = 0.0
    pseudorange_sigma_m: float64 = 0.0
    pseudorange_rate_sigma_mps: float64 = 0.0
    cn0_dbhz: float32 = 0.0
    satellite_position_ecef_m: Point = field(default_factory=Point)
    satellite_velocity_ecef_mps: Vector3 = field(default_factory=Vector3)
    satellite_clock_bias_s: float64 = 0.0
    satellite_clock_drift_s_s: float64 = 0.0
    ionosphere_delay_m: float64 = 0.0
    troposphere_delay_m: float64 = 0.0
    carrier_phase_cycles: float64 = 0.0
    carrier_wavelength_m: float64 = 0.0
    carrier_phase_sigma_cycles: float64 = 0.0
    carrier_lock_time_s: float64 = 0.0
    carrier_phase_flags: uint8 = 0


@dataclass
@annotate.final
class GnssMeasurements(IdlStruct, typename=_name('adaptive_gnss_ins', 'msg', 'GnssMeasurements')):
    header: Header = field(default_factory=Header)
    gps_week: uint16 = 0
    gps_time_of_week_s: float64 = 0.0
    satellites: sequence[SatelliteMeasurement] = field(default_factory=list)
    klobuchar_alpha: array[float64, 4] = _zeros(4)
    klobuchar_beta: array[float64, 4] = _zeros(4)


@dataclass
@annotate.final
class SatelliteNoise(IdlStruct, typename=_name('adaptive_gnss_ins', 'msg', 'SatelliteNoise')):
    constellation: uint8 = 0
    prn: uint16 = 0
    elevation_deg: float64 = 0.0
    used: bool = False
    rejection_reason: uint8 = 0
    innovation_pseudorange_m: float64 = 0.0
    innovation_pseudorange_rate_mps: float64 = 0.0
    normalized_innovation_pseudorange: float64 = 0.0
    normalized_innovation_pseudorange_rate: float64 = 0.0
    r_pseudorange_m2: float64 = 0.0
    r_pseudorange_rate_m2_s2: float64 = 0.0
    kde_credibility: float64 = 0.0
    gaussian: bool = False
    ar_order: uint8 = 0
    robust_weight: float64 = 0.0


@dataclass
@annotate.final
class NoiseEstimates(IdlStruct, typename=_name('adaptive_gnss_ins', 'msg', 'NoiseEstimates')):
    header: Header = field(default_factory=Header)
    filter_variant: str = ''
    satellites: sequence[SatelliteNoise] = field(default_factory=list)
    adaptive_factor: float64 = 0.0
    mahalanobis_d2: float64 = 0.0
    chi2_threshold: float64 = 0.0
    q_scale: float64 = 0.0
    nis: float64 = 0.0


# --- rcl_interfaces: parameters and their services ---

class ParameterType:
    """rcl_interfaces/msg/ParameterType constants."""
    NOT_SET = 0
    BOOL = 1
    INTEGER = 2
    DOUBLE = 3
    STRING = 4
    BYTE_ARRAY = 5
    BOOL_ARRAY = 6
    INTEGER_ARRAY = 7
    DOUBLE_ARRAY = 8
    STRING_ARRAY = 9


@dataclass
@annotate.final
class ParameterValue(IdlStruct, typename=_name('rcl_interfaces', 'msg', 'ParameterValue')):
    type: uint8 = 0
    bool_value: bool = False
    integer_value: int64 = 0
    double_value: float64 = 0.0
    string_value: str = ''
    byte_array_value: sequence[uint8] = field(default_factory=list)
    bool_array_value: sequence[bool] = field(default_factory=list)
    integer_array_value: sequence[int64] = field(default_factory=list)
    double_array_value: sequence[float64] = field(default_factory=list)
    string_array_value: sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class Parameter(IdlStruct, typename=_name('rcl_interfaces', 'msg', 'Parameter')):
    name: str = ''
    value: ParameterValue = field(default_factory=ParameterValue)


@dataclass
@annotate.final
class ParameterEvent(IdlStruct, typename=_name('rcl_interfaces', 'msg', 'ParameterEvent')):
    stamp: Time = field(default_factory=Time)
    node: str = ''
    new_parameters: sequence[Parameter] = field(default_factory=list)
    changed_parameters: sequence[Parameter] = field(default_factory=list)
    deleted_parameters: sequence[Parameter] = field(default_factory=list)


@dataclass
@annotate.final
class SetParametersResult(IdlStruct,
                          typename=_name('rcl_interfaces', 'msg', 'SetParametersResult')):
    successful: bool = False
    reason: str = ''


@dataclass
@annotate.final
class FloatingPointRange(IdlStruct, typename=_name('rcl_interfaces', 'msg', 'FloatingPointRange')):
    from_value: float64 = 0.0
    to_value: float64 = 0.0
    step: float64 = 0.0


@dataclass
@annotate.final
class IntegerRange(IdlStruct, typename=_name('rcl_interfaces', 'msg', 'IntegerRange')):
    from_value: int64 = 0
    to_value: int64 = 0
    step: uint64 = 0


@dataclass
@annotate.final
class ParameterDescriptor(IdlStruct,
                          typename=_name('rcl_interfaces', 'msg', 'ParameterDescriptor')):
    name: str = ''
    type: uint8 = 0
    description: str = ''
    additional_constraints: str = ''
    read_only: bool = False
    dynamic_typing: bool = False
    floating_point_range: sequence[FloatingPointRange] = field(default_factory=list)
    integer_range: sequence[IntegerRange] = field(default_factory=list)


@dataclass
@annotate.final
class ListParametersResult(IdlStruct,
                           typename=_name('rcl_interfaces', 'msg', 'ListParametersResult')):
    names: sequence[str] = field(default_factory=list)
    prefixes: sequence[str] = field(default_factory=list)


# Service payloads as rmw_cyclonedds writes them: a request header (the client's GUID,
# of which the server echoes the lower 8 bytes, and a sequence number) before the fields.

@dataclass
@annotate.final
class ListParametersRequest(IdlStruct,
                            typename=_name('rcl_interfaces', 'srv', 'ListParameters_Request')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    prefixes: sequence[str] = field(default_factory=list)
    depth: uint64 = 0


@dataclass
@annotate.final
class ListParametersResponse(IdlStruct,
                             typename=_name('rcl_interfaces', 'srv', 'ListParameters_Response')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    result: ListParametersResult = field(default_factory=ListParametersResult)


@dataclass
@annotate.final
class GetParametersRequest(IdlStruct,
                           typename=_name('rcl_interfaces', 'srv', 'GetParameters_Request')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    names: sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class GetParametersResponse(IdlStruct,
                            typename=_name('rcl_interfaces', 'srv', 'GetParameters_Response')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    values: sequence[ParameterValue] = field(default_factory=list)


@dataclass
@annotate.final
class GetParameterTypesRequest(IdlStruct, typename=_name('rcl_interfaces', 'srv',
                                                         'GetParameterTypes_Request')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    names: sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class GetParameterTypesResponse(IdlStruct, typename=_name('rcl_interfaces', 'srv',
                                                          'GetParameterTypes_Response')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    types: sequence[uint8] = field(default_factory=list)


@dataclass
@annotate.final
class SetParametersRequest(IdlStruct,
                           typename=_name('rcl_interfaces', 'srv', 'SetParameters_Request')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    parameters: sequence[Parameter] = field(default_factory=list)


@dataclass
@annotate.final
class SetParametersResponse(IdlStruct,
                            typename=_name('rcl_interfaces', 'srv', 'SetParameters_Response')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    results: sequence[SetParametersResult] = field(default_factory=list)


@dataclass
@annotate.final
class DescribeParametersRequest(IdlStruct, typename=_name('rcl_interfaces', 'srv',
                                                          'DescribeParameters_Request')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    names: sequence[str] = field(default_factory=list)


@dataclass
@annotate.final
class DescribeParametersResponse(IdlStruct, typename=_name('rcl_interfaces', 'srv',
                                                           'DescribeParameters_Response')):
    client_guid: uint64 = 0
    sequence_number: int64 = 0
    descriptors: sequence[ParameterDescriptor] = field(default_factory=list)


__all__ = [name for name in dir() if not name.startswith('_')]
