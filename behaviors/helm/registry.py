"""The behaviour types this helm knows, by their pHelmIvP names, and the entry-point group that adds more.

pHelmIvP loads third-party behaviours from shared libraries (``ivp_behavior_dir``); here an installed package
adds a ``BHV_`` type by declaring an entry point in group ``ivp_helm.behaviors`` whose name is the type and whose
value is the class::

    [project.entry-points."ivp_helm.behaviors"]
    BHV_Pulse = "my_package.pulse:PulseBehavior"

The built-in types come first (an installed package cannot replace ``BHV_Waypoint``); an entry point is imported
only when a ``.bhv`` file names its type, through the project's one loader (``util.extensions``).
"""

from __future__ import annotations

import importlib

from util.extensions import ExtensionPoint, load_extension

from .behavior import Behavior

#: The built-in types: module (in this package) and class, imported when a ``.bhv`` file first names the type (a
#: helm loads only what its mission uses: BHV_Trail's CPA tables and contact code stay out of a loitering USV's).
BEHAVIOR_TYPES: dict[str, tuple[str, str]] = {
    "BHV_Waypoint": ("bhv_waypoint", "WaypointBehavior"),
    "BHV_Loiter": ("bhv_loiter", "LoiterBehavior"),
    "BHV_ConstantSpeed": ("bhv_constant", "ConstantSpeedBehavior"),
    "BHV_ConstantHeading": ("bhv_constant", "ConstantHeadingBehavior"),
    "BHV_ConstantDepth": ("bhv_constant", "ConstantDepthBehavior"),
    "BHV_StationKeep": ("bhv_stationkeep", "StationKeepBehavior"),
    "BHV_Trail": ("bhv_trail", "TrailBehavior"),
}


def builtin_class(type_name: str) -> type[Behavior] | None:
    """The built-in class for ``type_name`` (imported now), or None."""
    where = BEHAVIOR_TYPES.get(type_name)
    if where is None:
        return None
    module = importlib.import_module(f"{__package__}.{where[0]}")
    cls: type[Behavior] = getattr(module, where[1])
    return cls

BEHAVIOR_POINT = ExtensionPoint(group="ivp_helm.behaviors", what="helm behaviour", source="a .bhv file",
                                entry_points_only=True)


def behavior_class(type_name: str) -> type[Behavior] | None:
    """The class for ``BHV_Waypoint`` etc., or None for a type neither built in nor installed.

    Raises ExtensionError when an installed entry point of that name cannot be imported, does not name a
    :class:`Behavior` subclass, or names one whose ``TYPE`` is another type.
    """
    builtin = builtin_class(type_name)
    if builtin is not None:
        return builtin
    if BEHAVIOR_POINT.entry_point(type_name) is None:
        return None
    loaded = load_extension(BEHAVIOR_POINT, type_name)
    if not (isinstance(loaded, type) and issubclass(loaded, Behavior)):
        raise BEHAVIOR_POINT.error(type_name, f"the entry point names {loaded!r}, not a Behavior subclass")
    if loaded.TYPE != type_name:
        raise BEHAVIOR_POINT.error(type_name, f"the entry point names {loaded.__qualname__}, whose TYPE is "
                                              f"{loaded.TYPE!r}")
    return loaded
