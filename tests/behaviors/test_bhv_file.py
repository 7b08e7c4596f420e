"""The .bhv grammar: what real missions use parses; every mistake names the file, line and token."""

from __future__ import annotations

from pathlib import Path

import pytest

from behaviors.helm.bhv_file import build_behaviors, parse_bhv_text, read_bhv_file
from behaviors.helm.bhv_loiter import LoiterBehavior
from behaviors.helm.bhv_waypoint import WaypointBehavior
from behaviors.helm.errors import BehaviorFileError
from behaviors.helm.info_buffer import InfoBuffer
from behaviors.helm.ivp import IvPDomain

from .core_loop import make_helm

USV_BHV = Path(__file__).resolve().parents[2] / "behaviors" / "usv.bhv"

ALPHA = """\
initialize DEPLOY = false
initialize   RETURN = false, LOITER_POS = "x=0,y=-75"
initialize_  STATION = false

Behavior = BHV_Waypoint
{
  name      = waypt_survey
  pwt       = 100
  condition = RETURN = false
  condition = DEPLOY = true
  endflag   = RETURN = true
  endflag   = SUMMARY=speed=$[SPEED],time=$[DUR_RUN_TIME]
  configflag = CRUISE_SPD = $[SPEED]
  activeflag = INFO=$[OWNSHIP]
  wptflag   = NEXT=$(NX),$(NY)
  perpetual = true
  updates   = WPT_UPDATE
  speed_alt = 1.2
  use_alt_speed = true
  lead = 8
  lead_damper = 1
  lead_to_start = true
  speed = 3   // meters per second
  capture_line = true
  capture_radius = 5.0
  slip_radius = 15.0
  efficiency_measure = all
  polygon = 60,-40:60,-160:150,-160:180,-100:150,-40
  order = normal
  repeat = 0
}

Behavior = BHV_ConstantSpeed {
  name = const_speed
  pwt = 200
  condition = SPD=true
  speed = 0.5
  duration = 10
  duration_reset = CONST_SPD_RESET=true
}
Behavior = BHV_Loiter
{
  name = loiter
  polygon = format=radial, x=75, y=-75, radius=30, pts=8, snap=1
  clockwise = false
  radius = 6
  nm_radius = 25
  priority = 100
  condition = (MODE == LOITERING) or \\
              (DEPLOY = loiter)
}
"""


def domain(*specs: str) -> IvPDomain:
    d = IvPDomain()
    for spec in specs or ("course:0:359:360", "speed:0:4:41"):
        d.add(spec)
    return d


def test_alpha_style_file_parses_with_its_details() -> None:
    bfile = parse_bhv_text(ALPHA, "alpha.bhv")
    inits = [(i.var, i.value, i.deferred) for i in bfile.initializes]
    assert inits == [("DEPLOY", "false", False), ("RETURN", "false", False), ("LOITER_POS", "x=0,y=-75", False),
                     ("STATION", "false", True)]
    bhvs = build_behaviors(bfile, domain(), InfoBuffer(), "alpha")
    assert [b.name for b in bhvs] == ["waypt_survey", "const_speed", "loiter"]
    wpt = bhvs[0]
    assert isinstance(wpt, WaypointBehavior)
    assert wpt.engine.points == [(60, -40), (60, -160), (150, -160), (180, -100), (150, -40)]
    assert wpt.cruise_speed() == 1.2 and wpt.engine.capture_radius == 5.0 and wpt.engine.capture_line
    assert [c.text for c in wpt.conditions] == ["RETURN = false", "DEPLOY = true"]
    assert [f.var for f in wpt.flags["endflag"]] == ["RETURN", "SUMMARY"]
    assert bhvs[1].pwt == 200 and bhvs[1].duration == 10
    loiter = bhvs[2]
    assert isinstance(loiter, LoiterBehavior)
    assert loiter.clockwise is False and not loiter.polygon.is_clockwise()
    assert len(loiter.polygon.vertices) == 8
    assert loiter.conditions[0].variables() == {"MODE", "DEPLOY"}


def test_usv_bhv_matches_the_course_mission() -> None:
    bfile = read_bhv_file(USV_BHV)
    assert [(i.var, i.value) for i in bfile.initializes] == [("DEPLOY_STATE", "POLYGON"),
                                                             ("MOOS_MANUAL_OVERRIDE", "false")]
    wpt, loiter = build_behaviors(bfile, domain("course:0:359:360", "speed:0:2:41"), InfoBuffer())
    assert wpt.TYPE == "BHV_Waypoint" and wpt.conditions[0].text == "DEPLOY_STATE = WAYPOINTS"
    assert wpt.speed == 1.5 and wpt.engine.repeat_forever and len(wpt.engine.points) == 100
    assert loiter.TYPE == "BHV_Loiter" and loiter.conditions[0].text == "DEPLOY_STATE = POLYGON"
    assert loiter.updates_var == "POLYGON_UPDATES" and loiter.center_activate and loiter.speed == 1.5
    assert loiter.polygon.center() == (0.0, 0.0) and loiter.polygon.max_radius() == pytest.approx(200, abs=0.1)
    assert len(loiter.polygon.vertices) == 6 and loiter.polygon.is_clockwise()


def test_brace_placement_and_line_continuation() -> None:
    text = "Behavior = BHV_ConstantHeading {\n name = h\n heading = \\\n   90\n duration = no-time-limit\n}\n"
    (bhv,) = build_behaviors(parse_bhv_text(text), domain(), InfoBuffer())
    assert bhv.desired == 90 and bhv.duration == -1


