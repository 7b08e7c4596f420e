"""The course's nav_convert rules, one by one, and the NODE_REPORT a NavigationReport becomes after the real DCCL
round trip (golden strings written from the course's C++ stream settings: 15 significant digits, no exponent)."""

from __future__ import annotations

import pytest

from frontseat.protobuf import frontseat_data_pb2 as fs
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.dccl import Codec
from gateway.goby.portal.timeutil import SystemClock
from translators.node_report_codec import format_course_report
from translators.trail import groups
from translators.trail.nav_convert import (
    NavGroupError,
    contact_report,
    nav_group,
    nav_set_group,
    to_navigation_report,
    to_node_status,
    vehicle_name,
)
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from util.geodesy import UTMGeodesy

KAUAI = (21.590491, -159.534166)  # the course's origin
REFERENCE_S = 1_700_000_000  # the warp's reference time
WARP = 5


@pytest.fixture(scope="module")
def geodesy() -> UTMGeodesy:
    return UTMGeodesy(*KAUAI)


def warped_clock() -> SystemClock:
    return SystemClock(use_sim_time=True, warp_factor=WARP, reference_micro=REFERENCE_S * 1_000_000)


def status_at(geodesy: UTMGeodesy, x: float, y: float, **fields: object) -> NodeStatus:
    status = NodeStatus(time=fields.pop("time", REFERENCE_S + 100.0), type=fields.pop("type", fs.USV))
    status.global_fix.lat, status.global_fix.lon = geodesy.to_geo(x, y)
    status.global_fix.depth = fields.pop("depth", 0.0)
    status.pose.heading = fields.pop("heading", 0.0)
    status.speed.over_ground = fields.pop("speed", 1.5)
    assert not fields
    return status


def test_to_dccl_unwarps_time_and_takes_xy_from_the_global_fix(geodesy):
    status = status_at(geodesy, 123.4, -56.7, depth=12.5, heading=-45.0, speed=1.8, time=REFERENCE_S + 100.0)
    status.local_fix.x, status.local_fix.y = 9999.0, 9999.0  # ignored: the course projects the global fix
    nav = to_navigation_report(status, 3, geodesy, warped_clock())
    assert nav.vehicle == 3
    assert nav.time == REFERENCE_S + 20.0  # 100 warped seconds after the reference are 20 real ones
    assert nav.x == pytest.approx(123.4, abs=1e-6) and nav.y == pytest.approx(-56.7, abs=1e-6)
    assert nav.z == -12.5
    assert nav.speed_over_ground == 1.8
    assert nav.heading == 315.0
    assert nav.type == NavigationReport.USV


@pytest.mark.parametrize(("heading", "normalised"), [(0.0, 0.0), (359.5, 359.5), (360.0, 0.0), (725.0, 5.0),
                                                     (-45.0, 315.0), (-720.0, 0.0), (-1e-12, 360.0 - 1e-12)])
def test_heading_is_normalised_to_0_360(geodesy, heading, normalised):
    nav = to_navigation_report(status_at(geodesy, 0, 0, heading=heading), 1, geodesy, SystemClock())
    assert nav.heading == pytest.approx(normalised, abs=1e-9)
    assert 0.0 <= nav.heading < 360.0


@pytest.mark.parametrize(("frontseat_type", "dccl_type"), [
    (fs.AUV, NavigationReport.AUV), (fs.GLIDER, NavigationReport.AUV), (fs.USV, NavigationReport.USV),
    (fs.USV_POWERED, NavigationReport.USV), (fs.USV_SAILING, NavigationReport.USV),
    (fs.SHIP, NavigationReport.TOPSIDE), (fs.ROV, NavigationReport.OTHER), (fs.UNKNOWN, NavigationReport.OTHER),
    (fs.BUOY, NavigationReport.OTHER)])
def test_vehicle_types_to_dccl(geodesy, frontseat_type, dccl_type):
    status = status_at(geodesy, 0, 0, type=frontseat_type)
    assert to_navigation_report(status, 1, geodesy, SystemClock()).type == dccl_type


@pytest.mark.parametrize(("dccl_type", "frontseat_type"), [
    (NavigationReport.AUV, fs.AUV), (NavigationReport.USV, fs.USV), (NavigationReport.TOPSIDE, fs.SHIP),
    (NavigationReport.OTHER, fs.OTHER)])
def test_vehicle_types_from_dccl(geodesy, dccl_type, frontseat_type):
    nav = NavigationReport(vehicle=2, time=0, x=0, y=0, z=0, speed_over_ground=0, heading=0, type=dccl_type)
    assert to_node_status(nav, geodesy, SystemClock()).type == frontseat_type


