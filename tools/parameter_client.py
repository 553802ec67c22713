"""A ROS 2 parameter client on Cyclone DDS, in the request/reply layout of rmw_cyclonedds,
used by cyclonedds_peer.py --parameters against gnss_ins_node's parameter services.

`exercise` lists, reads, describes and sets parameters, checks the answers against the
node's documented behaviour (params/defaults.yaml defaults; runtime parameters settable,
the rest read-only) and leaves every parameter as it found it. It listens on
/parameter_events (reliable, keep last 1000, as rclcpp's subscribers) and requires one
event with the name and the new value in changed_parameters per accepted set, and none
for a refused one.
"""

import random
import time

import cyclonedds_ros_types as ros
from cyclonedds_setup import reader, writer, xcdr1_qos

# A reply lost because the node's reply writer had not yet matched our reader is
# retried with a new sequence number.
REPLY_TIMEOUT_S = 2.0
ATTEMPTS = 10


class ServiceClient:
    """One service: a request writer and a reply reader matched by the request header."""

    def __init__(self, participant, service, request_type, response_type):
        qos = xcdr1_qos(depth=10)
        self.name = service
        self.writer = writer(participant, f'rq{service}Request', request_type, qos)
        self.reader = reader(participant, f'rr{service}Reply', response_type, qos)
        self.guid = random.getrandbits(63)
        self.sequence = 0
        self.latencies_s = []

    def call(self, request):
        """The reply to `request` (its header is filled in here), or None."""
        deadline = time.monotonic() + 20.0
        while not (self.writer.get_matched_subscriptions()
                   and self.reader.get_matched_publications()):
            if time.monotonic() > deadline:
                return None
            time.sleep(0.05)
        for _ in range(ATTEMPTS):
            self.sequence += 1
            request.client_guid = self.guid
            request.sequence_number = self.sequence
            start = time.monotonic()
            self.writer.write(request)
            while time.monotonic() - start < REPLY_TIMEOUT_S:
                for reply in self.reader.take(N=10):
                    if (reply.client_guid, reply.sequence_number) == (self.guid, self.sequence):
                        self.latencies_s.append(time.monotonic() - start)
                        return reply
                time.sleep(0.001)
        return None


def double(value):
    return ros.ParameterValue(type=ros.ParameterType.DOUBLE, double_value=value)


