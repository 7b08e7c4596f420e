"""Closed loop on loopback: our MOOSDB, ``ivp-helm`` as a process, and the kinematic vehicle double.

MOOSTimeWarp 20 makes minutes of mission run in seconds; every wait is a condition with a generous timeout.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from gateway.moos import MoosClock
from gateway.moos.testing import running_moosdb

from .moos_harness import (
    REPO,
    WARP,
    helm_process,
    observer,
    polygon_center,
    ring_stats,
    vehicle,
    write_mission,
)

WATCH = ["IVPHELM_STATE", "IVPHELM_ALLSTOP", "DESIRED_HEADING", "DESIRED_SPEED", "WPT_INDEX", "WPT_STAT",
         "ARRIVED", "DONE", "LOITER_MODE", "VIEW_POLYGON", "IVPHELM_BHV_ACTIVE", "IVPHELM_CONFIG_WARNING",
         "IVPHELM_UPDATE_RESULT", "NEXT"]

SURVEY = """\
initialize DEPLOY = false
Behavior = BHV_Waypoint
{
  name      = survey
  condition = DEPLOY = true
  wptflag   = ARRIVED = $(X),$(Y):$(PX),$(PY)
  endflag   = DONE = true
  speed     = 2.0
  capture_radius = 5
  slip_radius    = 0
  points    = 40,0:40,50:-20,50:-20,10
}
"""
SURVEY_POINTS = [(40, 0), (40, 50), (-20, 50), (-20, 10)]


def test_park_then_waypoints_in_order_within_capture_radius(tmp_path: Path) -> None:
    clock = MoosClock(WARP)
    bhv = tmp_path / "survey.bhv"
    bhv.write_text(SURVEY)
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, WATCH) as obs:
        mission = write_mission(tmp_path, db.port, bhv)
        with helm_process(mission, tmp_path), vehicle(db.port, clock, x=0, y=0, heading=0) as sim:
            assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "PARK"), (tmp_path / "helm.log").read_text()
            assert obs.wait(lambda: obs.values("IVPHELM_ALLSTOP") == ["ManualOverride"])
            assert obs.wait(lambda: obs.values("DESIRED_SPEED") == [0.0])
            obs.post("DEPLOY", "true")
            obs.post("MOOS_MANUAL_OVERRIDE", "false")
            assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "DRIVE")
            assert obs.wait(lambda: obs.values("DONE"), timeout=90), obs.values("WPT_INDEX")
        track = sim.track
    # MOOS times stamped by the helm itself, so observer latency does not count
    start = next(t for t, n, v, _ in obs.mail if n == "IVPHELM_STATE" and v == "DRIVE")
    duration = next(t for t, n, _, _ in obs.mail if n == "DONE") - start
    assert obs.values("WPT_INDEX") == [0.0, 1.0, 2.0, 3.0]
    # pHelmIvP 19.8.1's postWptFlags: $(X),$(Y) the waypoint reached (the last one again on completion);
    # $(PX)/$(PY) are later releases' macros and post as written (test_phelmivp_compare checks it against 19.8.1)
    # as pHelmIvP 19.8.1: on completion the engine's reset point (the first) is posted before the last one
    assert obs.values("ARRIVED") == [f"{p}:$(PX),$(PY)" for p in ("40,0", "40,50", "-20,50", "40,0", "-20,10")]
    assert obs.last("WPT_STAT") == "behavior-name=survey,completed"
    # each point was reached within the capture radius, in order
    times = []
    for px, py in SURVEY_POINTS:
        t, d = min(((t, math.hypot(x - px, y - py)) for t, x, y, _, _ in track if t > (times[-1] if times else 0)),
                   key=lambda item: item[1])
        assert d < 5.0, (px, py, d)
        times.append(t)
    assert times == sorted(times)
    path = 40 + 50 + 60 + 40
    assert 0.8 * path / 2.0 < duration < 1.5 * path / 2.0, duration  # about the straight-line time at 2 m/s


def usv_mission(tmp_path: Path, port: int) -> Path:
    return write_mission(tmp_path, port, REPO / "behaviors" / "usv.bhv")


def test_usv_loiter_goes_round_the_hexagon_clockwise_and_resizes_live(tmp_path: Path) -> None:
    clock = MoosClock(WARP)
    with running_moosdb("trail_usv", warp=WARP) as db, observer(db.port, clock, WATCH) as obs:
        with helm_process(usv_mission(tmp_path, db.port), tmp_path), \
                vehicle(db.port, clock, x=0, y=-120, heading=0) as sim:
            # the file's own initialize MOOS_MANUAL_OVERRIDE = false engages the helm
            assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "DRIVE"), (tmp_path / "helm.log").read_text()
            assert obs.wait(lambda: obs.last("IVPHELM_BHV_ACTIVE") == "polygon")
            assert obs.wait(lambda: obs.last("DESIRED_SPEED") == pytest.approx(1.5))
            # the course's CommandTranslation order: POLYGON_UPDATES first, then DEPLOY_STATE
            obs.post("POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=60,pts=6")
            obs.post("DEPLOY_STATE", "POLYGON")
            assert obs.wait(lambda: any("result=success" in str(v) for v in obs.values("IVPHELM_UPDATE_RESULT")))
            assert obs.wait(lambda: obs.last("LOITER_MODE") == "stable", timeout=60)
            start = clock.time()
            obs.wait_moos(300)
            low, high, swept = ring_stats(sim.track, 0, 0, start)
            assert 60 * math.cos(math.radians(30)) - 8 < low and high < 60 + 12, (low, high)  # corners overshoot
            assert swept > 360  # clockwise, at least one lap
            assert polygon_center(str(obs.last("VIEW_POLYGON"))) == pytest.approx((0, 0), abs=0.5)


def test_usv_deploy_state_switch_and_center_activate(tmp_path: Path) -> None:
    clock = MoosClock(WARP)
    with running_moosdb("trail_usv", warp=WARP) as db, observer(db.port, clock, WATCH) as obs:
        with helm_process(usv_mission(tmp_path, db.port), tmp_path), \
                vehicle(db.port, clock, x=0, y=0, heading=0) as sim:
            assert obs.wait(lambda: obs.last("IVPHELM_BHV_ACTIVE") == "polygon"), (tmp_path / "helm.log").read_text()
            obs.post("DEPLOY_STATE", "WAYPOINTS")
            assert obs.wait(lambda: obs.last("IVPHELM_BHV_ACTIVE") == "waypt_survey")
            assert obs.wait(lambda: obs.last("LOITER_MODE") == "idle")
            # the track's first point is (134,33): the vehicle turns toward it
            assert obs.wait(lambda: sim.model.x > 40, timeout=60)
            assert obs.last("WPT_INDEX") == 0.0
            obs.wait_moos(20)
            posted_at = clock.time()
            obs.post("DEPLOY_STATE", "POLYGON")
            assert obs.wait(lambda: obs.last("IVPHELM_BHV_ACTIVE") == "polygon")
            assert obs.wait(lambda: polygon_center(str(obs.last("VIEW_POLYGON")))[0] > 30)
            cx, cy = polygon_center(str(obs.last("VIEW_POLYGON")))
            active_at = max(t for t, n, v, _ in obs.mail if n == "IVPHELM_BHV_ACTIVE" and v == "polygon")
            # recentred on a position the vehicle had between the command and the loiter's activation
            window = [(x, y) for t, x, y, _, _ in sim.track if posted_at - 2 <= t <= active_at + 1]
            assert min(math.hypot(cx - x, cy - y) for x, y in window) < 2.0, ((cx, cy), window[:1], window[-1:])


def test_malconfig_over_moos_names_the_file_line_and_token(tmp_path: Path) -> None:
    clock = MoosClock(WARP)
    bhv = tmp_path / "bad.bhv"
    bhv.write_text("Behavior = BHV_Loiter\n{\n  name = l\n  polygon = radial:: x=0,y=0,radius=20,pts=6\n"
                   "  clockwise = sideways\n}\n")
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, WATCH) as obs:
        with helm_process(write_mission(tmp_path, db.port, bhv), tmp_path), vehicle(db.port, clock):
            assert obs.wait(lambda: obs.values("IVPHELM_STATE")[-3:] == ["MALCONFIG"] * 3)
            warning = str(obs.last("IVPHELM_CONFIG_WARNING"))
            assert warning.startswith(f"{bhv}:5: ") and "clockwise = sideways" in warning
            obs.wait_moos(5)
            assert obs.values("DESIRED_HEADING") == [] and obs.values("DESIRED_SPEED") == []


def test_values_posted_long_before_the_helm_started_are_not_dropped_as_stale(tmp_path: Path) -> None:
    """pHelmIvP's skew is min(message age, time since registering): a value the DB hands over is fresh."""
    clock = MoosClock(WARP)
    bhv = tmp_path / "survey.bhv"
    bhv.write_text(SURVEY)
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, WATCH + ["IVPHELM_SKEW"]) as obs:
        obs.post("DEPLOY", "true")
        obs.post("MOOS_MANUAL_OVERRIDE", "false")
        obs.wait_moos(90)  # older than ok_skew (60 s) by the time the helm registers
        mission = write_mission(tmp_path, db.port, bhv)
        (tmp_path / "survey.bhv").write_text(SURVEY.replace("initialize DEPLOY = false\n", ""))
        with helm_process(mission, tmp_path), vehicle(db.port, clock, x=0, y=0, heading=0):
            assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "DRIVE"), (tmp_path / "helm.log").read_text()
            assert obs.wait(lambda: obs.last("DESIRED_SPEED") == pytest.approx(2.0))
        assert obs.values("IVPHELM_SKEW") == []
