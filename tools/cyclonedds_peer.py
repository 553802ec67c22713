#!/usr/bin/env python3
"""Independent DDS peer of gnss_ins_node on Eclipse Cyclone DDS (PyPI `cyclonedds`).

Usage: cyclonedds_peer.py --bag BAG --namespace NS --node NAME [--speed X]
                          [--variant NAME] [--golden CSV] [--parameters] [--sim-time]

Plays the /imu and /gnss/measurements messages of a simulated bag (read with `rosbags`,
decoded and re-encoded by Cyclone's own CDR code from the hand-written types of
cyclonedds_ros_types.py) to the node under NS, paced at X times real time, and checks what
the node publishes: `odometry`, `fix`, `~/noise_estimates` and `/diagnostics` (frames,
finite values, covariance shapes, position against the bag's truth within 3 sigma of the
node's own covariance, and with --golden every solution equal to `gnss_ins replay`'s but
those published before a late measurement arrived). With `--parameters` it also lists,
reads, describes and sets the node's parameters through the standard parameter services
(rmw_cyclonedds request/reply mapping; the node must run with
RMW_IMPLEMENTATION=rmw_cyclonedds_cpp). With `--sim-time` it publishes the bag's time
on /clock and checks that the node (run with use_sim_time) stamps its reports with it.
The node's log lines must arrive on /rosout.

Prints a JSON summary on stdout; every failed check on stderr, and exits 1 if any failed.
Run it inside a loopback-only network namespace with the venv of
scripts/setup_test_peers.sh, ROS_DOMAIN_ID naming the node's domain.
"""

import argparse
import csv
import importlib.metadata
import json
import math
import sys
import time
from pathlib import Path

from rosbags.highlevel import AnyReader

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cyclonedds_ros_types as ros  # noqa: E402  (the tools directory is not a package)
from cyclonedds_setup import reader, ros_domain_participant, writer, xcdr1_qos  # noqa: E402
from replay_match import check_late_runs  # noqa: E402

WGS84_A_M = 6378137.0
WGS84_F = 1.0 / 298.257223563
# Tolerance on symmetry and on the unit quaternion (rounding only).
ROUNDING = 1e-9
# The fixture's IMU rate, and every how many IMU samples the bag time goes on /clock.
BAG_IMU_RATE_HZ = 100.0
CLOCK_EVERY_IMU = 10
# Odometry position error allowed, in multiples of the filter's own 3D sigma
# (sqrt of the trace of its position covariance).
SIGMA_BUDGET = 3.0
# How many IMU samples a held-back epoch (--late-epoch) is sent after: 0.8 s of the bag
# (0.2 s of wall time at 4x), late however the node's two readers interleave, within
# the node's 2 s `engine.imu_buffer_s`.
LATE_BY_IMU_SAMPLES = 80


class Checks:
    """Collects failed checks instead of stopping at the first."""

    def __init__(self):
        self.failures = []

    def that(self, ok, what):
        if not ok:
            self.failures.append(what)
        return ok


def ecef_of(lat_deg, lon_deg, h_m):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    e2 = WGS84_F * (2.0 - WGS84_F)
    n = WGS84_A_M / math.sqrt(1.0 - e2 * math.sin(lat) ** 2)
    return ((n + h_m) * math.cos(lat) * math.cos(lon),
            (n + h_m) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - e2) + h_m) * math.sin(lat))


