#!/usr/bin/env python3
"""rclpy's own parameter client (ROS 2 Jazzy on Fast DDS) against gnss_ins_node.

Usage: jazzy_parameters.py --namespace NS --node NAME [--require-parameter-events]

Lists, reads, types, describes and sets the node's parameters through
rclpy.parameter_client.AsyncParameterClient, as `ros2 param` does, and checks the answers
against the node's documented behaviour (params/defaults.yaml defaults; a description for every
parameter; the runtime parameters settable, the others read-only and a set of them refused
with the reason; an invalid value refused; an atomic set all or nothing). Leaves every
parameter as it found it. It also listens on /parameter_events and reports what the node
announced there; with `--require-parameter-events` each accepted set must be announced, once,
with its new value.

Prints a JSON summary on stdout, every failed check on stderr, and exits 1 if any failed.
See tools/jazzy_common.py for the environment.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from jazzy_common import (  # noqa: E402  (the tools directory is not a package)
    Checks, JazzyNode, argument_parser, node_fqn, reliable, report, wait_until)

from rcl_interfaces.msg import ParameterEvent, ParameterType  # noqa: E402
from rclpy.parameter import Parameter, parameter_value_to_python  # noqa: E402
from rclpy.parameter_client import AsyncParameterClient  # noqa: E402

REPLY_TIMEOUT_S = 10.0
MASK = 'gnss.elevation_mask_deg'
VARIANT = 'filter.variant'


class Client:
    """The parameter client of one node; every call waits for its reply."""

    def __init__(self, jazzy, fqn, checks):
        self.client = AsyncParameterClient(jazzy.node, fqn)
        self.checks = checks

    def call(self, what, future):
        """The reply, or None (a failed check) when it does not come."""
        done = wait_until(future.done, REPLY_TIMEOUT_S, 0.005)
        if not self.checks.that(done and future.exception() is None,
                                f'{what}: no reply ({future.exception() if done else "timeout"})'):
            return None
        return future.result()

    def set(self, name, value):
        """The SetParametersResult of setting one parameter."""
        reply = self.call(f'set {name}', self.client.set_parameters([Parameter(name, value=value)]))
        return reply.results[0] if reply is not None and len(reply.results) == 1 else None

    def value(self, name):
        reply = self.call(f'get {name}', self.client.get_parameters([name]))
        return parameter_value_to_python(reply.values[0]) if reply is not None else None


def check_listing(checks, client):
    listed = client.call('list', client.client.list_parameters([], 0))
    if listed is None:
        return {}, []
    names = list(listed.result.names)
    for expected in ('use_sim_time', VARIANT, MASK, 'output.rate_hz'):
        checks.that(expected in names, f'list_parameters lacks {expected}')
    checks.that('gnss' in listed.result.prefixes, 'list_parameters prefixes lack gnss')
    gnss = client.call('list gnss', client.client.list_parameters(['gnss'], 0))
    if gnss is not None:
        checks.that(gnss.result.names and all(n.startswith('gnss.') for n in gnss.result.names),
                    f'list_parameters with prefix gnss: {list(gnss.result.names)}')
    return {'listed': len(names)}, names


def check_values(checks, client, names):
    """Values and types of some parameters, and a description and a type for every one."""
    asked = [VARIANT, MASK, 'use_sim_time', 'no.such_param']
    got = client.call('get', client.client.get_parameters(asked))
    if got is not None and checks.that(len(got.values) == 4, 'get_parameters: 4 values'):
        v = got.values
        checks.that(v[0].type == ParameterType.PARAMETER_STRING and v[0].string_value == 'ekf',
                    f'{VARIANT} = {v[0]}')
        checks.that(v[1].type == ParameterType.PARAMETER_DOUBLE and v[1].double_value == 10.0,
                    f'{MASK} = {v[1]}')
        checks.that(v[2].type == ParameterType.PARAMETER_BOOL and not v[2].bool_value,
                    f'use_sim_time = {v[2]}')
        checks.that(v[3].type == ParameterType.PARAMETER_NOT_SET, 'an unknown name is NOT_SET')
    types = client.call('types', client.client.get_parameter_types(names))
    described = client.call('describe', client.client.describe_parameters(names))
    summary = {}
    if types is None or described is None:
        return summary
    if not checks.that(len(types.types) == len(names) == len(described.descriptors),
                       f'{len(names)} names, {len(types.types)} types, '
                       f'{len(described.descriptors)} descriptors'):
        return summary
    undescribed = [d.name for d in described.descriptors if not d.description.strip()]
    checks.that(not undescribed, f'parameters without a description: {undescribed}')
    mistyped = [d.name for d, t in zip(described.descriptors, types.types, strict=True)
                if d.type != t]
    checks.that(not mistyped, f'descriptor type differs from get_parameter_types: {mistyped}')
    checks.that([d.name for d in described.descriptors] == names, 'descriptors out of order')
    by_name = {d.name: d for d in described.descriptors}
    mask, variant = by_name.get(MASK), by_name.get(VARIANT)
    if checks.that(mask is not None and variant is not None, 'mask and variant described'):
        checks.that(not mask.read_only and variant.read_only,
                    'elevation mask settable, variant read-only')
        checks.that('Unit: deg' in mask.description, f'description {mask.description!r}')
        summary['mask_description'] = mask.description
    summary['read_only'] = sum(d.read_only for d in described.descriptors)
    return summary


def check_sets(checks, client):
    """Accepted, refused and atomic sets; returns the summary and the accepted sets."""
    summary, accepted = {}, []
    applied = client.set(MASK, 12.5)
    if checks.that(applied is not None and applied.successful, f'set {MASK} 12.5: {applied}'):
        accepted.append((MASK, 12.5))
    checks.that(client.value(MASK) == 12.5, 'the elevation mask reads back as set')
    refused = client.set(VARIANT, 'ermakf')
    checks.that(refused is not None and not refused.successful and 'read-only' in refused.reason,
                f'set {VARIANT}: {refused}')
    summary['refused_read_only'] = refused.reason if refused is not None else None
    invalid = client.set(MASK, 95.0)
    checks.that(invalid is not None and not invalid.successful and invalid.reason,
                f'mask 95 deg: {invalid}')
    summary['refused_invalid'] = invalid.reason if invalid is not None else None
    wrong_type = client.set(MASK, 'high')
    checks.that(wrong_type is not None and not wrong_type.successful and wrong_type.reason,
                f'mask as a string: {wrong_type}')
    summary['refused_wrong_type'] = wrong_type.reason if wrong_type is not None else None
    checks.that(client.value(MASK) == 12.5, 'refused sets left the elevation mask alone')

    both = [Parameter(MASK, value=11.0), Parameter(VARIANT, value='ermakf')]
    atomic = client.call('set atomically', client.client.set_parameters_atomically(both))
    result = atomic.result if atomic is not None else None
    checks.that(result is not None and not result.successful and result.reason,
                f'atomic set with a read-only parameter: {result}')
    summary['refused_atomic'] = result.reason if result is not None else None
    checks.that(client.value(MASK) == 12.5, 'a refused atomic set changed nothing')
    restore = client.call('restore atomically', client.client.set_parameters_atomically(
        [Parameter(MASK, value=10.0)]))
    if checks.that(restore is not None and restore.result.successful, f'restore: {restore}'):
        accepted.append((MASK, 10.0))
    checks.that(client.value(MASK) == 10.0, 'the elevation mask is back at its default')
    return summary, accepted


def check_parameter_events(checks, jazzy, fqn, accepted, required):
    """What the node announced on /parameter_events for the accepted sets: one event with
    the name and the new value in changed_parameters per accepted set, nothing for a
    refused one (the declaration events of the start carry new_parameters only)."""
    wait_until(lambda: len(change_events(jazzy, fqn)) >= len(accepted), 2.0 if required else 0.5)
    events = change_events(jazzy, fqn)
    announced = [[(p.name, parameter_value_to_python(p.value)) for p in e.changed_parameters]
                 for e in events]
    if required:
        checks.that(announced == [[a] for a in accepted],
                    f'/parameter_events announced {announced}, the accepted sets were {accepted}')
    return {'events': len(events), 'announced': announced, 'accepted_sets': accepted}


def change_events(jazzy, fqn):
    return [e for e in jazzy.messages('parameter_events')
            if e.node == fqn and e.changed_parameters]


def main():
    parser = argument_parser(__doc__)
    parser.add_argument('--require-parameter-events', action='store_true',
                        help='fail unless every accepted set is announced on /parameter_events')
    args = parser.parse_args()

    checks = Checks()
    fqn = node_fqn(args.namespace, args.node)
    jazzy = JazzyNode('jazzy_parameter_client')
    jazzy.subscribe('parameter_events', ParameterEvent, '/parameter_events', reliable(1000))
    jazzy.start()
    try:
        client = Client(jazzy, fqn, checks)
        summary = {'rmw': jazzy.rmw()}
        checks.that(summary['rmw'] == 'rmw_fastrtps_cpp', f'middleware {summary["rmw"]}')
        if not checks.that(client.client.wait_for_services(timeout_sec=30.0),
                           f'the parameter services of {fqn} were not discovered in 30 s'):
            return report(summary, checks)
        listing, names = check_listing(checks, client)
        summary.update(listing)
        summary.update(check_values(checks, client, names))
        sets, accepted = check_sets(checks, client)
        summary.update(sets)
        summary['parameter_events'] = check_parameter_events(
            checks, jazzy, fqn, accepted, args.require_parameter_events)
        return report(summary, checks)
    finally:
        jazzy.close()


if __name__ == '__main__':
    sys.exit(main())
