"""The trail mission's groups, spelled as the Goby3 course's ``src/lib/groups.h`` (post-homework3).

Intervehicle carries only the numeric part (``usv_nav`` 1 and ``auv_nav`` 2 share DCCL id 124 and are told apart by
the message's ``type``: see :mod:`translators.trail.nav_convert`); interprocess matches on the name.
"""

from __future__ import annotations

from gateway.goby.portal.group import Group
from translators.usv.groups import usv_command

BROADCAST_GROUP = 0  # goby::middleware::Group::broadcast_group

example = Group("goby3_course::example")
usv_nav = Group("goby3_course::usv_nav", 1)
auv_nav = Group("goby3_course::auv_nav", 2)

health_status = Group("goby3_course::health_status", BROADCAST_GROUP)
health_status_good = Group("goby3_course::health_status_good", 1)
health_status_failed = Group("goby3_course::health_status_failed", 2)

auv_command = Group("goby3_course::auv_command", BROADCAST_GROUP)

__all__ = ["BROADCAST_GROUP", "auv_command", "auv_nav", "example", "health_status", "health_status_failed",
           "health_status_good", "usv_command", "usv_nav"]
