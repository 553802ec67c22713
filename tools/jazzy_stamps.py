#!/usr/bin/env python3
"""Stamps and latency through gnss_ins_node, driven by a genuine ROS 2 Jazzy rclpy node.

Usage: jazzy_stamps.py --namespace NS --node NAME [--duration-s S] [--exact-stamps]

Publishes, in real time, a 200 Hz sensor_msgs/Imu of a device at rest (sensor-data QoS, as
IMU drivers do) stamped in this decade at x.0025 s, x.0075 s, ... with every other stamp one
nanosecond later (…2500001 ns), and a 5 Hz sensor_msgs/NavSatFix stamped at x.0 s, x.2 s,
... plus one nanosecond, to the node under NS (run loosely coupled with a given heading:
`-p filter.coupling:=loose -p init.heading_deg:=90.0`). Subscribes `odometry` and `fix/filtered` and
measures, for every output, how its stamp compares with the nearest input stamp (each output
is computed at an IMU sample) and the latency from publishing that Imu to receiving its
Odometry (p50/p90/p99/max, including rclpy's own publish and take).

Checks: every IMU sample from the first Odometry on gets exactly one Odometry and one
NavSatFix, each within 1 us of its stamp (f64 seconds at 1.75e9 s round to 119 ns at most).
With `--exact-stamps` every output stamp must equal its IMU stamp to the nanosecond.
The latency is reported, not checked (a benchmark, not a test, judges speed).

Prints a JSON summary on stdout, every failed check on stderr, and exits 1 if any failed.
See tools/jazzy_common.py for the environment.
"""

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from jazzy_common import (  # noqa: E402  (the tools directory is not a package)
    SECOND_NS, Checks, JazzyNode, argument_parser, handshake, node_fqn, reliable, report,
    ros_time, stamp_ns, unconvertible_fix, unconvertible_imu, wait_until)

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import Imu, NavSatFix  # noqa: E402

# 2025-06-15: f64 seconds resolve 238 ns here, not the nanoseconds of the stamps.
EPOCH_NS = 1_750_000_000 * SECOND_NS
IMU_PERIOD_NS = 5_000_000
IMU_OFFSET_NS = 2_500_000
FIX_PERIOD_NS = 200_000_000
FIX_OFFSET_NS = 1
# An output farther than this from every input stamp was not computed at one.
NEAR_NS = 1_000
GRAVITY_MPS2 = 9.80
DATUM = (39.10, 117.20, 10.0)


def imu_stamp_ns(k):
    """x.0025 s, x.0075 s, ...; odd k one nanosecond later."""
    return EPOCH_NS + IMU_OFFSET_NS + k * IMU_PERIOD_NS + k % 2


def imu_at(k):
    imu = Imu()
    imu.header.stamp = ros_time(imu_stamp_ns(k))
    imu.header.frame_id = 'base_link'
    imu.orientation_covariance[0] = -1.0  # no orientation estimate
    imu.linear_acceleration.z = GRAVITY_MPS2
    return imu


def fix_at(t_ns):
    fix = NavSatFix()
    fix.header.stamp = ros_time(t_ns)
    fix.header.frame_id = 'gnss'
    fix.status.status, fix.status.service = fix.status.STATUS_FIX, fix.status.SERVICE_GPS
    fix.latitude, fix.longitude, fix.altitude = DATUM
    fix.position_covariance[0] = fix.position_covariance[4] = 1.5 ** 2
    fix.position_covariance[8] = 3.0 ** 2
    fix.position_covariance_type = fix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    return fix


def stream(imu, gnss, duration_s):
    """Publishes in real time; returns {k: perf_counter_ns just before publishing Imu k}."""
    published = {}
    count = int(duration_s * SECOND_NS / IMU_PERIOD_NS)
    start = time.monotonic()
    # The first fix after the first IMU sample: the filter has nothing before that.
    next_fix_ns = FIX_PERIOD_NS + FIX_OFFSET_NS
    for k in range(count):
        wait = k * IMU_PERIOD_NS * 1e-9 - (time.monotonic() - start)
        if wait > 0:
            time.sleep(wait)
        published[k] = time.perf_counter_ns()
        imu.publish(imu_at(k))
        # A fix follows the first IMU sample after its stamp, as a receiver's fix comes
        # after the IMU samples of its time.
        if EPOCH_NS + next_fix_ns <= imu_stamp_ns(k):
            gnss.publish(fix_at(EPOCH_NS + next_fix_ns))
            next_fix_ns += FIX_PERIOD_NS
    return published


def nearest_imu(t_ns):
    """The index of the IMU stamp nearest `t_ns` and the difference (ns)."""
    k = round((t_ns - EPOCH_NS - IMU_OFFSET_NS) / IMU_PERIOD_NS)
    return k, t_ns - imu_stamp_ns(k)


def percentile(sorted_values, p):
    return sorted_values[min(len(sorted_values) - 1, int(p / 100.0 * len(sorted_values)))]