BAD = [
    ("Behavior = BHV_AvoidCollision\n{\n name = t\n}\n", 1, "BHV_AvoidCollision", "unknown behaviour type"),
    ("Behavior = BHV_Trail\n{\n name = t\n}\n", 1, "BHV_Trail", "contact is not set"),
    ("Behavior = BHV_Waypoint\n{\n name = w\n speeed = 2\n}\n", 4, "speeed", "unknown parameter"),
    ("Behavior = BHV_Waypoint\n{\n name = w\n speed = fast\n}\n", 4, "speed = fast", "must be a number"),
    ("Behavior = BHV_Waypoint\n{\n name = w\n points = 1,2:3\n}\n", 4, "points = 1,2:3", "bad vertex"),
    ("Behavior = BHV_Waypoint\n{\n condition = A = 1 and B = 2\n}\n", 3, "A = 1", "parentheses"),
    ("Behavior = BHV_Waypoint\n{\n name = w\n just some words\n}\n", 4, "just some words", "parameter = value"),
    ("initialize DEPLOY\n", 1, "DEPLOY", "initialize VAR = value"),
    ("Behaviour = BHV_Waypoint\n", 1, "Behaviour", "unknown line"),
    ("#include plugs.bhv\n", 1, "#include", "nsplug"),
    ("Behavior = BHV_Waypoint\n name = w\n", 2, "name = w", "expected '{'"),
    ("Behavior = BHV_Waypoint\n{\n name = w\n", 1, "Behavior", "not closed"),
    ("Behavior = BHV_Loiter\n{\n name = l\n polygon = 0,0:10,0:5,5:10,10:0,10\n}\n", 4, "polygon", "not convex"),
    ("Behavior = BHV_Loiter\n{\n name = l\n polygon = radial:: x=0,y=0,radius=20,pts=6,colour=red\n}\n", 4,
     "polygon", "unknown key 'colour'"),
    ("Behavior = BHV_Loiter\n{\n name = l\n}\n", 1, "BHV_Loiter", "needs a polygon"),
    ("Behavior = BHV_ConstantDepth\n{\n depth = 3\n}\n", 1, "BHV_ConstantDepth", "'depth' decision variable"),
    ("Behavior = BHV_ConstantSpeed\n{\n name = a\n}\nBehavior = BHV_ConstantSpeed\n{\n name = ab\n}\n", 5, "ab",
     "prefix"),
    ("set MODE = ACTIVE {\n DEPLOY == true\n}\n", 2, "DEPLOY == true", "'==' is not allowed"),
    ("set MODE = ACTIVE {\n DEPLOY = true\n} TWO WORDS\n", 3, "TWO WORDS", "one word"),
    ("set MODE = ACTIVE {\n DEPLOY = true\n", 1, "set MODE", "not closed"),
    ("set MODE {\n DEPLOY = true\n}\n", 1, "set MODE", "set VAR = value"),
]


@pytest.mark.parametrize(("text", "line", "token", "reason"), BAD)
def test_errors_name_file_line_and_token(text: str, line: int, token: str, reason: str) -> None:
    with pytest.raises(BehaviorFileError) as info:
        build_behaviors(parse_bhv_text(text, "mission.bhv"), domain(), InfoBuffer())
    err = info.value
    assert (err.path, err.line) == ("mission.bhv", line)
    assert token in err.token
    assert reason in str(err)
    assert str(err).startswith(f"mission.bhv:{line}: ")


def test_a_bad_file_puts_the_helm_in_malconfig_with_the_message(tmp_path: Path) -> None:
    helm = make_helm(tmp_path, "Behavior = BHV_Waypoint\n{\n name = w\n speeed = 2\n}\n")
    assert helm.state == "MALCONFIG"
    assert helm.problems == [f"{tmp_path / 'test.bhv'}:4: unknown parameter 'speeed' for BHV_Waypoint (at 'speeed')"]
    posts = helm.startup(0.0) + helm.iterate(1.0) + helm.iterate(2.0)
    assert [p.value for p in posts if p.var == "IVPHELM_STATE"] == ["MALCONFIG", "MALCONFIG"]
    assert any(p.var == "IVPHELM_CONFIG_WARNING" and "speeed" in p.value for p in posts)
    assert not any(p.var.startswith("DESIRED_") for p in posts)


def test_missing_file_and_bad_helm_parameters_are_malconfig(tmp_path: Path) -> None:
    helm = make_helm(tmp_path, "", allow_disengaged="true")
    assert helm.state == "MALCONFIG"
    assert any("unknown pHelmIvP parameter 'allow_disengaged'" in p for p in helm.problems)
    from behaviors.helm.config import HelmConfig
    from behaviors.helm.helm import Helm
    cfg = HelmConfig.from_pairs([("behaviors", str(tmp_path / "nope.bhv")), ("domain", "course:0:359:360")], "m")
    helm = Helm(cfg)
    assert helm.state == "MALCONFIG" and "cannot read behaviour file" in helm.problems[0]
    cfg = HelmConfig.from_pairs([("behaviors", "x.bhv"), ("domain", "speed:4:0:41")], "m.moos")
    assert cfg.problems and "need high >= low" in cfg.problems[0] and "speed:4:0:41" in cfg.problems[0]
