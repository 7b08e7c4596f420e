"""Smaller helm semantics: flag timing, waypoint order/repeat, DISABLED, skew, deferred initialize, alias."""

from __future__ import annotations

from pathlib import Path

from behaviors.apps.ivp_helm import HelmApp
from gateway.moos import MoosClock
from gateway.moos.testing import running_moosdb

from .core_loop import CoreLoop, make_helm
from .kinematic_vehicle import KinematicModel
from .moos_harness import WARP, observer, write_mission

FLAGS = """\
initialize GO = false
initialize_ LATE = 7
Behavior = BHV_ConstantHeading
{
  name = hdg
  condition = GO = true
  heading = 90
  duration = no-time-limit
  runflag = RUN = $[BHVNAME]
  activeflag = ACT = 1
  inactiveflag = INACT = $[CTR]
  idleflag = IDLE = yes
  activeflag = COND_FLAG = on [if] GO = true
  activeflag = NEVER = on [if] GO = maybe
  updates = HDG_UPDATES
}
Behavior = BHV_ConstantSpeed
{
  name = watcher
  condition = ACT = 1
  speed = 1
  duration = no-time-limit
  runflag = SAW_ACT = true
}
"""


def test_flag_timing_and_visibility_on_the_next_iteration(tmp_path: Path) -> None:
    loop = CoreLoop(make_helm(tmp_path, FLAGS, start_engaged="true"))
    loop.run(2)
    assert loop.values("IDLE") == ["yes"] and len(loop.values("INACT")) == 1
    assert loop.values("LATE") == [7.0]  # deferred: posted once the helm saw its own IVPHELM_STATE
    loop.poke("GO", "true")
    loop.run(0.1)  # one iteration
    assert loop.values("RUN") == ["hdg"] and loop.values("ACT") == [1.0]
    assert loop.values("COND_FLAG") == ["on"] and loop.values("NEVER") == []  # [if] conditional flags
    assert loop.values("SAW_ACT") == []  # flags enter the info buffer after every behaviour has run
    loop.run(0.1)
    assert loop.values("SAW_ACT") == ["true"]
    loop.run(2)
    assert loop.values("RUN") == ["hdg"] and loop.values("ACT") == [1.0]  # on transitions only
    loop.poke("HDG_UPDATES", "heading=180 # pwt=50")
    loop.run(1)
    assert loop.last("DESIRED_HEADING") == 180.0
    assert loop.values("IVPHELM_UPDATE_RESULT")[-1].startswith("bhv=hdg,var=HDG_UPDATES,")
    loop.poke("HDG_UPDATES", "heading=180 # pwt=50")
    loop.run(0.5)
    assert "result=duplicate" in loop.values("IVPHELM_UPDATE_RESULT")[-1]
    loop.poke("HDG_UPDATES", "name=other # heading=0")
    loop.run(0.5)
    assert "result=name_mismatch" in loop.values("IVPHELM_UPDATE_RESULT")[-1]
    loop.poke("GO", "false")
    loop.run(1)
    assert loop.values("IDLE") == ["yes", "yes"] and len(loop.values("INACT")) == 2


REPEAT = """\
Behavior = BHV_Waypoint
{
  name = w
  speed = 2
  capture_radius = 4
  slip_radius = 0
  order = reverse
  repeat = 1
  wptflag = HIT = $(X),$(Y):$(PX),$(PY)
  cycleflag = CYCLED = $[CYCLES]
  endflag = END = true
  points = 0,30:30,30
}
"""


def test_reverse_order_and_one_repeat(tmp_path: Path) -> None:
    loop = CoreLoop(make_helm(tmp_path, REPEAT, start_engaged="true"))
    assert loop.run(400, until=lambda: loop.values("END"))
    # pHelmIvP 19.8.1: $(X),$(Y) is the waypoint reached; $(PX)/$(PY) and cycle flags are not expanded; on
    # completion the engine's reset point (the first, 30,30) is posted before the one reached
    assert loop.values("HIT") == ["30,30:$(PX),$(PY)", "0,30:$(PX),$(PY)", "30,30:$(PX),$(PY)", "30,30:$(PX),$(PY)",
                                  "0,30:$(PX),$(PY)"]
    assert loop.values("CYCLED") == ["$[CYCLES]", "$[CYCLES]"]
    assert loop.values("WPT_STAT").count("behavior-name=w,cycled") == 1
    assert loop.last("WPT_STAT") == "behavior-name=w,completed"
    assert loop.helm.engine.behaviors[0].name == "w"  # repeat > 0 made it perpetual: it stays


def test_another_helm_state_disables_this_helm(tmp_path: Path) -> None:
    loop = CoreLoop(make_helm(tmp_path, REPEAT, start_engaged="true"))
    loop.run(2)
    loop._deliver(loop.helm.handle_mail("IVPHELM_STATE", "DRIVE", loop.t, "pHelmIvP_other", loop.t))
    loop.run(2)
    assert "DisabledByStandbyHelm" in loop.values("IVPHELM_ALLSTOP")
    assert loop.values("IVPHELM_STATE")[-1] == "DISABLED"
    assert loop.values("IVPHELM_STATE").count("DISABLED") == 1  # posted on change only
    assert loop.last("DESIRED_SPEED") == 0.0


def test_stale_mail_is_dropped_with_ivphelm_skew(tmp_path: Path) -> None:
    loop = CoreLoop(make_helm(tmp_path, FLAGS, start_engaged="true", ok_skew="30"), KinematicModel())
    loop.run(1)
    loop.helm.registered_at = loop.t - 60
    loop._deliver(loop.helm.handle_mail("GO", "true", loop.t - 100, "uPokeDB", loop.t))
    loop.run(1)
    assert loop.values("RUN") == [] and loop.values("IVPHELM_SKEW")
    # an old value the DB hands over right after registration is not stale (skew = time since registering)
    loop.helm.registered_at = loop.t - 5
    loop._deliver(loop.helm.handle_mail("GO", "true", loop.t - 100, "uPokeDB", loop.t))
    loop.run(1)
    assert loop.values("RUN") == ["hdg"]


