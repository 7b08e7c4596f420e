"""The helm core in simulated time (no MOOS): states, all-stop, flags, and each behaviour's geometry."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from .core_loop import CoreLoop, make_helm
from .kinematic_vehicle import KinematicModel
from .moos_harness import bhv_block, ring_stats

WAYPOINTS = """\
initialize DEPLOY = false
Behavior = BHV_Waypoint
{
  name = survey
  condition = DEPLOY = true
  endflag = RETURN = true
  endflag = SUMMARY=speed=$[SPEED]
  wptflag = NEXT=$(NX),$(NY)
  activeflag = INFO=$[OWNSHIP]:$[BHVNAME]:$[BHVTYPE]
  idleflag = IDLE_SEEN = true
  configflag = CRUISE_SPD = $[SPEED]
  speed = 2.0
  capture_radius = 5
  slip_radius = 15
  points = 0,60:60,60:60,0
}
"""


def test_park_until_override_then_drive_and_allstop_postings(tmp_path: Path) -> None:
    helm = make_helm(tmp_path, WAYPOINTS)
    loop = CoreLoop(helm)
    assert loop.values("DEPLOY") == ["false"] and loop.values("IVPHELM_DOMAIN") == ["course,0,359,360:speed,0,4,41"]
    loop.run(3)
    assert set(loop.values("IVPHELM_STATE")) == {"PARK"}
    assert loop.values("IVPHELM_ALLSTOP") == ["ManualOverride"]  # once, not every tick
    assert loop.values("DESIRED_HEADING") == [0.0] and loop.values("DESIRED_SPEED") == [0.0]
    loop.poke("MOOS_MANUAL_OVERRIDE", 0.0)  # a double has no effect
    loop.run(1)
    assert loop.last("IVPHELM_STATE") == "PARK"
    loop.poke("MOOS_MANUAL_OVERRIDE", "false")
    loop.run(3)
    assert loop.last("IVPHELM_STATE") == "DRIVE"
    # nothing active: NothingToDo twice (one-iteration grace), then one set of zeros
    assert loop.values("IVPHELM_ALLSTOP") == ["ManualOverride", "NothingToDo", "NothingToDo"]
    assert loop.values("DESIRED_SPEED") == [0.0, 0.0]
    assert loop.values("IDLE_SEEN") == ["true"] and loop.values("CRUISE_SPD") == ["$[SPEED]"]
    loop.poke("DEPLOY", "true")
    loop.run(2)
    assert loop.values("IVPHELM_ALLSTOP")[-1] == "clear"
    assert loop.values("INFO") == ["alpha:survey:BHV_Waypoint"]
    assert loop.last("DESIRED_SPEED") == pytest.approx(2.0) and loop.last("DESIRED_HEADING") == 0.0
    assert loop.last("IVPHELM_BHV_ACTIVE") == "survey"
    loop.poke("MOOS_MANUAL_OVERRIDE", "true")
    loop.run(1)
    assert loop.last("IVPHELM_STATE") == "PARK" and loop.values("IVPHELM_ALLSTOP")[-1] == "ManualOverride"
    assert loop.last("DESIRED_SPEED") == 0.0


def test_helm_waits_for_nav_before_anything(tmp_path: Path) -> None:
    helm = make_helm(tmp_path, WAYPOINTS, start_engaged="true")
    helm.startup(0.0)
    posts = helm.iterate(5.0) + helm.iterate(6.0)
    assert [p.var for p in posts] == ["IVPHELM_STATE", "IVPHELM_STATE"]
    assert posts[0].value == "DRIVE"


def test_waypoints_reached_in_order_then_endflags(tmp_path: Path) -> None:
    loop = CoreLoop(make_helm(tmp_path, WAYPOINTS, start_engaged="true"))
    loop.poke("DEPLOY", "true")
    assert loop.run(300, until=lambda: loop.values("RETURN"))
    # on each advance (no wptflag_on_start) and twice at completion, where 19.8.1's next point is still the last one
    assert loop.values("NEXT") == ["60,60", "60,0", "60,0", "60,0"]
    assert loop.values("WPT_INDEX") == [0.0, 1.0, 2.0]
    assert loop.values("SUMMARY") == ["speed=$[SPEED]"]  # 19.8.1 expands only OWNSHIP/BHVNAME/BHVTYPE/CONTACT
    assert loop.last("WPT_STAT") == "behavior-name=survey,completed"
    # each waypoint was passed within the slip radius, and the capture radius held for most
    for px, py in [(0, 60), (60, 60), (60, 0)]:
        closest = min(math.hypot(x - px, y - py) for _, x, y, _, _ in loop.model.track)
        assert closest < 15
    loop.run(2)
    assert loop.values("IVPHELM_ALLSTOP")[-2:] == ["NothingToDo", "NothingToDo"]
    assert helm_names(loop) == []  # the completed non-perpetual behaviour was removed


def helm_names(loop: CoreLoop) -> list[str]:
    return [b.name for b in loop.helm.engine.behaviors]


LOITER = """\
initialize DEPLOY_STATE = IDLE
Behavior = BHV_Loiter
{
  name = loiter
  condition = DEPLOY_STATE = POLYGON
  updates = POLYGON_UPDATES
  speed = 2.0
  clockwise = %s
  center_activate = %s
  polygon = radial:: x=0,y=0,radius=60,pts=8
}
"""


@pytest.mark.parametrize("clockwise", [True, False])
def test_loiter_acquires_then_circles_in_the_set_direction(tmp_path: Path, clockwise: bool) -> None:
    helm = make_helm(tmp_path, LOITER % (str(clockwise).lower(), "false"), start_engaged="true")
    loop = CoreLoop(helm, KinematicModel(x=-150, y=-20, heading=90))
    loop.poke("DEPLOY_STATE", "POLYGON")
    assert loop.run(200, until=lambda: loop.last("LOITER_MODE") == "stable")
    start = loop.t
    loop.run(400)
    low, high, turned = ring_stats(loop.model.track, 0, 0, start)
    inner = 60 * math.cos(math.radians(22.5))  # the octagon's edge midpoints
    assert inner - 8 < low and high < 60 + 8
    assert (turned > 360) if clockwise else (turned < -360)
    assert set(loop.values("LOITER_MODE")) >= {"acquiring_external", "stable"}


def test_polygon_updates_move_and_resize_live_and_center_activate(tmp_path: Path) -> None:
    helm = make_helm(tmp_path, LOITER % ("true", "true"), start_engaged="true")
    loop = CoreLoop(helm, KinematicModel(x=100, y=100, heading=0))
    loop.run(2)  # idle first: center_activate recentres only on an idle-to-running transition
    loop.poke("DEPLOY_STATE", "POLYGON")
    loop.run(2)
    loiter = helm.engine.behaviors[0]
    assert loiter.polygon.center() == pytest.approx((100, 100), abs=0.5)  # recentred on the vehicle
    loop.run(300)
    low, high, _ = ring_stats(loop.model.track, 100, 100, loop.t - 150)
    assert 45 < low and high < 68
    loop.poke("POLYGON_UPDATES", "polygon=radial:: x=-200,y=0,radius=30,pts=6")
    loop.run(1)
    assert loop.values("IVPHELM_UPDATE_RESULT")[-1].endswith("result=success,val=polygon=radial:: x=-200,y=0,radius=30,pts=6")
    assert loiter.polygon.center() == pytest.approx((-200, 0), abs=0.5)
    assert loop.run(400, until=lambda: loop.last("LOITER_MODE") == "stable")
    start = loop.t
    loop.run(200)
    low, high, turned = ring_stats(loop.model.track, -200, 0, start)
    assert 30 * math.cos(math.radians(30)) - 8 < low and high < 30 + 8 and turned > 360
    loop.poke("POLYGON_UPDATES", "polygon=not a polygon")
    loop.run(1)
    assert "result=param_error" in loop.values("IVPHELM_UPDATE_RESULT")[-1]
    assert any("Faulty update" in str(v) for v in loop.values("BHV_WARNING"))


def test_deploy_state_switches_behaviours(tmp_path: Path) -> None:
    text = Path(__file__).resolve().parents[2].joinpath("behaviors", "usv.bhv").read_text()
    helm = make_helm(tmp_path, text, domains=("course:0:359:360", "speed:0:2:41"))
    loop = CoreLoop(helm, KinematicModel(x=0, y=0))
    loop.run(5)
    assert loop.last("IVPHELM_STATE") == "DRIVE"  # the file's own initialize MOOS_MANUAL_OVERRIDE = false
    assert loop.last("IVPHELM_BHV_ACTIVE") == "polygon" and loop.last("IVPHELM_BHV_IDLE") == "waypt_survey"
    loop.poke("DEPLOY_STATE", "WAYPOINTS")
    loop.run(5)
    assert loop.last("IVPHELM_BHV_ACTIVE") == "waypt_survey" and loop.last("IVPHELM_BHV_IDLE") == "polygon"
    assert loop.last("LOITER_MODE") == "idle"
    assert loop.last("DESIRED_SPEED") == pytest.approx(1.5)
    assert loop.last("WPT_INDEX") == 0.0


def test_constant_behaviours_and_duration(tmp_path: Path) -> None:
    text = "initialize GO = true\n" + "".join([
        bhv_block("ConstantHeading", name="hdg", condition="GO = true", heading=271.6),
        bhv_block("ConstantSpeed", name="spd", condition="GO = true", speed=1.3, duration=10, endflag="SPD_DONE = true"),
        bhv_block("ConstantDepth", name="dep", condition="GO = true", depth=12),
        bhv_block("ConstantSpeed", name="once", pwt=0, condition="GO = true", endflag="ONCE = true", duration=None),
    ])
    helm = make_helm(tmp_path, text, domains=("course:0:359:360", "speed:0:4:41", "depth:0:100:101"),
                     start_engaged="true")
    loop = CoreLoop(helm)
    loop.run(5)
    assert loop.last("DESIRED_HEADING") == 272.0 and loop.last("DESIRED_SPEED") == pytest.approx(1.3)
    assert loop.last("DESIRED_DEPTH") == 12.0
    assert loop.values("ONCE") == ["true"]  # duration defaults to 0: completes at once
    assert loop.run(20, until=lambda: loop.values("SPD_DONE"))
    loop.run(2)
    assert loop.last("IVPHELM_ALLSTOP") == "MissingDecVars:speed"


def test_station_keep_holds_its_point(tmp_path: Path) -> None:
    text = """\
Behavior = BHV_StationKeep
{
  name = sk
  station_pt = 40,-30
  inner_radius = 4
  outer_radius = 15
  outer_speed = 1.2
  transit_speed = 2
  duration = no-time-limit
}
"""
    loop = CoreLoop(make_helm(tmp_path, text, start_engaged="true"))
    loop.run(200)
    assert math.hypot(loop.model.x - 40, loop.model.y + 30) < 8
    assert loop.last("PSKEEP_MODE") == "SEEKING_STATION"
