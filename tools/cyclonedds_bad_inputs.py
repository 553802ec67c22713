#!/usr/bin/env python3
"""Bad input for gnss_ins_node over Cyclone DDS: the node must count it in /diagnostics,
stay up, and publish no NaN.

Usage: cyclonedds_bad_inputs.py --bag BAG --namespace NS --node NAME [--speed X]

In this order, against a freshly started node:
 1. a GNSS epoch before any IMU sample, and an epoch whose time of week is NaN;
 2. undecodable payloads from a second participant whose types carry the ROS names but
    the wrong layout: an Imu cut after its header, a GnssMeasurements claiming 10^9
    satellites, a NavSatFix whose covariance has 8 elements instead of 9;
 3. the bag's IMU and GNSS streams (at X times real time) interleaved with: IMU samples
    with NaN, IMU stamps repeated and going 0.5 s backwards, and a second IMU publisher
    with another frame_id;
then checks every counter of /diagnostics against what was sent, that the filter runs,
and that every Odometry and NavSatFix is finite. Prints a JSON summary; exit 1 on failure.
Run it inside a loopback-only network namespace with the venv of
scripts/setup_test_peers.sh, ROS_DOMAIN_ID naming the node's domain.
"""

import copy
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import cyclonedds.idl.annotations as annotate
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, uint8, uint16, uint32
from cyclonedds.pub import DataWriter

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cyclonedds_ros_types as ros  # noqa: E402
from cyclonedds_peer import (  # noqa: E402
    Checks, Peer, paced, peer_argument_parser, read_bag, report, wait_until)
import cyclonedds_setup as dds  # noqa: E402

# Malformed messages sent of each kind, and the stream's bad-sample period.
MALFORMED_EACH = 5
BAD_EVERY_IMU = 200
WRONG_FRAME = 'second_imu_link'


@dataclass
@annotate.final
class TruncatedImu(IdlStruct, typename='sensor_msgs::msg::dds_::Imu_'):
    """An Imu that ends after its header."""
    header: ros.Header = field(default_factory=ros.Header)


@dataclass
@annotate.final
class LyingGnss(IdlStruct, typename='adaptive_gnss_ins::msg::dds_::GnssMeasurements_'):
    """A GnssMeasurements whose satellite count promises far more than follows."""
    header: ros.Header = field(default_factory=ros.Header)
    gps_week: uint16 = 0
    gps_time_of_week_s: float64 = 0.0
    satellite_count: uint32 = 1_000_000_000


@dataclass
@annotate.final
class ShortCovarianceFix(IdlStruct, typename='sensor_msgs::msg::dds_::NavSatFix_'):
    """A NavSatFix with 8 covariance elements instead of 9."""
    header: ros.Header = field(default_factory=ros.Header)
    status: ros.NavSatStatus = field(default_factory=ros.NavSatStatus)
    latitude: float64 = 0.0
    longitude: float64 = 0.0
    altitude: float64 = 0.0
    position_covariance: array[float64, 8] = field(default_factory=lambda: [0.0] * 8)
    position_covariance_type: uint8 = 0


def counter(peer, key):
    return int(peer.latest_diagnostics().get(key, 0))


def wait_for_count(peer, key, at_least, timeout_s=10.0):
    return wait_until(lambda: counter(peer, key) >= at_least, timeout_s, 0.2)


def send_until_counted(peer, write, key, checks):
    """Repeats `write` until the node's `key` counter moves (the node's best-effort
    readers drop what comes before they match the writer); returns the writes made."""
    before = counter(peer, key)
    writes = 0
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        write()
        writes += 1
        time.sleep(0.25)
        if counter(peer, key) > before:
            return writes
    checks.that(False, f'{key} never counted')
    return writes