def enu_of(llh, datum):
    """East-north-up of the geodetic point `llh` (deg, deg, m) at `datum` (same units)."""
    x, y, z = ecef_of(*llh)
    x0, y0, z0 = ecef_of(*datum)
    dx, dy, dz = x - x0, y - y0, z - z0
    lat, lon = math.radians(datum[0]), math.radians(datum[1])
    e = -math.sin(lon) * dx + math.cos(lon) * dy
    n = (-math.sin(lat) * math.cos(lon) * dx - math.sin(lat) * math.sin(lon) * dy
         + math.cos(lat) * dz)
    u = math.cos(lat) * math.cos(lon) * dx + math.cos(lat) * math.sin(lon) * dy + math.sin(lat) * dz
    return (e, n, u)


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def read_bag(path):
    """The input messages (time-ordered, Cyclone objects), the truth track and the datum."""
    inputs, truth, datum = [], [], None
    kinds = {'/imu': ros.Imu, '/gnss/measurements': ros.GnssMeasurements}
    with AnyReader([Path(path)]) as reader:
        for connection, t_ns, raw in reader.messages():
            kind = kinds.get(connection.topic)
            if kind is not None:
                message = kind.deserialize(bytes(raw))
                # Cyclone re-encodes what it decoded to the very same bytes: the two CDR
                # implementations agree on the layout of every message played.
                if message.serialize(use_version_2=False) != bytes(raw):
                    raise SystemExit(f'{connection.topic} at {t_ns} ns does not round-trip')
                inputs.append((t_ns, connection.topic, message))
            elif connection.topic == '/ground_truth':
                odom = ros.Odometry.deserialize(bytes(raw))
                p = odom.pose.pose.position
                truth.append((seconds(odom.header.stamp), (p.x, p.y, p.z)))
            elif connection.topic == '/ground_truth/datum':
                fix = ros.NavSatFix.deserialize(bytes(raw))
                datum = (fix.latitude, fix.longitude, fix.altitude)
    inputs.sort(key=lambda m: m[0])
    return inputs, truth, datum


def truth_at(truth, t_s):
    """Linear interpolation of the truth track at `t_s` (None outside it)."""
    lo, hi = 0, len(truth) - 1
    if not truth or t_s < truth[0][0] or t_s > truth[-1][0]:
        return None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if truth[mid][0] <= t_s:
            lo = mid
        else:
            hi = mid
    (t0, a), (t1, b) = truth[lo], truth[hi]
    w = 0.0 if t1 == t0 else (t_s - t0) / (t1 - t0)
    return tuple(x + w * (y - x) for x, y in zip(a, b))


def diagnostic_values(array):
    return {kv.key: kv.value for status in array.status for kv in status.values}


class Peer:
    """The Cyclone DDS participant with the node's topics."""

    def __init__(self, namespace, node):
        self.participant = ros_domain_participant()
        qos = xcdr1_qos(depth=100_000)
        ns = namespace.rstrip('/')

        def ros_writer(name, kind):
            return writer(self.participant, 'rt' + name, kind, qos)

        def ros_reader(name, kind):
            return reader(self.participant, 'rt' + name, kind, qos)

        self.imu = ros_writer(f'{ns}/imu', ros.Imu)
        self.gnss = ros_writer(f'{ns}/gnss/measurements', ros.GnssMeasurements)
        self.odometry = ros_reader(f'{ns}/odometry', ros.Odometry)
        self.fix = ros_reader(f'{ns}/fix/filtered', ros.NavSatFix)
        self.noise = ros_reader(f'{ns}/{node}/noise_estimates', ros.NoiseEstimates)
        self.diagnostics = ros_reader('/diagnostics', ros.DiagnosticArray)
        self.clock = ros_writer('/clock', ros.Clock)
        self.rosout = ros_reader('/rosout', ros.Log)
        self.received = {'odometry': [], 'fix': [], 'noise': [], 'diagnostics': [],
                         'rosout': []}

    def matched(self):
        return (self.imu.get_matched_subscriptions() and self.gnss.get_matched_subscriptions()
                and self.odometry.get_matched_publications()
                and self.diagnostics.get_matched_publications())

    def drain(self):
        for name in self.received:
            reader = getattr(self, name)
            while True:
                samples = reader.take(N=1000)
                if not samples:
                    break
                self.received[name].extend(samples)

    def latest_diagnostics(self):
        self.drain()
        found = self.received['diagnostics']
        return diagnostic_values(found[-1]) if found else {}


def wait_until(condition, timeout_s, step_s=0.05):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(step_s)
    return False


def handshake(peer, checks):
    """Repeats a bad IMU sample (NaN) and an empty GNSS epoch until the node's diagnostics
    count both: then both input paths are matched at the node's end as well (its
    best-effort readers drop what arrives before they know our writers)."""
    bad_imu = ros.Imu()
    bad_imu.angular_velocity.x = float('nan')
    empty = ros.GnssMeasurements()

    def counted():
        peer.imu.write(bad_imu)
        peer.gnss.write(empty)
        time.sleep(0.2)
        d = peer.latest_diagnostics()
        return int(d.get('unconvertible_imu', 0)) > 0 and \
            int(d.get('rejected_gnss_no_satellites', 0)) > 0
    return checks.that(wait_until(counted, 30.0, 0.0),
                       'the node never counted the NaN IMU sample and the empty GNSS epoch')


