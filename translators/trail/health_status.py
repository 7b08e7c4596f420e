"""The course's HealthStatus on intervehicle (goby3-course post-homework2: ``src/bin/health_monitor/app.cpp`` and the
topside manager's ``subscribe_usv_health``): which group a status goes on, the group functions of its publisher
and subscriber, and the publication options of each group.

DCCL carries no group: the publisher's group function writes ``state`` from the group (``health_status_good`` ->
GOOD, ``health_status_failed`` -> FAILED), and the subscriber's reads it back (GOOD -> good, anything else ->
failed), so both groups share DCCL id 125 and are told apart by ``state``.
"""

from __future__ import annotations

from gateway.goby.intervehicle import Publisher, TransporterConfig
from gateway.goby.portal.group import Group
from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__OK, VehicleHealth
from translators.trail import groups
from translators.trail.protobuf.health_status_pb2 import HealthStatus

#: (max_queue, value_base) of each group's publication, as the course's health monitor sets them.
BUFFER = {groups.health_status_good: (1, 50), groups.health_status_failed: (1, 500)}


def set_health_group(status: HealthStatus, group: Group) -> None:
    """The course's publisher group function: ``state`` from the group (GOOD or FAILED)."""
    if group.numeric == groups.health_status_good.numeric:
        status.state = HealthStatus.GOOD
    elif group.numeric == groups.health_status_failed.numeric:
        status.state = HealthStatus.FAILED


def health_group(status: HealthStatus) -> Group:
    """The course's subscriber group function: GOOD is ``health_status_good``, any other state ``_failed``."""
    return groups.health_status_good if status.state == HealthStatus.GOOD else groups.health_status_failed


def report_group(report: VehicleHealth) -> Group:
    """Where the monitor sends a coroner report: HEALTH__OK to ``health_status_good``, anything else ``_failed``."""
    return groups.health_status_good if report.state == HEALTH__OK else groups.health_status_failed


def health_publisher(group: Group) -> Publisher:
    """The monitor's publication options on ``group``: ``buffer { max_queue value_base }`` and the group function."""
    max_queue, value_base = BUFFER[group]
    cfg = TransporterConfig()
    cfg.intervehicle.buffer.max_queue = max_queue
    cfg.intervehicle.buffer.value_base = value_base
    return Publisher(cfg=cfg, set_group=set_health_group)


def health_status(report: VehicleHealth, now_micro: int) -> tuple[Group, HealthStatus]:
    """The group and the HealthStatus (``timestamp`` = ``now_micro``, ``state`` as the group function sets it) the
    monitor publishes for one coroner report."""
    group = report_group(report)
    status = HealthStatus(timestamp=now_micro)
    set_health_group(status, group)
    return group, status