def test_alias_names_the_app_and_falls_back_to_the_phelmivp_block(tmp_path: Path) -> None:
    clock = MoosClock(WARP)
    bhv = tmp_path / "h.bhv"
    bhv.write_text("Behavior = BHV_ConstantSpeed\n{\n name = s\n speed = 1\n duration = no-time-limit\n}\n")
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, ["IVPHELM_STATE"]) as obs:
        mission = write_mission(tmp_path, db.port, bhv)
        with HelmApp(mission, alias="pHelmIvP_backup", clock=clock) as app:
            assert app.state == "PARK"
            assert obs.wait(lambda: obs.values("IVPHELM_STATE"))
            assert {src for _, name, _, src in obs.mail if name == "IVPHELM_STATE"} == {"pHelmIvP_backup"}


def test_console_script_reports_an_unreadable_mission(tmp_path: Path) -> None:
    import subprocess

    from .moos_harness import IVP_HELM

    result = subprocess.run([str(IVP_HELM), str(tmp_path / "missing.moos")], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 2
    assert "missing.moos" in result.stderr


LOITER_UPDATES = """\
initialize GO = false
Behavior = BHV_Loiter
{
  name = l
  condition = GO = true
  speed = 2
  clockwise = best
  updates = UP
  polygon = radial:: x=0,y=0,radius=50,pts=8
}
"""


def test_loiter_best_direction_center_assign_and_radius_updates(tmp_path: Path) -> None:
    # west of the polygon heading south: turning the least means going round counter-clockwise
    loop = CoreLoop(make_helm(tmp_path, LOITER_UPDATES, start_engaged="true"),
                    KinematicModel(x=-120, y=0, heading=180))
    loop.run(2)  # the helm makes no decision in its first second
    loop.poke("GO", "true")  # best is chosen on each idle-to-running transition
    loop.run(1)
    loiter = loop.helm.engine.behaviors[0]
    assert loiter.clockwise is False and not loiter.polygon.is_clockwise()
    loop.poke("UP", "center_assign=30,-40")
    loop.run(1)
    assert loiter.polygon.center() == (30, -40)
    loop.poke("UP", "mod_poly_rad=-20")
    loop.run(1)
    assert abs(loiter.polygon.max_radius() - 30) < 0.01 and loiter.polygon.center() == (30, -40)
    loop.poke("UP", "mod_poly_rad=-100")
    loop.run(1)
    assert abs(loiter.polygon.max_radius() - 5) < 0.01  # pHelmIvP's minimum radius


MODES = """\
initialize DEPLOY = false
initialize RETURN = false

set MODE = ACTIVE {
  DEPLOY = true
} INACTIVE

set MODE = RETURNING {
  MODE = ACTIVE
  RETURN = true
} LOITERING

Behavior = BHV_ConstantSpeed
{
  name = slow
  condition = MODE == LOITERING
  speed = 1
  duration = no-time-limit
}
Behavior = BHV_ConstantSpeed
{
  name = fast
  condition = MODE == RETURNING
  speed = 2
  duration = no-time-limit
}
"""


def test_hierarchical_modes(tmp_path: Path) -> None:
    loop = CoreLoop(make_helm(tmp_path, MODES, domains=("speed:0:4:41",), start_engaged="true"))
    assert {"DEPLOY", "RETURN", "MODE"} <= loop.helm.registrations()
    loop.run(2)
    assert loop.values("MODE") == ["INACTIVE"]  # on change only
    assert "modes=MODE@INACTIVE" in loop.last("IVPHELM_SUMMARY")
    loop.poke("DEPLOY", "true")
    loop.run(1)
    assert loop.last("MODE") == "ACTIVE:LOITERING" and loop.last("DESIRED_SPEED") == 1.0
    loop.poke("RETURN", "true")
    loop.run(1)
    assert loop.last("MODE") == "ACTIVE:RETURNING" and loop.last("DESIRED_SPEED") == 2.0
    assert "modes=MODE@ACTIVE:RETURNING" in loop.last("IVPHELM_SUMMARY")
    assert loop.values("MODE") == ["INACTIVE", "ACTIVE:LOITERING", "ACTIVE:RETURNING"]


def test_bhv_status_other_override_var_and_park_on_allstop(tmp_path: Path) -> None:
    text = "initialize GO = false\nBehavior = BHV_ConstantSpeed\n{\n name = s\n condition = GO = true\n speed = 1\n" \
           " duration = no-time-limit\n}\n"
    loop = CoreLoop(make_helm(tmp_path, text, other_override_var="MY_OVERRIDE", park_on_allstop="true"))
    loop.run(2)
    assert loop.last("IVPHELM_STATE") == "PARK"
    loop.poke("MY_OVERRIDE", "false")
    loop.run(0.1)
    assert loop.last("IVPHELM_STATE") == "DRIVE"
    assert loop.values("BHV_STATUS") == ["name=s,pc=GO = true,pwt=100,state=idle,updates=0/0"]
    assert loop.values("IVPHELM_ALLSTOP")[-1] == "NothingToDo"  # the grace iteration
    loop.run(1)
    # nothing to do persisted past the grace: park_on_allstop dropped control
    assert loop.values("IVPHELM_STATE")[-1] == "PARK" and loop.values("IVPHELM_STATE").count("DRIVE") == 2
    assert loop.values("BHV_STATUS") == ["name=s,pc=GO = true,pwt=100,state=idle,updates=0/0"]  # on change only