def paced(inputs, speed, switch_gap_s=0.0):
    """Yields the time-ordered `inputs` (t_ns, topic, message) each when its bag time since
    the first, divided by `speed`, has passed, and at least `switch_gap_s` after the one
    before where the topic changes."""
    t0_ns, start = inputs[0][0], time.monotonic()
    previous = None
    for t_ns, topic, message in inputs:
        wait = (t_ns - t0_ns) * 1e-9 / speed - (time.monotonic() - start)
        if previous is not None and topic != previous:
            wait = max(wait, switch_gap_s)
        previous = topic
        if wait > 0:
            time.sleep(wait)
        yield t_ns, topic, message


def held_back(inputs, epoch, imu_samples):
    """`inputs` with the GNSS epoch of index `epoch` sent after the `imu_samples` IMU
    samples that follow it: a measurement delivered late, which the node must apply by a
    roll-back."""
    gnss = [k for k, (_, topic, _) in enumerate(inputs) if topic == '/gnss/measurements']
    k = gnss[epoch]
    rest = inputs[:k] + inputs[k + 1:]
    imu_after = [j for j in range(k, len(rest)) if rest[j][1] == '/imu']
    at = imu_after[imu_samples - 1] + 1
    return rest[:at] + [inputs[k]] + rest[at:]


def stream(peer, inputs, speed, clock_every):
    """Publishes the inputs paced at `speed` times real time; returns counts per topic.

    DDS orders the samples of one writer only, so the node may see an epoch and the IMU
    sample of the same stamp in either order: the engine's result does not depend on it,
    and the node must still equal `gnss_ins replay` exactly."""
    sent = {'/imu': 0, '/gnss/measurements': 0}
    for _, topic, message in paced(inputs, speed):
        (peer.imu if topic == '/imu' else peer.gnss).write(message)
        sent[topic] += 1
        # As `ros2 bag play --clock`: the bag's time on /clock (every `clock_every` IMU
        # samples).
        if clock_every and topic == '/imu' and sent[topic] % clock_every == 0:
            peer.clock.write(ros.Clock(clock=message.header.stamp))
    return sent


def check_covariance(checks, what, values, n):
    checks.that(len(values) == n * n, f'{what}: {len(values)} values, not {n}x{n}')
    checks.that(all(math.isfinite(v) for v in values), f'{what}: not finite')
    for i in range(n):
        checks.that(values[i * n + i] >= 0.0, f'{what}: negative variance {i}')
        for j in range(n):
            a, b = values[i * n + j], values[j * n + i]
            if not checks.that(abs(a - b) <= ROUNDING * max(1.0, abs(a)),
                               f'{what}: not symmetric at ({i}, {j})'):
                return


def check_odometry(checks, odometry, truth):
    errors = []
    for o in odometry:
        p, q = o.pose.pose.position, o.pose.pose.orientation
        tw = o.twist.twist
        finite = all(math.isfinite(v) for v in (p.x, p.y, p.z, q.x, q.y, q.z, q.w, tw.linear.x,
                                                 tw.linear.y, tw.linear.z, tw.angular.x,
                                                 tw.angular.y, tw.angular.z))
        if not checks.that(finite, f'Odometry at {seconds(o.header.stamp)} not finite'):
            continue
        checks.that(o.header.frame_id == 'map' and o.child_frame_id == 'base_link',
                    f'Odometry frames {o.header.frame_id!r} -> {o.child_frame_id!r}')
        checks.that(abs(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w - 1.0) < ROUNDING,
                    'Odometry orientation is not a unit quaternion')
        check_covariance(checks, 'Odometry pose covariance', o.pose.covariance, 6)
        check_covariance(checks, 'Odometry twist covariance', o.twist.covariance, 6)
        reference = truth_at(truth, seconds(o.header.stamp))
        if reference is not None:
            c = o.pose.covariance
            sigma_3d = math.sqrt(max(c[0] + c[7] + c[14], 0.0))
            errors.append((math.dist((p.x, p.y, p.z), reference), sigma_3d))
    checks.that(errors, 'no Odometry within the truth track')
    rmse = math.sqrt(sum(e * e for e, _ in errors) / len(errors)) if errors else math.nan
    worst = max((e for e, _ in errors), default=math.nan)
    worst_ratio = max((e / s for e, s in errors if s > 0.0), default=math.nan)
    checks.that(worst_ratio <= SIGMA_BUDGET, f'Odometry position error up to {worst_ratio:.2f} '
                                             f'of its own 3D sigma (budget {SIGMA_BUDGET})')
    return {'count': len(odometry), 'rmse_3d_m': rmse, 'max_error_3d_m': worst,
            'max_error_over_sigma_3d': worst_ratio}


