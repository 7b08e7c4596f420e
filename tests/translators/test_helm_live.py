"""A helm (the real pHelmIvP when on PATH, and our ivp-helm) driven through the gateway, as in the course.

node_status in -> NAV_* -> the helm drives -> desired_course and helm_state out; then ``usv-command polygon``
switches the helm from its waypoint behaviour to the loiter behaviour with the commanded polygon.
"""

from __future__ import annotations

import math
import shutil
import sys
import time
from pathlib import Path

import pytest
from translator_procs import ORIGIN, run_cli, start_child

from behaviors.testing import write_helm_mission
from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import USV, DesiredCourse, NodeStatus
from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, HelmStateReport
from gateway.goby.portal.testing import PortalClient
from gateway.moos.testing import connected_comms

TIMEOUT_S = 60.0
WAYPOINT_SPEED = 1.0
LOITER_SPEED = 1.8

BHV = """
initialize DEPLOY_STATE = WAYPOINTS
initialize MOOS_MANUAL_OVERRIDE = false

Behavior = BHV_Waypoint
{
  name      = waypt
  pwt       = 100
  condition = DEPLOY_STATE = WAYPOINTS
  speed     = %(waypoint_speed)s
  capture_radius = 5
  points    = 2000,0
}

Behavior = BHV_Loiter
{
  name      = polygon
  pwt       = 100
  condition = DEPLOY_STATE = POLYGON
  updates   = POLYGON_UPDATES
  center_activate = true
  speed     = %(loiter_speed)s
  polygon   = radial:: x=0,y=0,radius=200,pts=6
}
"""

def helm_command(kind: str, mission: Path) -> list[str]:
    if kind == "pHelmIvP":
        if shutil.which("pHelmIvP") is None:
            pytest.skip("the real pHelmIvP is not on PATH")
        return ["pHelmIvP", str(mission)]
    run_main = "import sys; from behaviors.apps.ivp_helm import main; sys.exit(main())"  # the ivp-helm console script
    return [sys.executable, "-c", run_main, str(mission), "-v"]


def nav_at_origin() -> NodeStatus:
    status = NodeStatus(time=time.time(), name="usv", type=USV)
    status.global_fix.lat, status.global_fix.lon = ORIGIN
    status.pose.heading = 90.0
    status.speed.over_ground = 0.0
    return status


@pytest.mark.parametrize("helm_kind", ["ivp-helm", "pHelmIvP"])
def test_helm_drives_through_the_gateway_and_a_shore_command_switches_its_behaviour(stack, tmp_path, helm_kind):
    bhv = tmp_path / "usv.bhv"
    bhv.write_text(BHV % {"waypoint_speed": WAYPOINT_SPEED, "loiter_speed": LOITER_SPEED})
    mission = write_helm_mission(tmp_path, stack.moos_port, bhv, community="usv", origin=ORIGIN, name="usv.moos")
    helm = start_child(helm_kind, helm_command(helm_kind, mission), tmp_path)
    try:
        with PortalClient(stack.broker.interprocess_config(), name="frontseat_stand_in") as client, \
                connected_comms(stack.moos_port, "watch_polygon_view", register=["VIEW_POLYGON"]) as watcher:
            courses: list[DesiredCourse] = client.collect(groups.desired_course, DesiredCourse)
            states: list[HelmStateReport] = client.collect(groups.helm_state, HelmStateReport)
            assert client.wait_subscribed()

            def drive_until(predicate, what: str) -> None:  # noqa: ANN001
                deadline = time.monotonic() + TIMEOUT_S
                while not predicate():
                    assert helm.running, f"{helm_kind} exited\n{helm.output()}"
                    assert time.monotonic() < deadline, f"timed out: {what}\n{helm.output()[-3000:]}\n{stack.logs()}"
                    client.publish(groups.node_status, nav_at_origin())
                    client.poll(0.25)

            drive_until(lambda: any(s.state == HELM_DRIVE for s in states), "helm_state DRIVE")
            drive_until(lambda: any(math.isclose(c.speed, WAYPOINT_SPEED) for c in courses),
                        "desired_course from the waypoint behaviour")
            eastward = next(c for c in courses if math.isclose(c.speed, WAYPOINT_SPEED))
            assert abs(eastward.heading - 90.0) <= 2.0  # the waypoint is due east of the origin

            result = run_cli(["polygon", "--sides", "6", "--radius", "300"], stack.env(), stack.workdir)
            assert result.returncode == 0, result.stdout + result.stderr
            drive_until(lambda: any(math.isclose(c.speed, LOITER_SPEED) for c in courses),
                        "desired_course from the loiter behaviour after the POLYGON command")
            views: list[str] = []
            drive_until(lambda: views.extend(m.string() for m in watcher.fetch()) or any(
                _max_vertex_range(v) > 250 for v in views), "VIEW_POLYGON with the commanded 300 m radius")
    finally:
        helm.stop(10)


def _max_vertex_range(view: str) -> float:
    """Largest vertex distance from (0, 0) in a VIEW_POLYGON spec (``pts={x,y:x,y:...},...``); 0 if none."""
    if "pts={" not in view:
        return 0.0
    body = view.split("pts={", 1)[1].split("}", 1)[0]
    best = 0.0
    for vertex in body.split(":"):
        try:
            x, y = (float(v) for v in vertex.split(",")[:2])
        except ValueError:
            continue
        best = max(best, math.hypot(x, y))
    return best
