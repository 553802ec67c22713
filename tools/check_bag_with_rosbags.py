#!/usr/bin/env python3
"""Reads a ROS 2 MCAP bag with the independent `rosbags` package and prints a JSON summary.

Usage: check_bag_with_rosbags.py BAG   (a .mcap file or a rosbag2 directory)

Every message is deserialized with the types rosbags builds from the message definitions
stored in the bag itself. The summary holds, per topic: type, count, first and last log
time, the offered QoS, and the first and last message decoded into plain JSON values
(a NaN float is written as the string "NaN").
It also checks every type definition stored in the bag against an independent reference:
rosbags' own ROS 2 Jazzy type store for standard types, and this repository's msg/*.msg
(parsed by rosbags) for the package's own types.

Run it with the venv made by scripts/setup_test_peers.sh (rosbags pinned in
tools/requirements-test-peers.txt).
"""

from __future__ import annotations

import dataclasses
import importlib.metadata
import json
import math
import sys
from pathlib import Path

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

PACKAGE = 'adaptive_gnss_ins'
MSG_DIR = Path(__file__).resolve().parent.parent / 'msg'


def to_json(value: object, fielddefs: dict) -> object:
    """A decoded message (rosbags dataclass) as plain JSON values: its fields in order,
    constants left out (`fielddefs` is the type store's table of field definitions)."""
    if dataclasses.is_dataclass(value):
        fields = fielddefs[value.__msgtype__][1]
        return {name: to_json(getattr(value, name), fielddefs) for name, _ in fields}
    if isinstance(value, np.ndarray):
        return [to_json(item, fielddefs) for item in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [to_json(item, fielddefs) for item in value]
    if isinstance(value, np.generic):
        return to_json(value.item(), fielddefs)
    if isinstance(value, float) and math.isnan(value):
        return 'NaN'
    return value


def package_types() -> dict:
    """Field definitions of the package's own messages, parsed from msg/*.msg."""
    types: dict = {}
    for path in sorted(MSG_DIR.glob('*.msg')):
        types.update(get_types_from_msg(path.read_text(), f'{PACKAGE}/msg/{path.stem}'))
    return types


def check_definitions(connections: list) -> dict[str, str]:
    """Verdict per type found in the bag's stored definitions."""
    jazzy = get_typestore(Stores.ROS2_JAZZY).fielddefs
    own = package_types()
    verdicts: dict[str, str] = {}
    for connection in connections:
        stored = get_types_from_msg(connection.msgdef.data, connection.msgtype)
        for name, fielddefs in stored.items():
            if name in own:
                ok = own[name] == fielddefs
                verdict = 'matches msg/' if ok else 'differs from msg/'
            elif name in jazzy:
                ok = jazzy[name] == fielddefs
                verdict = 'matches jazzy' if ok else 'differs from jazzy'
            else:
                verdict = 'no reference'
            previous = verdicts.setdefault(name, verdict)
            if previous != verdict:
                verdicts[name] = f'{previous}; {verdict}'
    return dict(sorted(verdicts.items()))


def qos_json(connection: object) -> list[dict]:
    """The offered QoS profiles of a connection, as rosbags parsed them."""
    return [
        {
            'history': profile.history.name.lower(),
            'depth': profile.depth,
            'reliability': profile.reliability.name.lower(),
            'durability': profile.durability.name.lower(),
        }
        for profile in connection.ext.offered_qos_profiles
    ]


def summarize(bag: Path) -> dict:
    """The JSON summary of `bag`."""
    topics: dict[str, dict] = {}
    with AnyReader([bag]) as reader:
        for connection in reader.connections:
            topics[connection.topic] = {
                'type': connection.msgtype,
                'encoding': connection.ext.serialization_format,
                'qos': qos_json(connection),
                'count_in_index': connection.msgcount,
                'count': 0,
                'first_log_time_ns': None,
                'last_log_time_ns': None,
                'first': None,
                'last': None,
            }
        previous_time = -1
        in_order = True
        total = 0
        for connection, timestamp, rawdata in reader.messages():
            message = to_json(
                reader.deserialize(rawdata, connection.msgtype), reader.typestore.fielddefs
            )
            topic = topics[connection.topic]
            topic['count'] += 1
            if topic['first'] is None:
                topic['first'] = message
                topic['first_log_time_ns'] = timestamp
            topic['last'] = message
            topic['last_log_time_ns'] = timestamp
            in_order = in_order and timestamp >= previous_time
            previous_time = timestamp
            total += 1
        return {
            'reader': f"rosbags {importlib.metadata.version('rosbags')}",
            'message_count': total,
            'message_count_in_index': reader.message_count,
            'start_time_ns': reader.start_time if total else None,
            'end_time_ns': reader.end_time if total else None,
            'log_time_order': in_order,
            'topics': dict(sorted(topics.items())),
            'definitions': check_definitions(reader.connections),
        }


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    json.dump(summarize(Path(sys.argv[1])), sys.stdout, indent=1, allow_nan=False)
    print()
    return 0


if __name__ == '__main__':
    sys.exit(main())