NO_FIX = -1  # sensor_msgs/NavSatStatus STATUS_NO_FIX


def check_fixes(checks, fixes, odometry, datum):
    """Every NavSatFix is finite and sits where the Odometry of the same stamp does, except
    those saying NO_FIX (NaN, covariance UNKNOWN) while the filter starts."""
    by_stamp = {(o.header.stamp.sec, o.header.stamp.nanosec): o for o in odometry}
    no_fix = [f for f in fixes if f.status.status == NO_FIX]
    first_odometry = min((seconds(o.header.stamp) for o in odometry), default=math.inf)
    for f in no_fix:
        checks.that(f.position_covariance_type == 0 and math.isnan(f.latitude)
                    and seconds(f.header.stamp) <= first_odometry,
                    f'NO_FIX at {seconds(f.header.stamp)}: type {f.position_covariance_type}')
    fixes = [f for f in fixes if f.status.status != NO_FIX]
    worst = 0.0
    for f in fixes:
        values = [f.latitude, f.longitude, f.altitude] + list(f.position_covariance)
        if not checks.that(all(math.isfinite(v) for v in values),
                           f'NavSatFix at {seconds(f.header.stamp)} not finite'):
            continue
        check_covariance(checks, 'NavSatFix covariance', f.position_covariance, 3)
        checks.that(f.position_covariance_type == 3, 'NavSatFix covariance type not KNOWN')
        checks.that(f.header.frame_id == 'base_link', f'NavSatFix frame {f.header.frame_id!r}')
        o = by_stamp.get((f.header.stamp.sec, f.header.stamp.nanosec))
        if o is not None:
            p = o.pose.pose.position
            enu = enu_of((f.latitude, f.longitude, f.altitude), datum)
            worst = max(worst, math.dist(enu, (p.x, p.y, p.z)))
    # Both outputs are one solution: they agree to the rounding of the geodetic conversion.
    checks.that(worst < 1e-3, f'NavSatFix and Odometry of one stamp differ by {worst} m')
    checks.that(len(fixes) == len(odometry),
                f'{len(fixes)} NavSatFix for {len(odometry)} Odometry')
    return {'count': len(fixes), 'no_fix': len(no_fix), 'max_fix_vs_odometry_m': worst}


def check_noise(checks, noise, epochs_sent, variant):
    used = 0
    for n in noise:
        checks.that(n.filter_variant == variant, f'noise_estimates variant {n.filter_variant!r}')
        checks.that(n.satellites, 'noise_estimates without satellites')
        for s in n.satellites:
            checks.that(0.0 <= s.elevation_deg <= 90.0 or not s.used,
                        f'elevation {s.elevation_deg} of a used satellite')
            if s.used:
                used += 1
                checks.that(s.rejection_reason == 0, 'a used satellite has a rejection reason')
                checks.that(math.isfinite(s.r_pseudorange_m2) and s.r_pseudorange_m2 > 0.0,
                            f'R of used satellite {s.prn}: {s.r_pseudorange_m2}')
                checks.that(math.isfinite(s.innovation_pseudorange_m),
                            f'innovation of used satellite {s.prn} not finite')
    # One report per epoch once the filter runs; epochs before the start give none.
    checks.that(0 < len(noise) <= epochs_sent, f'{len(noise)} noise_estimates '
                                               f'for {epochs_sent} epochs')
    return {'count': len(noise), 'used_satellite_entries': used}


