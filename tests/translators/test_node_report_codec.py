"""The NODE_REPORT codec: the course's format byte for byte, pNodeReporter's format, and the parser."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from translators.node_report_codec import (
    NodeReport,
    NodeReportError,
    format_course_report,
    format_local_report,
    is_moos_number,
    parse_node_report,
    plain_g15,
)

# Inputs as the course's IvPHelmTranslation has them (NavigationReport values as DCCL decodes them; depth = -z),
# and the lines its C++ stream code printed for them: the course's `publish_contact_nav_to_moos` statement,
# compiled with g++ 12 on these values (heading first brought into [0, 360) by the course's nav_convert loops).
COURSE_VECTORS = [
    (("USV", "USV", 1754431234.56789, 123.4, -567.8, -0.0, 359, 1.5),
     "NAME=USV,TYPE=USV,TIME=1754431234.56789,X=123.4,Y=-567.8,DEPTH=-0,HDG=359,SPD=1.5"),
    (("AUV_0", "AUV", 35088624691.35791, -9999.9, 0.1, 40, 0, 0),
     "NAME=AUV_0,TYPE=AUV,TIME=35088624691.3579,X=-9999.9,Y=0.1,DEPTH=40,HDG=0,SPD=0"),
    (("USV", "USV", 1754431234, 0, -0.1, 1, 725, 5),
     "NAME=USV,TYPE=USV,TIME=1754431234,X=0,Y=-0.1,DEPTH=1,HDG=5,SPD=5"),
    (("AUV_3", "AUV", 1754431234.1, -45.6, -78.9, 200, -90, 2.3),
     "NAME=AUV_3,TYPE=AUV,TIME=1754431234.1,X=-45.6,Y=-78.9,DEPTH=200,HDG=270,SPD=2.3"),
    (("USV", "USV", 701772493826.7891, 10000, -10000, 6000, 360, 0.1),
     "NAME=USV,TYPE=USV,TIME=701772493826.789,X=10000,Y=-10000,DEPTH=6000,HDG=0,SPD=0.1"),
    (("AUV_1", "AUV", 1.5, 1234.5, -0.5, 12, 1079, 3.3),
     "NAME=AUV_1,TYPE=AUV,TIME=1.5,X=1234.5,Y=-0.5,DEPTH=12,HDG=359,SPD=3.3"),
    (("OTHER", "OTHER", 35088624691, -0.3, 9.9, 3, -720, 4.9),
     "NAME=OTHER,TYPE=OTHER,TIME=35088624691,X=-0.3,Y=9.9,DEPTH=3,HDG=0,SPD=4.9"),
]


@pytest.mark.parametrize(("values", "line"), COURSE_VECTORS)
def test_course_format_is_byte_identical_to_the_course(values, line):
    name, vtype, time, x, y, depth, heading, speed = values
    report = NodeReport(name=name, type=vtype, time=time, x=x, y=y, depth=depth, heading=heading, speed=speed)
    assert format_course_report(report) == line


@pytest.mark.parametrize(("value", "text"), [
    (1e20, "100000000000000000000"), (1.5e-7, "0.00000015"), (-9.31322574615479e-10, "-0.000000000931322574615479"),
    (35088624691.35791, "35088624691.3579"), (0.0, "0"), (-0.0, "-0"),
])
def test_plain_g15_keeps_the_digits_and_drops_the_exponent(value, text):
    assert plain_g15(value) == text


def test_course_format_never_writes_an_exponent_where_cpp_would():
    report = NodeReport(name="USV", type="USV", time=1e16, x=-9.3e-10, y=2e-5, depth=1e15, heading=1e-9, speed=1e-4)
    line = format_course_report(report)
    assert line == "NAME=USV,TYPE=USV,TIME=10000000000000000,X=0,Y=0,DEPTH=1000000000000000,HDG=0,SPD=0"
    assert all(is_moos_number(item.split("=", 1)[1]) for item in line.split(",")[2:])


def test_course_format_refuses_missing_or_non_finite_numbers():
    with pytest.raises(NodeReportError, match="TIME"):
        format_course_report(NodeReport(name="USV", x=1, y=2, depth=0, heading=0, speed=0))
    with pytest.raises(NodeReportError, match="NAME"):
        format_course_report(NodeReport(time=1, x=1, y=2, depth=0, heading=0, speed=0))
    with pytest.raises(NodeReportError, match="finite"):
        format_course_report(NodeReport(name="USV", time=1, x=float("nan"), y=2, depth=0, heading=0, speed=0))


@settings(max_examples=200, deadline=None)
@given(time=st.floats(0, 1e13), x=st.floats(-1e6, 1e6), y=st.floats(-1e6, 1e6), depth=st.floats(0, 6000),
       heading=st.floats(-1e4, 1e4), speed=st.floats(0, 50))
def test_every_course_line_parses_back_to_the_same_values(time, x, y, depth, heading, speed):
    line = format_course_report(NodeReport(name="USV", type="USV", time=time, x=x, y=y, depth=depth,
                                           heading=heading, speed=speed))
    back = parse_node_report(line)
    assert back.time == pytest.approx(time, rel=1e-14, abs=1e-300)
    assert (back.x, back.y, back.depth, back.speed) == pytest.approx((x, y, depth, speed), abs=0.0005 + 1e-9)
    assert 0 <= back.heading < 360
    assert min(abs(back.heading - heading % 360), 360 - abs(back.heading - heading % 360)) <= 0.0005 + 1e-9


def test_local_format_follows_node_record_get_spec():
    report = NodeReport(name="alpha", x=12.344, y=-45.6, speed=1.2, heading=108.5, depth=0.0, lat=43.824948631,
                        lon=-70.329646024, type="kayak", color="yellow", mode="DRIVE", allstop="clear", index=17,
                        yaw=0.3, time=1754431234.567, length=4)
    assert format_local_report(report) == (
        "NAME=alpha,X=12.34,Y=-45.6,SPD=1.2,HDG=108.5,DEP=0,LAT=43.82494863,LON=-70.32964602,TYPE=kayak,"
        "COLOR=yellow,MODE=DRIVE,ALLSTOP=clear,INDEX=17,YAW=-0.3228859,TIME=1754431234.57,LENGTH=4")
    assert format_local_report(report, terse=True) == (
        "NAME=alpha,X=12.34,Y=-45.6,SPD=1.2,HDG=108.5,TYPE=kayak,COLOR=yellow,MODE=DRIVE,ALLSTOP=clear,INDEX=17,"
        "TIME=1754431234.57,LENGTH=4")


def test_local_format_leaves_out_what_is_not_set():
    assert format_local_report(NodeReport(name="auv0", type="auv", index=0, length=2, time=5)) == \
        "NAME=auv0,TYPE=auv,TIME=5,LENGTH=2"


def test_parser_reads_every_form_phelmivp_accepts():
    report = parse_node_report(
        " name = usv , Type=USV,utc_time=+100.5,x=-1.5,Y=2,LAT=43.8,lon=-70.3,speed=1.25,heading=350,dep=3,"
        "LEN=4,alt=7,YAW=0.1,SPD_OG=1,HDG_OG=2,COLOR=red,GROUP=blue,MODE=DRIVE,ALLSTOP=clear,INDEX=3,"
        "THRUST_MODE_REVERSE=TRUE,TRAJECTORY={1,2:3,4},RIDER=x=1,,")
    assert (report.name, report.type, report.time, report.x, report.y) == ("usv", "USV", 100.5, -1.5, 2.0)
    assert (report.lat, report.lon, report.speed, report.heading, report.depth) == (43.8, -70.3, 1.25, 350, 3)
    assert (report.length, report.altitude, report.yaw, report.speed_og, report.heading_og) == (4, 7, 0.1, 1, 2)
    assert (report.color, report.group, report.mode, report.allstop, report.index) == ("red", "blue", "DRIVE",
                                                                                       "clear", 3)
    assert report.thrust_mode_reverse and report.trajectory == "1,2:3,4"
    assert report.properties == {"RIDER": "x=1"}
    assert parse_node_report("NAME=a,SPD=1,SPEED=2,DEPTH=3,DEP=4").speed == 2  # the last of two aliases counts
    assert parse_node_report("NAME=a,DEPTH=3,DEP=4").depth == 4


@pytest.mark.parametrize(("line", "fault"), [
    ("NAME=USV,X=1e-05,Y=2", "X=1e-05 is not a number"),
    ("NAME=USV,TIME=now", "TIME=now is not a number"),
    ("NAME=USV,HDG=", "HDG= is not a number"),
    ("NAME=USV,X=1 2", "X=1 2 is not a number"),
    ("NAME=USV,garbage", "'garbage' is not KEY=value"),
    ("NAME=USV,=5", "'=5' is not KEY=value"),
    ("NAME=USV,INDEX=first", "INDEX=first is not a number"),
])
def test_parser_names_the_bad_field(line, fault):
    with pytest.raises(NodeReportError) as info:
        parse_node_report(line)
    assert str(info.value) == fault


def test_moos_number_is_mbutils_isnumber():
    for good in ("1", "-1", "+1", "1.", ".5", "-.5", "0010", "123.456"):
        assert is_moos_number(good), good
    for bad in ("", "-", ".", "1e5", "1E5", "inf", "nan", " 1", "1-", "1.2.3", "--1", "0x10"):
        assert not is_moos_number(bad), bad
