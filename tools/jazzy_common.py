"""What the genuine ROS 2 Jazzy peers (tools/jazzy_*.py) share: an rclpy node on Fast DDS
spun in a background thread, the QoS profiles they use, checks collected into a JSON report,
and the bag's messages decoded by rclpy itself.

The peers run with the venv of scripts/setup_test_peers.sh (ROS 2 Jazzy wheels from PyPI).
What rclpy needs from the environment there:
- LD_LIBRARY_PATH with the venv's lib/ (rcl, rmw, Fast DDS and the type supports, which
  rmw_implementation and rosidl_typesupport open by file name through LD_LIBRARY_PATH) and
  every site-packages/ros_*.libs (the vendored tinyxml2, OpenSSL 1.1, lttng-ust, yaml and
  spdlog: the wheels' RPATH points next to where the libraries were before installation, so
  it does not find them). ros-wheels-bootstrapper, a dependency of rclpy, sets both: its
  .pth file re-executes every Python interpreter of the venv once with them.
- RMW_IMPLEMENTATION unset or `rmw_fastrtps_cpp`: no other middleware is installed, and any
  other value stops rclpy.init (rcl error 102). AMENT_PREFIX_PATH is not needed.
- ROS_DOMAIN_ID naming the node's domain; a loopback-only network namespace around both.
rclpy is initialised with `--disable-external-lib-logs`, so nothing is written to ~/.ros/log.
"""

import argparse
import json
import math
import sys
import threading
import time
from pathlib import Path

import rclpy
from builtin_interfaces.msg import Time
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import Imu, NavSatFix


class Checks:
    """Collects failed checks instead of stopping at the first."""

    def __init__(self):
        self.failures = []

    def that(self, ok, what):
        if not ok:
            self.failures.append(what)
        return ok


def report(summary, checks):
    """Prints the JSON summary (stdout) and the failures (stderr); the exit status."""
    summary['failures'] = checks.failures
    print(json.dumps(summary, indent=1, default=str))
    for failure in checks.failures:
        print(f'FAILED: {failure}', file=sys.stderr)
    return 1 if checks.failures else 0


def reliable(depth):
    """Reliable, volatile, keep last `depth`: rclpy's default with a deeper history."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


def rosout_reader():
    """/rosout as rcl offers it (reliable, transient local, 1000 lines): a late reader gets
    the node's start-up lines too."""
    return QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)


SECOND_NS = 1_000_000_000


def stamp_ns(stamp):
    """A builtin_interfaces/Time as integer nanoseconds (exact)."""
    return stamp.sec * SECOND_NS + stamp.nanosec


def ros_time(t_ns):
    """Integer nanoseconds as a builtin_interfaces/Time (exact)."""
    return Time(sec=t_ns // SECOND_NS, nanosec=t_ns % SECOND_NS)


def wait_until(condition, timeout_s, step_s=0.05):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(step_s)
    return condition()


def argument_parser(doc):
    """The arguments of every peer: the node's namespace and name; described by the first
    line of `doc`."""
    parser = argparse.ArgumentParser(description=doc.split('\n')[0])
    parser.add_argument('--namespace', required=True)
    parser.add_argument('--node', required=True)
    return parser


def node_fqn(namespace, node):
    return f'{namespace.rstrip("/")}/{node}'


class JazzyNode:
    """An rclpy node whose callbacks run in a background executor thread, so that the main
    thread can publish on its own schedule. Received messages are appended to lists, each
    as (perf_counter_ns at reception, message)."""

    def __init__(self, name):
        rclpy.init(args=['--ros-args', '--disable-external-lib-logs'])
        self.node = rclpy.create_node(name)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.received = {}
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)

    def subscribe(self, key, kind, topic, qos):
        into = self.received.setdefault(key, [])
        self.node.create_subscription(
            kind, topic, lambda m: into.append((time.perf_counter_ns(), m)), qos)

    def messages(self, key):
        return [m for _, m in self.received[key]]

    def start(self):
        self.thread.start()
        return self

    def close(self):
        """Stops the executor thread before the node goes (a C++ abort otherwise)."""
        self.executor.shutdown()
        rclpy.try_shutdown()
        if self.thread.is_alive():
            self.thread.join(timeout=5.0)
        self.node.destroy_node()

    @staticmethod
    def rmw():
        return rclpy.get_rmw_implementation_identifier()


def read_bag(path, kinds):
    """The messages of the topics in `kinds` ({topic: rclpy message class}) as
    [(log time ns, topic, message)] in log-time order, each decoded by rclpy from the bag's
    serialized bytes (rosbags only reads the MCAP file)."""
    from rosbags.highlevel import AnyReader  # noqa: PLC0415  (only the bag peers need it)
    found = []
    with AnyReader([Path(path)]) as reader:
        connections = [c for c in reader.connections if c.topic in kinds]
        for connection, t_ns, raw in reader.messages(connections=connections):
            found.append((t_ns, connection.topic,
                          deserialize_message(bytes(raw), kinds[connection.topic])))
    found.sort(key=lambda m: m[0])
    return found


def diagnostic_values(array):
    return {kv.key: kv.value for status in array.status for kv in status.values}


def own_diagnostics(jazzy, fqn):
    """The node's /diagnostics received under the key 'diagnostics' (its status is named
    `<fqn>: filter`)."""
    return [m for m in jazzy.messages('diagnostics')
            if m.status and m.status[0].name.startswith(f'{fqn}:')]


def unconvertible_imu():
    """An Imu the node counts as `unconvertible_imu` and drops before the filter."""
    imu = Imu()
    imu.angular_velocity.x = math.nan
    return imu


def unconvertible_fix():
    """A NavSatFix without a solution: counted as `unconvertible_fix` and dropped."""
    fix = NavSatFix()
    fix.status.status = fix.status.STATUS_NO_FIX
    return fix


def handshake(jazzy, fqn, bad, checks):
    """Repeats unconvertible messages, `bad` = [(publisher, message, diagnostics counter)],
    until the node's diagnostics count every one: then each input path is matched at the
    node's end too (its best-effort readers drop what arrives before they know the writer).
    The node drops these messages before the filter."""
    def counted():
        for publisher, message, _ in bad:
            publisher.publish(message)
        time.sleep(0.2)
        own = own_diagnostics(jazzy, fqn)
        values = diagnostic_values(own[-1]) if own else {}
        return all(int(values.get(counter, 0)) > 0 for _, _, counter in bad)
    return checks.that(wait_until(counted, 30.0, 0.0),
                       f'the node never counted {[c for _, _, c in bad]} in /diagnostics')