def check_diagnostics(checks, diagnostics, node_fqn, sent, bad_imu):
    checks.that(diagnostics, 'no /diagnostics')
    if not diagnostics:
        return {}
    last = diagnostics[-1]
    values = diagnostic_values(last)
    status = last.status[0]
    checks.that(status.name.startswith(node_fqn), f'diagnostics name {status.name!r}')
    checks.that(status.level == 0, f'diagnostics level {status.level} ({status.message})')
    checks.that(values.get('phase') == 'running', f'phase {values.get("phase")!r}')
    imu = int(values.get('imu_received', -1)) - int(values.get('unconvertible_imu', 0))
    checks.that(imu == sent['/imu'], f'{imu} good IMU samples counted, {sent["/imu"]} sent')
    checks.that(int(values.get('unconvertible_imu', 0)) >= bad_imu, 'bad IMU samples counted')
    return {'count': len(diagnostics), 'last': values}


def peer_argument_parser(doc, default_speed):
    """The arguments of every peer script: the bag to play, the node's namespace and name,
    and the playback speed (times real time); described by the first line of `doc`."""
    parser = argparse.ArgumentParser(description=doc.split('\n')[0])
    parser.add_argument('--bag', required=True)
    parser.add_argument('--namespace', required=True)
    parser.add_argument('--node', required=True)
    parser.add_argument('--speed', type=float, default=default_speed)
    return parser


def main():
    parser = peer_argument_parser(__doc__, default_speed=4.0)
    parser.add_argument('--variant', default='ekf')
    parser.add_argument('--golden', help='replay CSV of the same bag to compare the fixes with')
    parser.add_argument('--parameters', action='store_true')
    parser.add_argument('--sim-time', action='store_true',
                        help='publish the bag time on /clock; the node runs with use_sim_time')
    parser.add_argument('--late-epoch', type=int, metavar='K',
                        help=f'send GNSS epoch K after the {LATE_BY_IMU_SAMPLES} IMU samples '
                             'that follow it')
    args = parser.parse_args()

    checks = Checks()
    inputs, truth, datum = read_bag(args.bag)
    peer = Peer(args.namespace, args.node)
    summary = {'cyclonedds': importlib.metadata.version('cyclonedds')}
    if not checks.that(wait_until(peer.matched, 30.0), 'the node was not discovered in 30 s'):
        return report(summary, checks)
    if not handshake(peer, checks):
        return report(summary, checks)
    if args.parameters:
        import parameter_client  # noqa: PLC0415  (only with --parameters)
        summary['parameters'] = parameter_client.exercise(peer.participant, args.namespace,
                                                          args.node, args.sim_time, checks)
    bad_imu = int(peer.latest_diagnostics().get('unconvertible_imu', 0))
    for name in ('odometry', 'fix', 'noise', 'diagnostics'):
        peer.received[name].clear()
    if args.late_epoch is not None:
        inputs = held_back(inputs, args.late_epoch, LATE_BY_IMU_SAMPLES)
    start = time.monotonic()
    sent = stream(peer, inputs, args.speed, CLOCK_EVERY_IMU if args.sim_time else 0)
    summary['stream_wall_s'] = time.monotonic() - start
    summary['sent'] = sent
    # Let the node finish and publish one more /diagnostics after the last input.
    time.sleep(2.5)
    peer.drain()
    received = peer.received
    summary['odometry'] = check_odometry(checks, received['odometry'], truth)
    summary['fix'] = check_fixes(checks, received['fix'], received['odometry'], datum)
    summary['noise_estimates'] = check_noise(checks, received['noise'],
                                             sent['/gnss/measurements'], args.variant)
    node_fqn = f'{args.namespace.rstrip("/")}/{args.node}'
    summary['diagnostics'] = check_diagnostics(checks, received['diagnostics'], node_fqn, sent,
                                               bad_imu)
    if args.sim_time:
        summary['sim_time'] = check_sim_time(checks, received['diagnostics'], inputs)
    summary['rosout'] = check_rosout(checks, received['rosout'], node_fqn, args.sim_time,
                                     inputs, args.parameters)
    if args.golden:
        measurement_s = [seconds(m.header.stamp) for _, topic, m in inputs
                         if topic == '/gnss/measurements']
        late = int(summary['diagnostics'].get('last', {}).get('late_measurements', 0))
        summary['golden'] = compare_golden(checks, received['fix'], args.golden,
                                           measurement_s, late)
    return report(summary, checks)


