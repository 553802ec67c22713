#!/usr/bin/env python3
"""A genuine ROS 2 Jazzy node (rclpy on Fast DDS) plays a loosely-coupled bag into
gnss_ins_node and checks what the node publishes against `gnss_ins replay` of the same bag.

Usage: jazzy_bag_peer.py --bag BAG --replay REPLAY --namespace NS --node NAME [--speed X]
                         [--sim-time]

Publishes the bag's /imu (sensor_msgs/Imu), /gnss/fix (sensor_msgs/NavSatFix) and
/gnss/velocity (geometry_msgs/TwistWithCovarianceStamped), decoded by rclpy from the bag and
paced at X times real time, to the node under NS, and subscribes the node's `odometry`,
`fix`, /diagnostics and /rosout. Every Odometry and NavSatFix must equal, field by field and
to the bit, the one of its stamp in REPLAY (the bag `gnss_ins replay --out` wrote with the
same parameters), but those the node published before a fix that came late arrived
(tools/replay_match.py), and none may be missing or extra. With `--sim-time` the peer also
publishes the bag's time on /clock (rosgraph_msgs/Clock, as `ros2 bag play --clock`) with
odd nanoseconds added, and checks that the node (run with use_sim_time) stamps /diagnostics
and /rosout with exactly the times it sent.

Prints a JSON summary on stdout, every failed check on stderr, and exits 1 if any failed.
See tools/jazzy_common.py for the environment.
"""

import importlib.metadata
import math
import sys
import time
from array import array
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from jazzy_common import (  # noqa: E402  (the tools directory is not a package)
    Checks, JazzyNode, argument_parser, diagnostic_values, handshake, node_fqn,
    own_diagnostics, read_bag, reliable, report, ros_time, rosout_reader, stamp_ns,
    unconvertible_fix, unconvertible_imu, wait_until)
from replay_match import check_late_runs  # noqa: E402

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import TwistWithCovarianceStamped  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rcl_interfaces.msg import Log  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import Imu, NavSatFix  # noqa: E402

INPUTS = {'/imu': Imu, '/gnss/fix': NavSatFix, '/gnss/velocity': TwistWithCovarianceStamped}
OUTPUTS = {'/odometry': Odometry, '/fix/filtered': NavSatFix}
# The bag's time goes on /clock every this many IMU samples.
CLOCK_EVERY_IMU = 10
# Added to the bag time on /clock, so that a node converting it through f64 seconds would
# be seen.
CLOCK_ODD_NS = 1
LOG_INFO = 20
# Wall time between a fix (and its velocity) and the next IMU sample. Choice: DDS orders
# the samples of one writer only. A fix that arrives after later IMU samples is applied by
# a roll-back, and only the solutions published meanwhile differ from replay (allowed, see
# tools/replay_match.py); but a fix whose velocity comes more than the pairing's wait
# (0.2 s of IMU time, 50 ms of wall time at 4x) after it goes on alone, which is another
# solution from then on. At 4 times real time the bag leaves 2.5 ms between a fix and the
# next IMU sample; the gap keeps both messages ahead of the IMU on a loaded machine.
GNSS_GAP_S = 0.02


class Peer:
    """The rclpy node with the node's inputs and outputs."""

    def __init__(self, namespace, node):
        self.jazzy = JazzyNode('jazzy_bag_peer')
        n, ns = self.jazzy.node, namespace.rstrip('/')
        depth = 10_000
        self.publishers = {topic: n.create_publisher(kind, f'{ns}{topic}', reliable(1000))
                           for topic, kind in INPUTS.items()}
        self.clock = n.create_publisher(Clock, '/clock', reliable(100))
        self.jazzy.subscribe('odometry', Odometry, f'{ns}/odometry', reliable(depth))
        self.jazzy.subscribe('fix', NavSatFix, f'{ns}/fix/filtered', reliable(depth))
        self.jazzy.subscribe('diagnostics', DiagnosticArray, '/diagnostics', reliable(depth))
        self.jazzy.subscribe('rosout', Log, '/rosout', rosout_reader())
        self.fqn = node_fqn(namespace, node)
        self.jazzy.start()

    def matched(self):
        r = self.jazzy.node
        return (all(p.get_subscription_count() > 0 for p in self.publishers.values())
                and all(s.get_publisher_count() > 0 for s in r.subscriptions
                        if s.topic_name != '/rosout'))

    def handshake(self, checks):
        bad_velocity = TwistWithCovarianceStamped()
        bad_velocity.twist.twist.linear.x = math.nan
        p = self.publishers
        return handshake(self.jazzy, self.fqn, [
            (p['/imu'], unconvertible_imu(), 'unconvertible_imu'),
            (p['/gnss/fix'], unconvertible_fix(), 'unconvertible_fix'),
            (p['/gnss/velocity'], bad_velocity, 'unconvertible_velocity')], checks)