def stamp_summary(what, outputs, published, exact, checks):
    """Compares every output's stamp with the nearest IMU stamp; by IMU stamp family."""
    families = {'x.0025_s': [], 'x.0025_s_plus_1_ns': []}
    by_k = {}
    for _, message in outputs:
        k, diff_ns = nearest_imu(stamp_ns(message.header.stamp))
        families['x.0025_s_plus_1_ns' if k % 2 else 'x.0025_s'].append(abs(diff_ns))
        by_k.setdefault(k, []).append(diff_ns)
    far = sum(abs(d) > NEAR_NS for diffs in by_k.values() for d in diffs)
    checks.that(far == 0, f'{what}: {far} stamps farther than {NEAR_NS} ns from every IMU stamp')
    repeated = sum(len(d) - 1 for d in by_k.values())
    checks.that(repeated == 0, f'{what}: {repeated} IMU samples with more than one output')
    if checks.that(by_k, f'{what}: none received'):
        first = min(by_k)
        missing = [k for k in range(first, max(published) + 1) if k not in by_k]
        checks.that(not missing, f'{what}: no output for {len(missing)} IMU samples after the '
                                 f'first (the first ones: {missing[:5]})')
    inexact = sum(d != 0 for diffs in by_k.values() for d in diffs)
    if exact:
        checks.that(inexact == 0, f'{what}: {inexact} of {len(outputs)} stamps differ from '
                                  'the IMU stamp they were computed at')
    summary = {'count': len(outputs), 'inexact': inexact}
    for name, diffs in families.items():
        diffs.sort()
        summary[name] = {'count': len(diffs), 'exact': diffs.count(0),
                         'median_abs_ns': percentile(diffs, 50) if diffs else None,
                         'max_abs_ns': diffs[-1] if diffs else None}
    return summary


def latency_summary(odometry, published):
    latencies_ms = sorted((received - published[k]) * 1e-6 for received, k in
                          ((r, nearest_imu(stamp_ns(m.header.stamp))[0]) for r, m in odometry)
                          if k in published)
    if not latencies_ms:
        return {}
    return {'samples': len(latencies_ms), 'p50_ms': percentile(latencies_ms, 50),
            'p90_ms': percentile(latencies_ms, 90), 'p99_ms': percentile(latencies_ms, 99),
            'max_ms': latencies_ms[-1]}


def main():
    parser = argument_parser(__doc__)
    parser.add_argument('--duration-s', type=float, default=10.0)
    parser.add_argument('--exact-stamps', action='store_true',
                        help='fail unless every output carries exactly its IMU stamp')
    args = parser.parse_args()

    checks = Checks()
    fqn, ns = node_fqn(args.namespace, args.node), args.namespace.rstrip('/')
    jazzy = JazzyNode('jazzy_stamps')
    imu = jazzy.node.create_publisher(Imu, f'{ns}/imu', qos_profile_sensor_data)
    gnss = jazzy.node.create_publisher(NavSatFix, f'{ns}/gnss/fix', qos_profile_sensor_data)
    jazzy.subscribe('odometry', Odometry, f'{ns}/odometry', reliable(10_000))
    jazzy.subscribe('fix', NavSatFix, f'{ns}/fix/filtered', reliable(10_000))
    jazzy.subscribe('diagnostics', DiagnosticArray, '/diagnostics', reliable(100))
    jazzy.start()
    try:
        summary = {'rmw': jazzy.rmw()}
        matched = wait_until(lambda: imu.get_subscription_count() > 0
                             and gnss.get_subscription_count() > 0, 30.0)
        if not (checks.that(matched, 'the node was not discovered in 30 s') and handshake(
                jazzy, fqn, [(imu, unconvertible_imu(), 'unconvertible_imu'),
                             (gnss, unconvertible_fix(), 'unconvertible_fix')], checks)):
            return report(summary, checks)
        published = stream(imu, gnss, args.duration_s)
        last_ns = imu_stamp_ns(max(published))
        wait_until(lambda: any(stamp_ns(m.header.stamp) >= last_ns - NEAR_NS
                               for m in jazzy.messages('odometry')), 2.0)
        time.sleep(0.2)
        odometry, fixes = jazzy.received['odometry'], jazzy.received['fix']
        # The fixes before the start say NO_FIX at the GNSS fix's stamp, not an IMU's.
        summary['no_fix'] = sum(m.status.status == m.status.STATUS_NO_FIX for _, m in fixes)
        fixes = [(t, m) for t, m in fixes if m.status.status != m.status.STATUS_NO_FIX]
        summary['imu_published'] = len(published)
        summary['odometry_stamps'] = stamp_summary('Odometry', odometry, published,
                                                   args.exact_stamps, checks)
        summary['fix_stamps'] = stamp_summary('NavSatFix', fixes, published, args.exact_stamps,
                                              checks)
        summary['latency_imu_to_odometry'] = latency_summary(odometry, published)
        return report(summary, checks)
    finally:
        jazzy.close()


if __name__ == '__main__':
    sys.exit(main())
