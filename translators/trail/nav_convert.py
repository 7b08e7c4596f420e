"""The course's ``nav_convert`` (goby3-course ``src/lib/nav/convert.h``): NodeStatus <-> DCCL NavigationReport.

Pure functions of their inputs, so the values can be checked against the course's rules one by one:

- NodeStatus -> NavigationReport: ``vehicle`` from the manager's config; ``time`` *unwarped* (DCCL's time2 codec
  decodes against the receiver's real clock); x/y from the global fix on the application's geodesy; ``z = -depth``;
  type GLIDER/AUV -> AUV, USV/USV_POWERED/USV_SAILING -> USV, SHIP -> TOPSIDE, else OTHER; heading in [0, 360).
- NavigationReport -> NodeStatus: global fix from x/y; depth ``-z``; local fix x/y/z; time *rewarped*; name
  ``USV`` / ``AUV_<vehicle - 2>`` / the type name; type AUV -> AUV, USV -> USV, TOPSIDE -> SHIP, else OTHER.

The group carried in the message (``nav_set_group``/``nav_group``, the course's ``src/lib/nav/intervehicle.h``)
lives here too: both navigation groups share DCCL id 124, so ``type`` is what tells them apart on the link.
"""

from __future__ import annotations

from frontseat.protobuf import frontseat_data_pb2 as fs
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.portal.group import Group
from gateway.goby.portal.timeutil import SystemClock, micro_to_si, si_to_micro
from translators.errors import TranslatorError
from translators.node_report_codec import NodeReport, angle360
from translators.trail import groups
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from util.geodesy import UTMGeodesy

AUV_INDEX_TO_MODEM_ID_OFFSET = 2  # the course's default: the vehicle id of AUV 0 (USV is 1)


class NavGroupError(TranslatorError, ValueError):
    """A navigation report published on, or received with, a group/type the course's nav functions refuse."""


_TO_DCCL_TYPE = {
    fs.AUV: NavigationReport.AUV, fs.GLIDER: NavigationReport.AUV,
    fs.USV: NavigationReport.USV, fs.USV_POWERED: NavigationReport.USV, fs.USV_SAILING: NavigationReport.USV,
    fs.SHIP: NavigationReport.TOPSIDE,
}
_TO_FRONTSEAT_TYPE = {
    NavigationReport.AUV: fs.AUV, NavigationReport.USV: fs.USV, NavigationReport.TOPSIDE: fs.SHIP,
}


def vehicle_name(nav: NavigationReport, auv_index_to_modem_id_offset: int = AUV_INDEX_TO_MODEM_ID_OFFSET) -> str:
    """``AUV_<vehicle - offset>`` for an AUV, else the type's name (``USV``, ``TOPSIDE``, ``OTHER``)."""
    name = NavigationReport.VehicleClass.Name(nav.type)
    if nav.type == NavigationReport.AUV:
        return f"{name}_{nav.vehicle - auv_index_to_modem_id_offset}"
    return name


def to_navigation_report(status: NodeStatus, vehicle: int, geodesy: UTMGeodesy,
                         clock: SystemClock) -> NavigationReport:
    """The DCCL report a manager sends for its own NodeStatus (time unwarped on ``clock``)."""
    nav = NavigationReport(vehicle=vehicle)
    nav.time = micro_to_si(clock.unwarp(si_to_micro(status.time)))
    nav.type = _TO_DCCL_TYPE.get(status.type, NavigationReport.OTHER)
    nav.x, nav.y = geodesy.to_local(status.global_fix.lat, status.global_fix.lon)
    nav.z = -status.global_fix.depth
    nav.speed_over_ground = status.speed.over_ground
    nav.heading = angle360(status.pose.heading)
    return nav


def to_node_status(nav: NavigationReport, geodesy: UTMGeodesy, clock: SystemClock) -> NodeStatus:
    """The NodeStatus the topside publishes for a received report (time rewarped on ``clock``)."""
    status = NodeStatus(time=rewarped_time(nav, clock), name=vehicle_name(nav))
    status.global_fix.lat, status.global_fix.lon = geodesy.to_geo(nav.x, nav.y)
    status.global_fix.depth = -nav.z
    status.local_fix.x, status.local_fix.y, status.local_fix.z = nav.x, nav.y, nav.z
    status.pose.heading = nav.heading
    status.speed.over_ground = nav.speed_over_ground
    status.type = _TO_FRONTSEAT_TYPE.get(nav.type, fs.OTHER)
    return status


def rewarped_time(nav: NavigationReport, clock: SystemClock) -> float:
    """The report's (real-clock) time on ``clock``'s warped time line, in seconds."""
    return micro_to_si(clock.warp(si_to_micro(nav.time)))


def contact_report(nav: NavigationReport, clock: SystemClock) -> NodeReport:
    """The fields of IvPHelmTranslation's NODE_REPORT for a received report (format it with
    :func:`translators.node_report_codec.format_course_report`)."""
    return NodeReport(name=vehicle_name(nav), type=NavigationReport.VehicleClass.Name(nav.type),
                      time=rewarped_time(nav, clock), x=nav.x, y=nav.y, depth=-nav.z, heading=nav.heading,
                      speed=nav.speed_over_ground)


def nav_set_group(nav: NavigationReport, group: Group) -> None:
    """The publisher's set-group function: write the group into ``type`` (usv_nav -> USV, auv_nav -> AUV)."""
    if group == groups.usv_nav:
        nav.type = NavigationReport.USV
    elif group == groups.auv_nav:
        nav.type = NavigationReport.AUV
    else:
        raise NavGroupError(f"Unsupported Group {group} for use with navigation publications")


def nav_group(nav: NavigationReport) -> Group:
    """The subscriber's group function: the group a received report belongs to, from its ``type``."""
    if nav.type == NavigationReport.AUV:
        return groups.auv_nav
    if nav.type == NavigationReport.USV:
        return groups.usv_nav
    raise NavGroupError(f"Unsupported VehicleClass {NavigationReport.VehicleClass.Name(nav.type)} "
                        "for use with navigation publications")
