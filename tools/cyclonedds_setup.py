"""Cyclone DDS set-up shared by the test peers: the participant of the ROS domain, the QoS
ROS 2 peers speak (reliable, XCDR1) and writers and readers on DDS topic names.

ROS 2 maps a topic `/a/b` to the DDS topic `rt/a/b`, and a service `/s` to the request
topic `rq/sRequest` and the reply topic `rr/sReply`; the callers spell those names out.
"""

import os

from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


def ros_domain_participant() -> DomainParticipant:
    """A participant in the domain ROS_DOMAIN_ID names (0 when unset or empty)."""
    return DomainParticipant(int(os.environ.get('ROS_DOMAIN_ID', '0') or 0))


def xcdr1_qos(depth: int) -> Qos:
    """Reliable, volatile, keep-last `depth`, XCDR1 data representation."""
    return Qos(
        Policy.Reliability.Reliable(max_blocking_time=duration(seconds=1)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(depth),
        Policy.DataRepresentation(use_cdrv0_representation=True),
    )


def writer(participant, dds_topic: str, kind, qos: Qos) -> DataWriter:
    """A writer of `kind` samples on the DDS topic `dds_topic`, topic and writer with `qos`."""
    return DataWriter(participant, Topic(participant, dds_topic, kind, qos=qos), qos=qos)


def reader(participant, dds_topic: str, kind, qos: Qos) -> DataReader:
    """A reader of `kind` samples on the DDS topic `dds_topic`, topic and reader with `qos`."""
    return DataReader(participant, Topic(participant, dds_topic, kind, qos=qos), qos=qos)
