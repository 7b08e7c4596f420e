"""BHV_Trail in the helm core (no MOOS): parameters, the three regions, postings, missing and stale contacts.

The contact USV sits at (0, 0) heading north at 1.5 m/s; with trail_angle 90 (relative) and trail_range 50 the
trail point is (50, 0), 50 m off the USV's starboard beam.
"""

from __future__ import annotations

import math

import pytest

from behaviors.helm.bhv_trail import TrailBehavior
from behaviors.helm.errors import ParamError
from behaviors.helm.helm import Helm
from behaviors.helm.info_buffer import InfoBuffer
from behaviors.helm.ivp import IvPDomain
from behaviors.helm.testing import helm_from_text

TRAIL = """\
Behavior = BHV_Trail
{
  name             = trail_usv
  contact          = usv
  decay            = 150,300
  on_no_contact_ok = false
  trail_angle      = 90
  trail_range      = 50
%s}

Behavior = BHV_ConstantDepth
{
  name     = depth
  duration = no-time-limit
  depth    = 10
}
"""
DOMAINS = ("course:0:359:360", "speed:0:4:41", "depth:0:200:201")
T0 = 1000.0


def trail_helm(extra: str = "") -> Helm:
    helm = helm_from_text(TRAIL % extra, DOMAINS, start_engaged="true", ownship="AUV0")
    assert not helm.problems, helm.problems
    helm.startup(T0 - 5)
    return helm


def step(helm: Helm, osx: float, osy: float, now: float = T0, report_time: float | None = T0,
         osh: float = 0.0) -> dict[str, list]:
    """Nav, optionally a USV report (at (0,0) heading north, 1.5 m/s, stamped ``report_time``), one iteration."""
    for var, value in (("NAV_X", osx), ("NAV_Y", osy), ("NAV_HEADING", osh), ("NAV_SPEED", 1.0),
                       ("NAV_DEPTH", 0.0)):
        helm.handle_mail(var, value, now, "sim", now)
    if report_time is not None:
        helm.handle_mail("NODE_REPORT", f"NAME=USV,TYPE=USV,TIME={report_time},X=0,Y=0,DEPTH=-0,HDG=0,SPD=1.5",
                         now, "gateway", now)
    posts: dict[str, list] = {}
    for post in helm.iterate(now):
        posts.setdefault(post.var, []).append(post.value)
    return posts


def behavior(**params: str) -> TrailBehavior:
    domain = IvPDomain()
    for spec in DOMAINS:
        domain.add(spec)
    bhv = TrailBehavior(domain, InfoBuffer(), "AUV0")
    for param, value in params.items():
        bhv.set_param(param, value)
    return bhv


def test_parameters_as_phelmivp_reads_them():
    assert behavior(trail_angle="210").trail_angle == -150  # stored as angle180
    assert behavior(trail_angle="270").trail_angle == -90
    assert behavior(trail_angle="-190").trail_angle == 170
    assert behavior(max_range="30").pwt_outer_dist == 30  # the deprecated name
    assert behavior(contact="usv").contact == "USV" and behavior(them="x").contact == "X"
    assert behavior(trail_angle_type="ABSOLUTE").angle_relative is False
    bhv = behavior(decay="150,300", time_on_leg="60", nm_radius="20", radius="5", no_alert_request="false",
                   post_trail_dist_on_idle="true", extrapolate="true", on_no_contact_ok="false")
    assert (bhv.extrapolator.decay_start, bhv.extrapolator.decay_end) == (150, 300)
    assert bhv.name == "(d)trail"
    for param, value, fault in (("radius", "-1", "out of range"), ("trail_angle_type", "sideways", "relative or"),
                                ("decay", "30,15", "START <= END"), ("decay", "30", "START,END"),
                                ("trail_range", "far", "must be a number"), ("bearing_lines", "white:0", "not sup")):
        with pytest.raises(ParamError, match=fault):
            behavior(**{param: value})


def test_no_contact_yet_halts_the_helm_with_bhv_error():
    helm = trail_helm()
    posts = step(helm, 60, 0, report_time=None)
    assert posts["BHV_ERROR"] == ["trail_usv: USV x/y/heading/speed info not found"]
    assert posts["IVPHELM_ALLSTOP"] == ["BehaviorError"]
    assert posts["DESIRED_HEADING"] == [0.0] and posts["DESIRED_DEPTH"] == [0.0]  # zeros at once, no grace
    assert "halted=true" in posts["IVPHELM_SUMMARY"][0]
    assert "BHV_STATUS" in posts and not any("name=depth" in s for s in posts["BHV_STATUS"])  # depth never ran
    posts = step(helm, 60, 0, now=T0 + 1)
    assert posts["IVPHELM_ALLSTOP"] == ["clear"] and "BHV_ERROR" not in posts
    assert posts["DESIRED_DEPTH"] == [10.0]


def test_no_contact_with_on_no_contact_ok_is_a_warning_only():
    helm = helm_from_text((TRAIL % "").replace("on_no_contact_ok = false", "on_no_contact_ok = true"), DOMAINS,
                          start_engaged="true")
    helm.startup(T0 - 5)
    posts = step(helm, 60, 0, report_time=None)
    assert posts["BHV_WARNING"] == ["trail_usv: USV x/y/heading/speed info not found"]
    assert posts["IVPHELM_ALLSTOP"] == ["MissingDecVars:course,speed"]
    assert "BHV_ERROR" not in posts


