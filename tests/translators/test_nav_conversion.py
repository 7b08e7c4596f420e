"""NodeStatus -> NAV_* and NODE_REPORT: exact variables, order, units and the UTM reference values."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, Source
from tests.geodesy_reference import ORIGIN, REFERENCE
from translators.frontseat.nav_conversion import format_g15, nav_posts, node_report
from translators.node_report_codec import course_number
from util.geodesy import UTMGeodesy

TOLERANCE_M = 0.005  # the reference lat/lon carry 8 decimals, about 1 mm


def make_status(lat: float, lon: float, **extra: object) -> NodeStatus:
    status = NodeStatus(time=1754431234.5625, name="usv")
    status.global_fix.lat = lat
    status.global_fix.lon = lon
    status.pose.SetInParent()
    status.speed.over_ground = 1.5
    for path, value in extra.items():
        target = status
        *parents, leaf = path.split("__")
        for parent in parents:
            target = getattr(target, parent)
        setattr(target, leaf, value)
    return status


@pytest.mark.parametrize(("xy", "latlon"), REFERENCE)
def test_nav_x_y_match_the_moos_geodesy_reference_values(xy, latlon):
    posts = dict(nav_posts(make_status(*latlon), UTMGeodesy(*ORIGIN)))
    assert posts["NAV_X"] == pytest.approx(xy[0], abs=TOLERANCE_M)
    assert posts["NAV_Y"] == pytest.approx(xy[1], abs=TOLERANCE_M)
    assert posts["NAV_LAT"] == latlon[0]
    assert posts["NAV_LONG"] == latlon[1]


def test_without_a_datum_nav_x_y_come_from_the_local_fix():
    status = make_status(43.0, -70.0, local_fix__x=12.5, local_fix__y=-3.25)
    posts = dict(nav_posts(status, None))
    assert (posts["NAV_X"], posts["NAV_Y"]) == (12.5, -3.25)
    assert "NAV_Z" not in posts


def test_minimal_status_posts_the_unconditional_variables_in_goby_order():
    names = [name for name, _ in nav_posts(make_status(43.8253, -70.3304), UTMGeodesy(*ORIGIN))]
    # Source unset reads as GPS (proto2 default: the first enum value), so GPS_UPDATE_RECEIVED is posted.
    assert names == ["NAV_X", "NAV_Y", "NAV_LAT", "NAV_LONG", "NAV_SPEED", "GPS_UPDATE_RECEIVED"]


def test_full_status_posts_every_variable_with_the_originals_units_and_order():
    status = make_status(
        43.8253, -70.3304,
        local_fix__x=1.0, local_fix__y=2.0, local_fix__z=-7.5,
        global_fix__depth=7.5, global_fix__altitude=12.0,
        pose__heading=90.0, pose__pitch=10.0, pose__roll=-5.0,
    )
    posts = nav_posts(status, UTMGeodesy(*ORIGIN))
    assert [name for name, _ in posts] == [
        "NAV_X", "NAV_Y", "NAV_LAT", "NAV_LONG", "NAV_Z", "NAV_DEPTH", "NAV_HEADING", "NAV_YAW",
        "NAV_SPEED", "NAV_PITCH", "NAV_ROLL", "NAV_ALTITUDE", "GPS_UPDATE_RECEIVED",
    ]
    values = dict(posts)
    assert values["NAV_Z"] == -7.5
    assert values["NAV_DEPTH"] == 7.5
    assert values["NAV_HEADING"] == 90.0
    assert values["NAV_YAW"] == pytest.approx(-math.pi / 2)  # negated heading in radians, no 90 degree offset
    assert values["NAV_SPEED"] == 1.5
    assert values["NAV_PITCH"] == pytest.approx(math.radians(10.0))
    assert values["NAV_ROLL"] == pytest.approx(math.radians(-5.0))
    assert values["NAV_ALTITUDE"] == 12.0
    assert values["GPS_UPDATE_RECEIVED"] == "Timestamp=1754431234.5625"


def test_heading_is_not_normalised_on_nav_heading():
    values = dict(nav_posts(make_status(43.8, -70.3, pose__heading=-30.0)))
    assert values["NAV_HEADING"] == -30.0
    assert values["NAV_YAW"] == pytest.approx(math.radians(30.0))


def test_gps_update_is_only_posted_for_a_gps_position_source():
    status = make_status(43.8, -70.3)
    status.source.position = Source.USBL
    assert "GPS_UPDATE_RECEIVED" not in dict(nav_posts(status))
    status.source.position = Source.GPS
    assert dict(nav_posts(status))["GPS_UPDATE_RECEIVED"].startswith("Timestamp=")


def test_format_g15_matches_cpp_setprecision_15():
    assert format_g15(1754431234.56789012) == "1754431234.56789"
    assert format_g15(0.1) == "0.1"
    assert format_g15(-0.0) == "-0"
    assert format_g15(1e20) == "1e+20"


def test_node_report_has_the_course_format():
    status = make_status(43.82494863, -70.32964602, pose__heading=-90.0, global_fix__depth=12.25)
    status.type = 20  # USV
    report = node_report(status, UTMGeodesy(*ORIGIN))
    keys = [item.split("=", 1)[0] for item in report.split(",")]
    assert keys == ["NAME", "TYPE", "TIME", "X", "Y", "DEPTH", "HDG", "SPD"]
    fields = dict(item.split("=", 1) for item in report.split(","))
    assert fields["NAME"] == "usv"
    assert fields["TYPE"] == "USV"
    assert fields["TIME"] == "1754431234.5625"
    assert float(fields["X"]) == pytest.approx(60.0, abs=TOLERANCE_M)
    assert float(fields["Y"]) == pytest.approx(-40.0, abs=TOLERANCE_M)
    assert fields["DEPTH"] == "12.25"
    assert fields["HDG"] == "270"  # normalised to [0, 360)
    assert fields["SPD"] == "1.5"


def test_node_report_name_falls_back_to_the_type_and_can_be_overridden():
    status = make_status(43.8, -70.3)
    status.ClearField("name")
    status.type = 10  # AUV
    assert node_report(status).startswith("NAME=AUV,TYPE=AUV,")
    assert node_report(status, name="AUV_0").startswith("NAME=AUV_0,TYPE=AUV,")


@settings(max_examples=60, deadline=None)
@given(x=st.floats(-20000, 20000), y=st.floats(-20000, 20000))
def test_nav_x_y_invert_the_datums_grid(x, y):
    """Any point placed on the datum's grid comes back as the same NAV_X/NAV_Y (to a millimetre)."""
    geodesy = UTMGeodesy(*ORIGIN)
    lat, lon = geodesy.to_geo(x, y)
    posts = dict(nav_posts(make_status(lat, lon), geodesy))
    assert posts["NAV_X"] == pytest.approx(x, abs=0.001)
    assert posts["NAV_Y"] == pytest.approx(y, abs=0.001)


