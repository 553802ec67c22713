#!/usr/bin/env python3
"""Latency benchmark (not a test): Imu written by Cyclone DDS to the Odometry of the same
stamp received back from gnss_ins_node, over loopback.

Usage: cyclonedds_latency.py --bag BAG --namespace NS --node NAME [--speed X]

Plays the bag's IMU and GNSS at X times real time (2 = 200 Hz for the 100 Hz fixture) and
prints the latency percentiles as JSON. The time includes the Python peer's own write and
take calls, so it is an upper bound on the node's share. Run it inside a loopback-only
network namespace with the venv of scripts/setup_test_peers.sh, e.g.
  unshare -n sh -c 'ip link set lo up; target/release/gnss_ins_node --ros-args \\
    -r __ns:=/lat -r __node:=ins & sleep 1; .venv/bin/python tools/cyclonedds_latency.py \\
    --bag tests/data/fixture_small.mcap --namespace /lat --node ins --speed 2; kill %1'
"""

import json
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cyclonedds_peer import (  # noqa: E402
    Checks, Peer, handshake, paced, peer_argument_parser, read_bag, wait_until)


def main():
    args = peer_argument_parser(__doc__, default_speed=2.0).parse_args()
    inputs, _, _ = read_bag(args.bag)
    peer = Peer(args.namespace, args.node)
    checks = Checks()
    if not (wait_until(peer.matched, 30.0) and handshake(peer, checks)):
        print('node not reachable', checks.failures, file=sys.stderr)
        return 1
    written, received = {}, {}
    done = threading.Event()

    def receive():
        while not done.is_set():
            for o in peer.odometry.take(N=100):
                received[(o.header.stamp.sec, o.header.stamp.nanosec)] = time.perf_counter()
            time.sleep(0.0001)

    receiver = threading.Thread(target=receive)
    receiver.start()
    for _, topic, message in paced(inputs, args.speed):
        if topic == '/imu':
            stamp = (message.header.stamp.sec, message.header.stamp.nanosec)
            written[stamp] = time.perf_counter()
            peer.imu.write(message)
        else:
            peer.gnss.write(message)
    time.sleep(1.0)
    done.set()
    receiver.join()
    latencies_ms = sorted(1e3 * (received[s] - written[s]) for s in received if s in written)
    if not latencies_ms:
        print('no Odometry received', file=sys.stderr)
        return 1

    def pct(p):
        return latencies_ms[min(len(latencies_ms) - 1, int(p / 100.0 * len(latencies_ms)))]
    print(json.dumps({'samples': len(latencies_ms), 'imu_rate_hz': 100.0 * args.speed,
                      'p50_ms': pct(50), 'p90_ms': pct(90), 'p99_ms': pct(99),
                      'max_ms': latencies_ms[-1]}, indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