@pytest.mark.parametrize(("vehicle", "dccl_type", "name"), [
    (2, NavigationReport.AUV, "AUV_0"), (5, NavigationReport.AUV, "AUV_3"), (1, NavigationReport.USV, "USV"),
    (1, NavigationReport.TOPSIDE, "TOPSIDE"), (9, NavigationReport.OTHER, "OTHER")])
def test_vehicle_names(vehicle, dccl_type, name):
    assert vehicle_name(NavigationReport(vehicle=vehicle, type=dccl_type)) == name


def test_unset_type_reads_as_auv_as_in_proto2():
    assert vehicle_name(NavigationReport(vehicle=4)) == "AUV_2"


def test_from_dccl_rewarps_time_and_fills_both_fixes(geodesy):
    nav = NavigationReport(vehicle=4, time=REFERENCE_S + 20.0, x=-250.5, y=1234.5, z=-30.0, speed_over_ground=2.5,
                           heading=271.0, type=NavigationReport.AUV)
    status = to_node_status(nav, geodesy, warped_clock())
    assert status.time == REFERENCE_S + 100.0
    assert status.name == "AUV_2"
    assert (status.local_fix.x, status.local_fix.y, status.local_fix.z) == (-250.5, 1234.5, -30.0)
    assert status.global_fix.depth == 30.0
    assert geodesy.to_local(status.global_fix.lat, status.global_fix.lon) == pytest.approx((-250.5, 1234.5),
                                                                                            abs=1e-6)
    assert (status.pose.heading, status.speed.over_ground) == (271.0, 2.5)
    assert status.IsInitialized()


def test_round_trip_through_dccl_bytes_gives_the_course_node_report(geodesy):
    """USV nav -> DCCL (13 bytes) -> decoded on the AUV -> NODE_REPORT, as IvPHelmTranslation posts it."""
    clock = warped_clock()
    status = status_at(geodesy, 123.44, -56.66, heading=-45.4, speed=1.54, time=REFERENCE_S + 100.0)
    nav = to_navigation_report(status, 1, geodesy, clock)
    codec = Codec()
    codec.load(NavigationReport)
    data = codec.encode(nav)
    assert len(data) == 13
    received = codec.decode(data, NavigationReport, now=REFERENCE_S + 30.0)
    assert format_course_report(contact_report(received, clock)) == (
        "NAME=USV,TYPE=USV,TIME=1700000100,X=123.4,Y=-56.7,DEPTH=-0,HDG=315,SPD=1.5")


@pytest.mark.parametrize(("nav", "expected"), [
    (NavigationReport(vehicle=3, time=REFERENCE_S + 20.5, x=-9999.9, y=0.1, z=-6000, speed_over_ground=5,
                      heading=359, type=NavigationReport.AUV),
     "NAME=AUV_1,TYPE=AUV,TIME=1700000102.5,X=-9999.9,Y=0.1,DEPTH=6000,HDG=359,SPD=5"),
    (NavigationReport(vehicle=1, time=REFERENCE_S + 0.25, x=0, y=-0.5, z=-1, speed_over_ground=0.1,
                      heading=0, type=NavigationReport.USV),
     "NAME=USV,TYPE=USV,TIME=1700000001.25,X=0,Y=-0.5,DEPTH=1,HDG=0,SPD=0.1"),
])
def test_contact_report_golden_strings(nav, expected):
    assert format_course_report(contact_report(nav, warped_clock())) == expected


def test_group_functions_follow_the_type():
    nav = NavigationReport(vehicle=1)
    nav_set_group(nav, groups.usv_nav)
    assert nav.type == NavigationReport.USV and nav_group(nav) == groups.usv_nav
    nav_set_group(nav, groups.auv_nav)
    assert nav.type == NavigationReport.AUV and nav_group(nav) == groups.auv_nav
    with pytest.raises(NavGroupError, match="Unsupported Group goby3_course::auv_command;0"):
        nav_set_group(nav, groups.auv_command)
    with pytest.raises(NavGroupError, match="Unsupported VehicleClass TOPSIDE"):
        nav_group(NavigationReport(vehicle=1, type=NavigationReport.TOPSIDE))


def test_course_group_wire_names():
    assert [str(g) for g in (groups.usv_nav, groups.auv_nav, groups.auv_command, groups.usv_command,
                             groups.health_status, groups.health_status_good, groups.health_status_failed)] == [
        "goby3_course::usv_nav;1", "goby3_course::auv_nav;2", "goby3_course::auv_command;0",
        "goby3_course::usv_command;0", "goby3_course::health_status;0", "goby3_course::health_status_good;1",
        "goby3_course::health_status_failed;2"]