@settings(max_examples=60, deadline=None)
@given(heading=st.floats(-1000, 1000))
def test_node_report_heading_is_always_in_0_360(heading):
    status = make_status(43.8, -70.3, pose__heading=heading)
    hdg = float(dict(item.split("=", 1) for item in node_report(status).split(","))["HDG"])
    assert 0.0 <= hdg < 360.0
    difference = (hdg - heading) % 360.0
    assert min(difference, 360.0 - difference) <= 0.0005 + 1e-9  # the same direction, to the 1e-3 printed


@pytest.mark.parametrize(
    ("value", "text"),
    [(-9.31322574615479e-10, "0"), (200.000000000407, "200"), (-0.0, "-0"), (1.25, "1.25"), (-40.0001234, "-40"),
     (12.3456, "12.346"), (1e20, "100000000000000000000")],
)
def test_report_numbers_never_use_exponents(value, text):
    """pHelmIvP drops a whole NODE_REPORT whose number reads like -9.3e-10 (checked against the real helm).

    An exact -0.0 prints ``-0`` as the course's C++ stream does (its ``DEPTH = -z`` for a surface vehicle)."""
    assert course_number(value) == text


def test_heading_just_below_360_reports_0():
    status = make_status(43.8, -70.3, pose__heading=359.99995)
    assert ",HDG=0," in node_report(status)