def stream(peer, inputs, speed, sim_time):
    """Publishes the inputs paced at `speed` times real time, the IMU sample after a fix at
    least GNSS_GAP_S later; returns the counts per topic and the /clock times sent (ns)."""
    sent = {topic: 0 for topic in INPUTS}
    clocks_ns = []
    t0_ns, start = inputs[0][0], time.monotonic()
    previous = '/imu'
    for t_ns, topic, message in inputs:
        wait = (t_ns - t0_ns) * 1e-9 / speed - (time.monotonic() - start)
        if topic == '/imu' and previous != '/imu':
            wait = max(wait, GNSS_GAP_S)
        previous = topic
        if wait > 0:
            time.sleep(wait)
        peer.publishers[topic].publish(message)
        sent[topic] += 1
        if sim_time and topic == '/imu' and sent[topic] % CLOCK_EVERY_IMU == 0:
            clocks_ns.append(stamp_ns(message.header.stamp) + CLOCK_ODD_NS)
            peer.clock.publish(Clock(clock=ros_time(clocks_ns[-1])))
    return sent, clocks_ns


def odometry_fields(o):
    """The numbers of an Odometry (as float64) and its frames."""
    p, q = o.pose.pose.position, o.pose.pose.orientation
    v, w = o.twist.twist.linear, o.twist.twist.angular
    numbers = ([p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z]
               + list(o.pose.covariance) + list(o.twist.covariance))
    return array('d', numbers), (o.header.frame_id, o.child_frame_id)


def fix_fields(f):
    """The numbers of a NavSatFix (as float64) and its frame."""
    numbers = ([f.latitude, f.longitude, f.altitude, f.status.status, f.status.service,
                f.position_covariance_type] + list(f.position_covariance))
    return array('d', numbers), (f.header.frame_id,)


def compare(checks, what, received, expected, fields, measurement_s, late):
    """Every expected message (by stamp) arrives once and equals the received one to the
    bit (`fields` gives the numbers and the frames of a message), but those published
    before a late measurement arrived (tools/replay_match.py)."""
    by_stamp = {}
    for m in received:
        by_stamp.setdefault(stamp_ns(m.header.stamp), []).append(m)
    repeated = sum(len(v) - 1 for v in by_stamp.values())
    missing, worst, compared = 0, 0.0, []
    for m in expected:
        t = stamp_ns(m.header.stamp)
        got = by_stamp.pop(t, [None])[0]
        if got is None:
            missing += 1
            continue
        (a, a_frames), (b, b_frames) = fields(got), fields(m)
        differs = a.tobytes() != b.tobytes() or a_frames != b_frames
        compared.append((t * 1e-9, differs))
        if differs:
            worst = max([worst] + [abs(x - y) for x, y in zip(a, b, strict=True)
                                   if not (math.isnan(x) or math.isnan(y))])
    checks.that(missing == 0, f'{what}: {missing} of the {len(expected)} replay messages missing')
    checks.that(not by_stamp, f'{what}: {len(by_stamp)} stamps that replay does not have')
    checks.that(repeated == 0, f'{what}: {repeated} stamps received more than once')
    runs = check_late_runs(checks, what, compared, measurement_s, late)
    return {'received': len(received), 'replay': len(expected), 'missing': missing,
            'differing': sum(differs for _, differs in compared), 'late_runs': runs,
            'largest_difference': worst}