def bag_span_s(inputs):
    return inputs[0][0] * 1e-9, inputs[-1][0] * 1e-9


def check_sim_time(checks, diagnostics, inputs):
    """With use_sim_time the reports carry the bag's time from /clock and the IMU rate is
    counted on it: the bag's 100 Hz, not the 4-times-faster wall rate."""
    first_s, last_s = bag_span_s(inputs)
    stamps = [seconds(d.header.stamp) for d in diagnostics]
    checks.that(stamps and all(s <= last_s for s in stamps),
                f'diagnostics stamps {stamps} beyond the bag ({last_s} s): not sim time')
    checks.that(any(first_s < s for s in stamps), 'no diagnostics stamped with bag time')
    rates = sorted(float(diagnostic_values(d)['imu_rate_hz']) for d in diagnostics
                   if float(diagnostic_values(d).get('imu_rate_hz', 0.0)) > 0.0)
    median = rates[len(rates) // 2] if rates else math.nan
    checks.that(abs(median - BAG_IMU_RATE_HZ) <= 0.1 * BAG_IMU_RATE_HZ,
                f'median imu_rate_hz {median} on sim time, bag rate {BAG_IMU_RATE_HZ}')
    return {'diagnostics_stamps_s': stamps, 'imu_rate_hz_median': median}


def check_rosout(checks, lines, node_fqn, sim_time, inputs, parameters):
    """The node's log lines arrive on /rosout under its logger name."""
    logger = node_fqn.strip('/').replace('/', '.')
    own = [line for line in lines if line.name == logger]
    checks.that(own, f'no /rosout line from {logger} (names: {sorted({x.name for x in lines})})')
    started = [x for x in own if x.level == 20 and 'filter initialized' in x.msg]
    checks.that(started, 'no /rosout INFO line "filter initialized"')
    if sim_time and started:
        first_s, last_s = bag_span_s(inputs)
        t = seconds(started[0].stamp)
        checks.that(first_s <= t <= last_s, f'/rosout stamp {t} s is not the bag time')
    if parameters:
        checks.that(any(x.level == 30 and 'read-only' in x.msg for x in own),
                    'the refused parameter is not on /rosout as a warning')
    return {'lines': len(own), 'levels': sorted({x.level for x in own})}


def compare_golden(checks, fixes, golden_csv, measurement_s, late):
    """The node runs the engine of `gnss_ins replay` on the same inputs: every fix equals
    the replay's solution of its stamp, but those published before a late measurement
    arrived (tools/replay_match.py)."""
    with open(golden_csv, newline='') as f:
        rows = {round(float(r['t_s']) * 1e3): r for r in csv.DictReader(f)}
    worst_deg, worst_h, compared = 0.0, 0.0, []
    for fix in fixes:
        t = seconds(fix.header.stamp)
        row = rows.get(round(t * 1e3))
        if row is None:
            continue
        diff_deg = max(abs(fix.latitude - float(row['lat_deg'])),
                       abs(fix.longitude - float(row['lon_deg'])))
        diff_h = abs(fix.altitude - float(row['height_m']))
        worst_deg, worst_h = max(worst_deg, diff_deg), max(worst_h, diff_h)
        # 1e-9 relative, as the issue asks of DDS against replay.
        compared.append((t, diff_deg > 1e-9 * 180.0 or diff_h > 1e-9 * 1e4))
    checks.that(len(compared) == len(rows),
                f'{len(compared)} of the {len(rows)} replay solutions received')
    runs = check_late_runs(checks, 'fix', compared, measurement_s, late)
    return {'matched': len(compared), 'solutions': len(rows), 'max_diff_deg': worst_deg,
            'max_diff_height_m': worst_h, 'late_runs': runs, 'late_measurements': late}


def report(summary, checks):
    summary['failures'] = checks.failures
    print(json.dumps(summary, indent=1, default=str))
    for failure in checks.failures:
        print(f'FAILED: {failure}', file=sys.stderr)
    return 1 if checks.failures else 0


if __name__ == '__main__':
    sys.exit(main())