def main():
    args = peer_argument_parser(__doc__, default_speed=4.0).parse_args()
    checks = Checks()
    summary = {}
    inputs, _, _ = read_bag(args.bag)
    peer = Peer(args.namespace, args.node)
    ns = args.namespace.rstrip('/')
    qos = dds.xcdr1_qos(depth=1000)
    # The malformed types need their own participant: one participant has one type per
    # topic.
    liar = DomainParticipant(peer.participant.domain_id)
    bad_imu = dds.writer(liar, f'rt{ns}/imu', TruncatedImu, qos)
    bad_gnss = dds.writer(liar, f'rt{ns}/gnss/measurements', LyingGnss, qos)
    bad_fix = dds.writer(liar, f'rt{ns}/gnss/fix', ShortCovarianceFix, qos)
    second_imu = DataWriter(peer.participant, peer.imu.topic, qos=qos)
    if not checks.that(wait_until(peer.matched, 30.0), 'the node was not discovered'):
        return report(summary, checks)

    # 1. GNSS before any IMU: it waits for the IMU (counted as received, nothing rejected);
    # an epoch with a NaN time of week does not convert. The first write of each also proves
    # the path is matched at the node's end.
    first_gnss = next(m for _, topic, m in inputs if topic == '/gnss/measurements')
    early = send_until_counted(peer, lambda: peer.gnss.write(first_gnss), 'gnss_received',
                               checks)
    nan_epoch = copy.deepcopy(first_gnss)
    nan_epoch.gps_time_of_week_s = math.nan
    nan_writes = send_until_counted(peer, lambda: peer.gnss.write(nan_epoch),
                                    'unconvertible_gnss', checks)
    summary['early_gnss_writes'] = early
    summary['nan_epoch_writes'] = nan_writes

    # 2. Undecodable payloads, each path matched first, then MALFORMED_EACH more.
    sent_undecodable = 0
    for writer, sample in ((bad_imu, TruncatedImu()), (bad_gnss, LyingGnss()),
                           (bad_fix, ShortCovarianceFix())):
        sent_undecodable += send_until_counted(peer, lambda: writer.write(sample),
                                               'undecodable', checks)
    base_undecodable = counter(peer, 'undecodable')
    for _ in range(MALFORMED_EACH):
        for writer, sample in ((bad_imu, TruncatedImu()), (bad_gnss, LyingGnss()),
                               (bad_fix, ShortCovarianceFix())):
            writer.write(sample)
    checks.that(wait_for_count(peer, 'undecodable', base_undecodable + 3 * MALFORMED_EACH),
                f'undecodable: {counter(peer, "undecodable")}, expected '
                f'{base_undecodable + 3 * MALFORMED_EACH}')

    # 3. The bag with bad samples woven in.
    bad = {'nan': 0, 'duplicate': 0, 'backwards': 0, 'foreign_frame': 0}
    peer.received['odometry'].clear()
    peer.received['fix'].clear()
    imu_count = 0
    for _, topic, message in paced(inputs, args.speed, switch_gap_s=0.02):
        if topic != '/imu':
            peer.gnss.write(message)
            continue
        peer.imu.write(message)
        imu_count += 1
        if imu_count % BAD_EVERY_IMU == 0 and seconds_of(message) > 1.0:
            nan = copy.deepcopy(message)
            nan.linear_acceleration.z = math.nan
            nan.header.stamp.nanosec = (nan.header.stamp.nanosec + 1000) % 1_000_000_000
            duplicate = copy.deepcopy(message)
            backwards = copy.deepcopy(message)
            backwards.header.stamp.sec -= 1
            backwards.header.stamp.nanosec = (backwards.header.stamp.nanosec + 500_000_000)
            if backwards.header.stamp.nanosec >= 1_000_000_000:
                backwards.header.stamp.sec += 1
                backwards.header.stamp.nanosec -= 1_000_000_000
            foreign = copy.deepcopy(message)
            foreign.header.frame_id = WRONG_FRAME
            for kind, writer, sample in (('nan', peer.imu, nan),
                                         ('duplicate', peer.imu, duplicate),
                                         ('backwards', peer.imu, backwards),
                                         ('foreign_frame', second_imu, foreign)):
                time.sleep(0.005)
                writer.write(sample)
                bad[kind] += 1
    summary['bad_samples_sent'] = bad
    time.sleep(2.5)
    peer.drain()
    values = peer.latest_diagnostics()
    summary['diagnostics'] = values
    expected = {
        'rejected_imu_duplicate_stamp': bad['duplicate'],
        'unconvertible_imu': bad['nan'],
        'unconvertible_gnss': nan_writes,
        'rejected_imu_out_of_order': bad['backwards'],
        'foreign_frame_imu': bad['foreign_frame'],
        'time_jump_resets': 0,
        'non_finite_outputs': 0,
    }
    for key, count in expected.items():
        checks.that(int(values.get(key, -1)) == count, f'{key} = {values.get(key)}, '
                                                       f'expected {count}')
    checks.that(values.get('phase') == 'running', f'phase {values.get("phase")!r}')
    odometry, fixes = peer.received['odometry'], peer.received['fix']
    checks.that(len(odometry) > 2000, f'only {len(odometry)} Odometry')
    for o in odometry:
        p, q = o.pose.pose.position, o.pose.pose.orientation
        numbers = [p.x, p.y, p.z, q.x, q.y, q.z, q.w] + list(o.pose.covariance) + \
            list(o.twist.covariance)
        if not checks.that(all(math.isfinite(v) for v in numbers), 'NaN in Odometry'):
            break
    for f in (f for f in fixes if f.status.status != -1):  # NO_FIX (NaN) while starting
        numbers = [f.latitude, f.longitude, f.altitude] + list(f.position_covariance)
        if not checks.that(all(math.isfinite(v) for v in numbers), 'NaN in NavSatFix'):
            break
    summary['odometry'] = len(odometry)
    summary['fix'] = len(fixes)
    return report(summary, checks)


def seconds_of(message):
    return message.header.stamp.sec + message.header.stamp.nanosec * 1e-9


if __name__ == '__main__':
    sys.exit(main())