def check_sim_time(checks, peer, clocks_ns, imu_rate_hz):
    """With use_sim_time the node's /diagnostics carry exactly the /clock times sent, in
    order, and the IMU rate is counted on that time (the bag's rate, not the faster wall
    rate)."""
    sent = set(clocks_ns)
    own = own_diagnostics(peer.jazzy, peer.fqn)
    stamps = [stamp_ns(m.header.stamp) for m in own]
    on_clock = [t for t in stamps if t in sent]
    checks.that(len(on_clock) >= 3, f'{len(on_clock)} diagnostics stamped with a /clock time')
    checks.that(all(t in sent or t == 0 for t in stamps),
                f'diagnostics stamps not sent on /clock: {[t for t in stamps if t not in sent]}')
    checks.that(stamps == sorted(stamps), 'diagnostics stamps go backwards')
    checks.that(stamps and stamps[-1] == clocks_ns[-1],
                f'the last diagnostics is stamped {stamps[-1:]}, the last /clock {clocks_ns[-1]}')
    rates = sorted(float(diagnostic_values(m).get('imu_rate_hz', 0.0)) for m in own
                   if stamp_ns(m.header.stamp) in sent)
    median = rates[len(rates) // 2] if rates else math.nan
    checks.that(abs(median - imu_rate_hz) <= 0.1 * imu_rate_hz,
                f'median imu_rate_hz {median} on sim time, the bag has {imu_rate_hz} Hz')
    return {'clocks_sent': len(clocks_ns), 'diagnostics': len(stamps),
            'diagnostics_on_clock': len(on_clock), 'imu_rate_hz_median': median}


def check_rosout(checks, peer, clocks_ns):
    """The node's log lines arrive on /rosout under its logger name; with sim time the
    "filter initialized" line is stamped with a /clock time sent."""
    logger = peer.fqn.strip('/').replace('/', '.')
    own = [x for x in peer.jazzy.messages('rosout') if x.name == logger]
    checks.that(own, f'no /rosout line from {logger}')
    started = [x for x in own if x.level == LOG_INFO and 'filter initialized' in x.msg]
    checks.that(started, 'no /rosout INFO line "filter initialized"')
    if clocks_ns and started:
        t = stamp_ns(started[0].stamp)
        checks.that(t in set(clocks_ns), f'/rosout "filter initialized" stamped {t} ns, '
                                         'not a /clock time sent')
    return {'lines': len(own), 'levels': sorted({x.level for x in own})}


def main():
    parser = argument_parser(__doc__)
    parser.add_argument('--bag', required=True)
    parser.add_argument('--replay', required=True)
    parser.add_argument('--speed', type=float, default=4.0)
    parser.add_argument('--sim-time', action='store_true',
                        help='publish the bag time on /clock; the node runs with use_sim_time')
    args = parser.parse_args()

    inputs = read_bag(args.bag, INPUTS)
    replayed = read_bag(args.replay, OUTPUTS)
    peer = Peer(args.namespace, args.node)
    try:
        return run(args, peer, inputs, replayed)
    finally:
        peer.jazzy.close()


def run(args, peer, inputs, replayed):
    checks = Checks()
    summary = {'rmw': peer.jazzy.rmw(), 'rclpy': importlib.metadata.version('ros-rclpy'),
               'fastdds': importlib.metadata.version('ros-fastrtps')}
    checks.that(summary['rmw'] == 'rmw_fastrtps_cpp', f'middleware {summary["rmw"]}')
    if not (checks.that(wait_until(peer.matched, 30.0), 'the node was not discovered in 30 s')
            and peer.handshake(checks)):
        return report(summary, checks)
    for key in ('odometry', 'fix', 'diagnostics'):
        peer.jazzy.received[key].clear()
    start = time.monotonic()
    summary['sent'], clocks_ns = stream(peer, inputs, args.speed, args.sim_time)
    summary['stream_wall_s'] = time.monotonic() - start
    expected_odometry = [m for _, t, m in replayed if t == '/odometry']
    expected_fix = [m for _, t, m in replayed if t == '/fix/filtered']

    def complete():
        done = len(peer.jazzy.received['odometry']) >= len(expected_odometry)
        if clocks_ns:
            done = done and any(stamp_ns(m.header.stamp) == clocks_ns[-1]
                                for m in peer.jazzy.messages('diagnostics'))
        return done
    wait_until(complete, 10.0)
    time.sleep(0.2)  # anything extra still in flight
    measurement_s = [stamp_ns(m.header.stamp) * 1e-9 for _, t, m in inputs if t == '/gnss/fix']
    own = own_diagnostics(peer.jazzy, node_fqn(args.namespace, args.node))
    late = int(diagnostic_values(own[-1]).get('late_measurements', 0)) if own else 0
    summary['late_measurements'] = late
    summary['odometry'] = compare(checks, 'Odometry', peer.jazzy.messages('odometry'),
                                  expected_odometry, odometry_fields, measurement_s, late)
    summary['fix'] = compare(checks, 'NavSatFix', peer.jazzy.messages('fix'), expected_fix,
                             fix_fields, measurement_s, late)
    checks.that(len(expected_odometry) > 1000, f'replay has {len(expected_odometry)} Odometry')
    if args.sim_time:
        imu_ns = [t for t, topic, _ in inputs if topic == '/imu']
        imu_rate_hz = (len(imu_ns) - 1) / ((imu_ns[-1] - imu_ns[0]) * 1e-9)
        summary['sim_time'] = check_sim_time(checks, peer, clocks_ns, imu_rate_hz)
    summary['rosout'] = check_rosout(checks, peer, clocks_ns)
    return report(summary, checks)


if __name__ == '__main__':
    sys.exit(main())
