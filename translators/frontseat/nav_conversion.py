"""NodeStatus -> MOOS strings and numbers: the NAV_* set pHelmIvP reads, and NODE_REPORT lines for contacts.

Pure functions (no sockets, no threads) so the exact values and formats can be tested against reference data;
the translators only move their results onto the wire.
"""

from __future__ import annotations

import math

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, Source, VehicleType
from translators.node_report_codec import NodeReport, format_course_report
from util.geodesy import UTMGeodesy

MoosValue = float | str
MoosPost = tuple[str, MoosValue]


def format_g15(value: float) -> str:
    """A number as a C++ stream prints it after ``std::setprecision(15)`` (``%.15g``), as Goby writes times."""
    return f"{value:.15g}"


def local_xy(status: NodeStatus, geodesy: UTMGeodesy | None) -> tuple[float, float]:
    """(x, y) metres of a NodeStatus on the local grid.

    With a datum we project ``global_fix`` on the datum's UTM grid exactly as MOOSGeodesy does for pHelmIvP,
    so NAV_X/NAV_Y agree with a MOOS-IvP vehicle whatever grid the sender used for ``local_fix``. Without a
    datum we fall back to ``local_fix`` (as Goby's converter always does), 0 if unset.
    """
    if geodesy is not None and status.HasField("global_fix"):
        return geodesy.to_local(status.global_fix.lat, status.global_fix.lon)
    return status.local_fix.x, status.local_fix.y


def gps_update_value(status: NodeStatus) -> str:
    """The GPS_UPDATE_RECEIVED string: ``Timestamp=<time, 15 significant digits>``."""
    return "Timestamp=" + format_g15(status.time)


def nav_posts(status: NodeStatus, geodesy: UTMGeodesy | None = None) -> list[MoosPost]:
    """The MOOS variables Goby's frontseat translator posts for one NodeStatus, in its order.

    Angles arrive in degrees; NAV_YAW is the negated heading in radians (no 90 degree offset) and NAV_PITCH /
    NAV_ROLL are radians, as in Goby's ``convert_and_publish_node_status``. GPS_UPDATE_RECEIVED is posted when
    the position source is GPS, which proto2 also reports when the source is unset.
    """
    x, y = local_xy(status, geodesy)
    posts: list[MoosPost] = [
        ("NAV_X", x),
        ("NAV_Y", y),
        ("NAV_LAT", status.global_fix.lat),
        ("NAV_LONG", status.global_fix.lon),
    ]
    if status.local_fix.HasField("z"):
        posts.append(("NAV_Z", status.local_fix.z))
    if status.global_fix.HasField("depth"):
        posts.append(("NAV_DEPTH", status.global_fix.depth))
    if status.pose.HasField("heading"):
        posts.append(("NAV_HEADING", status.pose.heading))
        posts.append(("NAV_YAW", -math.radians(status.pose.heading)))
    posts.append(("NAV_SPEED", status.speed.over_ground))
    if status.pose.HasField("pitch"):
        posts.append(("NAV_PITCH", math.radians(status.pose.pitch)))
    if status.pose.HasField("roll"):
        posts.append(("NAV_ROLL", math.radians(status.pose.roll)))
    if status.global_fix.HasField("altitude"):
        posts.append(("NAV_ALTITUDE", status.global_fix.altitude))
    if status.source.position == Source.GPS:
        posts.append(("GPS_UPDATE_RECEIVED", gps_update_value(status)))
    return posts


def vehicle_type_name(status: NodeStatus) -> str:
    """The VehicleType enum name (``USV``, ``AUV``, ...), ``UNKNOWN`` when unset."""
    return VehicleType.Name(status.type)


def node_report(status: NodeStatus, geodesy: UTMGeodesy | None = None, name: str | None = None) -> str:
    """A NODE_REPORT line in the Goby3 course's format (:func:`translators.node_report_codec.format_course_report`).

    NAME is ``name`` if given, else the status's name, else its type name; DEPTH is the global fix's depth.
    """
    x, y = local_xy(status, geodesy)
    report = NodeReport(name=name or status.name or vehicle_type_name(status), type=vehicle_type_name(status),
                        time=status.time, x=x, y=y, depth=status.global_fix.depth, heading=status.pose.heading,
                        speed=status.speed.over_ground)
    return format_course_report(report)