def exercise(participant, namespace, node, sim_time, checks):
    """Runs the parameter checks; returns a summary (values seen, reply latencies)."""
    base = f'/{namespace.strip("/")}/{node}/'.replace('//', '/')
    P = ros
    clients = {
        'list': ServiceClient(participant, base + 'list_parameters', P.ListParametersRequest,
                              P.ListParametersResponse),
        'get': ServiceClient(participant, base + 'get_parameters', P.GetParametersRequest,
                             P.GetParametersResponse),
        'types': ServiceClient(participant, base + 'get_parameter_types',
                               P.GetParameterTypesRequest, P.GetParameterTypesResponse),
        'describe': ServiceClient(participant, base + 'describe_parameters',
                                  P.DescribeParametersRequest, P.DescribeParametersResponse),
        'set': ServiceClient(participant, base + 'set_parameters', P.SetParametersRequest,
                             P.SetParametersResponse),
    }
    summary = {}
    fqn = base.rstrip('/')
    events = reader(participant, 'rt/parameter_events', P.ParameterEvent, xcdr1_qos(depth=1000))

    def call(kind, request):
        reply = clients[kind].call(request)
        checks.that(reply is not None, f'no reply from {clients[kind].name}')
        return reply

    listed = call('list', P.ListParametersRequest(prefixes=[], depth=0))
    if listed is None:
        return summary
    names = listed.result.names
    summary['listed'] = len(names)
    for expected in ('use_sim_time', 'filter.variant', 'gnss.elevation_mask_deg'):
        checks.that(expected in names, f'list_parameters lacks {expected}')
    checks.that('gnss' in listed.result.prefixes, 'list_parameters prefixes lack gnss')
    gnss = call('list', P.ListParametersRequest(prefixes=['gnss'], depth=0))
    if gnss is not None:
        checks.that(gnss.result.names and all(n.startswith('gnss.') for n in gnss.result.names),
                    f'list_parameters with prefix gnss: {gnss.result.names}')

    asked = ['filter.variant', 'gnss.elevation_mask_deg', 'use_sim_time', 'no.such_param']
    got = call('get', P.GetParametersRequest(names=asked))
    if got is not None and checks.that(len(got.values) == 4, 'get_parameters: 4 values'):
        v = got.values
        checks.that(v[0].type == P.ParameterType.STRING and v[0].string_value == 'ekf',
                    f'filter.variant = {v[0]}')
        checks.that(v[1].type == P.ParameterType.DOUBLE and v[1].double_value == 10.0,
                    f'gnss.elevation_mask_deg = {v[1]}')
        checks.that(v[2].type == P.ParameterType.BOOL and v[2].bool_value is sim_time,
                    f'use_sim_time = {v[2]}')
        checks.that(v[3].type == P.ParameterType.NOT_SET, 'an unknown name is NOT_SET')
    types = call('types', P.GetParameterTypesRequest(names=asked))
    if types is not None:
        checks.that(list(types.types) == [4, 3, 1, 0], f'get_parameter_types: {types.types}')
    described = call('describe', P.DescribeParametersRequest(
        names=['gnss.elevation_mask_deg', 'filter.variant']))
    if described is not None and checks.that(len(described.descriptors) == 2, 'descriptors'):
        mask, variant = described.descriptors
        checks.that(not mask.read_only and variant.read_only,
                    'elevation mask settable, variant read-only')
        checks.that('Unit: deg' in mask.description, f'description {mask.description!r}')

    def set_one(name, value):
        reply = call('set', P.SetParametersRequest(
            parameters=[P.Parameter(name=name, value=value)]))
        ok = reply is not None and checks.that(len(reply.results) == 1, 'one result')
        return reply.results[0] if ok else None

    def mask_value():
        reply = call('get', P.GetParametersRequest(names=['gnss.elevation_mask_deg']))
        return reply.values[0].double_value if reply is not None else None

    # The node's /parameter_events writer must have matched before the first set.
    deadline = time.monotonic() + 20.0
    while not events.get_matched_publications() and time.monotonic() < deadline:
        time.sleep(0.05)
    checks.that(bool(events.get_matched_publications()), 'no /parameter_events writer matched')
    applied = set_one('gnss.elevation_mask_deg', double(12.5))
    checks.that(applied is not None and applied.successful, f'set elevation mask: {applied}')
    checks.that(mask_value() == 12.5, 'the elevation mask reads back as set')
    refused = set_one('filter.variant',
                      P.ParameterValue(type=P.ParameterType.STRING, string_value='ermakf'))
    checks.that(refused is not None and not refused.successful
                and 'read-only' in refused.reason, f'set filter.variant: {refused}')
    summary['refused_reason'] = refused.reason if refused is not None else None
    invalid = set_one('gnss.elevation_mask_deg', double(95.0))
    checks.that(invalid is not None and not invalid.successful, f'mask 95 deg: {invalid}')
    summary['invalid_reason'] = invalid.reason if invalid is not None else None
    restored = set_one('gnss.elevation_mask_deg', double(10.0))
    checks.that(restored is not None and restored.successful, 'restore the elevation mask')
    checks.that(mask_value() == 10.0, 'the elevation mask is back at its default')

    accepted = [[('gnss.elevation_mask_deg', 12.5)], [('gnss.elevation_mask_deg', 10.0)]]
    received = []
    deadline = time.monotonic() + 2.0
    while True:
        received.extend(e for e in events.take(N=100)
                        if e.node == fqn and e.changed_parameters)
        if len(received) >= len(accepted) or time.monotonic() > deadline:
            break
        time.sleep(0.01)
    announced = [[(p.name, p.value.double_value) for p in e.changed_parameters]
                 for e in received]
    checks.that(announced == accepted,
                f'/parameter_events announced {announced}, the accepted sets were {accepted}')
    summary['parameter_events'] = {'announced': announced}

    latencies = sorted(t for c in clients.values() for t in c.latencies_s)
    if latencies:
        summary['calls'] = len(latencies)
        summary['reply_latency_ms_median'] = 1e3 * latencies[len(latencies) // 2]
        summary['reply_latency_ms_max'] = 1e3 * latencies[-1]
    return summary