def test_inside_radius_matches_the_contacts_heading_and_speed():
    posts = step(trail_helm(), 52, 1)
    assert posts["REGION"] == ["Inside radius"]
    assert posts["TRAIL_DISTANCE"] == [2.0]
    assert posts["TRAIL_SPEED"] == [1.5]
    assert posts["VIEW_POINT"] == ["x=50,y=0,label=AUV0_trailpoint"]
    assert posts["PURSUIT"] == [1.0] and posts["TRAIL_RELEVANCE"] == [1.0] and posts["TRAIL_CTR"] == [1.0]
    assert posts["DESIRED_HEADING"] == [0.0] and posts["DESIRED_SPEED"] == [pytest.approx(1.5)]
    assert posts["DESIRED_DEPTH"] == [10.0]


@pytest.mark.parametrize(("osx", "osy", "heading", "trail_speed", "desired_speed"), [
    (50, -10, 0.0, 1.9, 1.9),  # 10 m behind: 1.5 * (1 + 0.5 * 10/20) = 1.875, aim straight ahead
    (60, 10, 315.0, 1.1, 1.1),  # 10 m ahead and 10 m out: 1.5 * (1 - 0.25) = 1.125, aim at (50, 20)
])
def test_inside_nm_radius_aims_ahead_of_the_trail_point_and_adjusts_speed(osx, osy, heading, trail_speed,
                                                                            desired_speed):
    posts = step(trail_helm(), osx, osy)
    assert posts["REGION"] == ["Inside nm_radius"]
    assert posts["TRAIL_DISTANCE"] == [float(round(math.hypot(osx - 50, osy)))]
    assert posts["TRAIL_HEADING"] == [heading]
    assert posts["TRAIL_SPEED"] == [pytest.approx(trail_speed)]
    assert posts["DESIRED_HEADING"] == [heading] and posts["DESIRED_SPEED"] == [pytest.approx(desired_speed)]


def test_outside_nm_radius_closes_on_the_moving_trail_point_fast():
    posts = step(trail_helm(), 50, -100)
    assert posts["REGION"] == ["Outside nm_radius"]
    assert posts["TRAIL_DISTANCE"] == [100.0]
    assert "TRAIL_SPEED" not in posts and "TRAIL_HEADING" not in posts
    assert posts["DESIRED_HEADING"][0] in (0.0, 359.0, 1.0)  # straight up the point's track
    assert posts["DESIRED_SPEED"][0] >= 3.5  # the point moves away at 1.5 m/s: catch it up
    posts = step(trail_helm(), 150, 0)  # abeam, 100 m out: cut in ahead of the point
    heading = posts["DESIRED_HEADING"][0]
    assert 270 < heading < 360 and posts["DESIRED_SPEED"][0] >= 2.5


def test_the_contact_is_extrapolated_to_the_helm_time_and_stale_contacts_give_nothing():
    helm = trail_helm()
    posts = step(helm, 50, 15, now=T0 + 10, report_time=T0)  # 10 s later the USV is 15 m further north
    assert posts["VIEW_POINT"] == ["x=50,y=15,label=AUV0_trailpoint"]
    assert posts["REGION"] == ["Inside radius"]
    posts = step(helm, 50, 15, now=T0 + 301, report_time=T0)  # older than decay_end: no function, no error
    assert posts["IVPHELM_ALLSTOP"] == ["MissingDecVars:course,speed"]
    assert "REGION" not in posts and "BHV_ERROR" not in posts


def test_absolute_angle_and_outer_distance():
    posts = step(trail_helm("  trail_angle_type = absolute\n  trail_angle = 180\n"), 0, -52)
    assert posts["VIEW_POINT"] == ["x=0,y=-50,label=AUV0_trailpoint"] and posts["REGION"] == ["Inside radius"]
    posts = step(trail_helm("  pwt_outer_dist = 100\n"), 200, 0)
    assert posts["TRAIL_RELEVANCE"] == [0.0] and posts["PURSUIT"] == [0.0]
    assert posts["TRAIL_RANGE"] == [200.0] and posts["MAX_RANGE"] == [100.0]
    assert "REGION" not in posts and posts["IVPHELM_ALLSTOP"] == ["MissingDecVars:course,speed"]


def test_going_idle_erases_the_trail_point_and_keeps_posting_the_distance():
    helm = helm_from_text("initialize STATE = TRAIL\n" + (TRAIL % "  condition = STATE = TRAIL\n"), DOMAINS,
                          start_engaged="true", ownship="AUV0")
    helm.startup(T0 - 5)
    step(helm, 52, 1)
    helm.handle_mail("STATE", "RECOVER", T0, "gateway", T0)
    posts = step(helm, 70, 1, now=T0 + 1, report_time=None)
    assert posts["PURSUIT"] == [0.0]
    assert posts["VIEW_POINT"] == ["x=50,y=0,active=false,label=AUV0_trailpoint"]  # the last point shown
    assert posts["TRAIL_DISTANCE"] == [20.0]  # to the point recomputed while idle, (50, 1.5)
    assert "REGION" not in posts
