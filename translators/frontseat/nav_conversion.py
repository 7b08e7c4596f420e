"""NodeStatus -> MOOS strings and numbers: the NAV_* set pHelmIvP reads, and NODE_REPORT lines for contacts.

Pure functions (no sockets, no threads) so the exact values and formats can be tested against reference data;
the translators only move their results onto the wire.
"""

from __future__ import annotations

import math

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, Source, VehicleType
from util.geodesy import UTMGeodesy

MoosValue = float | str
MoosPost = tuple[str, MoosValue]


def format_g15(value: float) -> str:
    """A number as a C++ stream prints it after ``std::setprecision(15)`` (``%.15g``), as Goby writes times."""
    return f"{value:.15g}"


def format_report_number(value: float) -> str:
    """A NODE_REPORT number: rounded to 1e-3 and printed like ``%.15g``, but never in exponent form.

    pHelmIvP's report parser rejects the whole report when a number reads ``-9.3e-10`` (as ``%.15g`` prints a
    y of almost zero); the course never hit this because its values were DCCL-quantized to 0.1 m / 1 degree.
    """
    rounded = round(value, 3) + 0.0  # + 0.0 turns -0.0 into 0.0
    text = f"{rounded:.15g}"
    if "e" in text:  # only for |value| >= 1e15 after rounding
        text = f"{rounded:.3f}".rstrip("0").rstrip(".")
    return text


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


def normalized_heading(degrees: float) -> float:
    """``degrees`` in [0, 360): a tiny negative angle must not round up to 360 once shifted."""
    heading = math.fmod(degrees, 360.0)
    if heading < 0.0:
        heading += 360.0
        if heading >= 360.0:
            heading = 0.0
    return heading + 0.0  # turns -0.0 into 0.0


def node_report(status: NodeStatus, geodesy: UTMGeodesy | None = None, name: str | None = None) -> str:
    """A NODE_REPORT line in the Goby3 course's format, which pHelmIvP's contact parser accepts.

    ``NAME=..,TYPE=..,TIME=..,X=..,Y=..,DEPTH=..,HDG=..,SPD=..``; every number is printed with 15 significant
    digits because the course sets the stream precision just before TIME and it sticks; X, Y, DEPTH, HDG and SPD
    are first rounded to 1e-3 so that they never print in exponent form (see :func:`format_report_number`).
    HDG is normalised to [0, 360) as the course's nav conversion does. NAME is ``name`` if given, else the status's name, else its
    type name.
    """
    x, y = local_xy(status, geodesy)
    vehicle_name = name or status.name or vehicle_type_name(status)
    heading = normalized_heading(round(normalized_heading(status.pose.heading), 3))  # 359.9999 -> 0, not 360
    fields = [
        ("NAME", vehicle_name),
        ("TYPE", vehicle_type_name(status)),
        ("TIME", format_g15(status.time)),
        ("X", format_report_number(x)),
        ("Y", format_report_number(y)),
        ("DEPTH", format_report_number(status.global_fix.depth)),
        ("HDG", format_report_number(heading)),
        ("SPD", format_report_number(status.speed.over_ground)),
    ]
    return ",".join(f"{key}={value}" for key, value in fields)
