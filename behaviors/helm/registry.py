"""The behaviour types this helm knows, by their pHelmIvP names."""

from __future__ import annotations

from .behavior import Behavior
from .bhv_constant import ConstantDepthBehavior, ConstantHeadingBehavior, ConstantSpeedBehavior
from .bhv_loiter import LoiterBehavior
from .bhv_stationkeep import StationKeepBehavior
from .bhv_waypoint import WaypointBehavior

BEHAVIOR_TYPES: dict[str, type[Behavior]] = {
    cls.TYPE: cls
    for cls in (WaypointBehavior, LoiterBehavior, ConstantSpeedBehavior, ConstantHeadingBehavior,
                ConstantDepthBehavior, StationKeepBehavior)
}


def behavior_class(type_name: str) -> type[Behavior] | None:
    """The class for ``BHV_Waypoint`` etc., or None for a type this helm does not implement."""
    return BEHAVIOR_TYPES.get(type_name)
