"""The AUV file and the node reports against the real MOOS-IvP 19.8.1 programs (interop).

Runs only when ``MOOSDB``, ``pHelmIvP`` and ``pNodeReporter`` are on PATH *and* the test runs in a private network
namespace (the real MOOSDB listens on every address); see docs/helm.md. Both helms run ``behaviors/auv.bhv.in``
(trail angle 90, depth 10) on the real MOOSDB with the same kinematic vehicle double, fed the same contact: a USV
on a straight line east at 1.5 m/s, reported in the course's format every 20 s.
"""

from __future__ import annotations

import math
import sys
import threading
from pathlib import Path

import pytest

from gateway.moos import MoosClock
from gateway.moos.testing import COURSE_IVP_RELEASE, ivp_release, moosdb_process, real_moos_skip_reason
from launch.config import render
from translators.node_report_codec import NodeReport, format_course_report, parse_node_report
from util.process import ChildProcess, free_port

from .moos_harness import REPO, helm_process, observer, vehicle
from .test_trail_closed_loop import STATION, auv_mission, trail_errors

pytestmark = [
    pytest.mark.interop,
    pytest.mark.skipif(real_moos_skip_reason("MOOSDB", "pHelmIvP", "pNodeReporter") is not None,
                       reason=str(real_moos_skip_reason("MOOSDB", "pHelmIvP", "pNodeReporter"))),
]

WARP = 20.0
HELMS = {"pHelmIvP": lambda mission: ["pHelmIvP", str(mission)], "ivp-helm": None}
USV_X0, USV_Y, USV_SPEED = -520.0, -100.0, 1.5


class ContactFeeder:
    """Posts the course's NODE_REPORT for a USV moving east at 1.5 m/s every 20 s of MOOS time (its own thread)."""

    def __init__(self, obs, clock: MoosClock, start: float) -> None:
        self.obs, self.clock, self.start = obs, clock, start
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="contact-feeder", daemon=True)

    def position(self, t: float) -> tuple[float, float, float]:
        return USV_X0 + USV_SPEED * (t - self.start), USV_Y, 90.0

    def track(self, start: float, end: float) -> list[tuple[float, float, float, float, float]]:
        return [(t, *self.position(t), USV_SPEED) for t in (start + k * 0.5 for k in range(int((end - start) * 2) + 1))]

    def _run(self) -> None:
        while not self._stop.wait(20.0 / WARP):  # the first report one slot after the start, as over acomms
            now = self.clock.time()
            x, y, heading = self.position(now)
            self.obs.post("NODE_REPORT", format_course_report(NodeReport(
                name="USV", type="USV", time=now, x=round(x, 1), y=y, depth=-0.0, heading=heading, speed=USV_SPEED)))

    def __enter__(self) -> ContactFeeder:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(10)


def run_trail(tmp_path: Path, helm: str) -> dict[str, object]:
    work = tmp_path / helm
    work.mkdir()
    bhv = work / "auv0.bhv"
    bhv.write_text(render(REPO / "behaviors" / "auv.bhv.in", {"trail_angle": 90, "deploy_depth": 10}))
    port = free_port()
    clock = MoosClock(WARP)
    mission = auv_mission(work, port, "AUV0", bhv, auv=True, warp=WARP)
    with moosdb_process(work, port=port, program="MOOSDB", community="AUV0", warp=WARP), \
            observer(port, clock, ["IVPHELM_STATE", "IVPHELM_ALLSTOP", "REGION", "BHV_ERROR"]) as obs, \
            helm_process(mission, work, HELMS[helm](mission) if HELMS[helm] else None), \
            vehicle(port, clock, x=USV_X0, y=USV_Y - 10, heading=90) as sim:
        assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "DRIVE", timeout=30), helm
        start = clock.time()
        with ContactFeeder(obs, clock, start) as feeder:
            obs.wait_moos(150 + 300 - (clock.time() - start), timeout=120)
            end = clock.time()
            depth = sim.model.depth
            obs.post("DEPLOY_DEPTH_UPDATES", "depth=0")
            obs.post("AUV_DEPLOY_STATE", "RECOVER")
            obs.wait_moos(120, timeout=60)
        errors = trail_errors(feeder.track(start, clock.time()), sim.track, 90.0, end - 300, end)
        recovered = (sim.model.depth, math.hypot(sim.model.x - STATION[0], sim.model.y - STATION[1]))
        obs.poll()
    return {"errors": errors, "depth": depth, "recovered": recovered, "allstops": obs.values("IVPHELM_ALLSTOP"),
            "regions": obs.values("REGION"), "bhv_error": obs.values("BHV_ERROR")[:1]}


def test_auv_file_trails_and_recovers_alike_under_both_helms(tmp_path: Path) -> None:
    results = {helm: run_trail(tmp_path, helm) for helm in HELMS}
    release = ivp_release()
    for helm, result in results.items():
        errors = result["errors"]
        # BHV_Trail's geometry changed after the course's release (24.8 holds a steady ~18 deg bearing offset and
        # trails outside the point): the bearing bound applies to ivp-helm and to pHelmIvP of the course's release
        bearing_bound = 15 if helm == "ivp-helm" or release == COURSE_IVP_RELEASE else 180
        good = sum(abs(dr) <= 10 and abs(db) <= bearing_bound for dr, db in errors)
        mean_range = sum(dr for dr, _ in errors) / len(errors)
        mean_bearing = sum(db for _, db in errors) / len(errors)
        print(f"\n{helm}: {good}/{len(errors)} fixes in tolerance, mean range error {mean_range:.1f} m, mean bearing "
              f"error {mean_bearing:.1f} deg, depth {result['depth']:.2f}, after RECOVER {result['recovered']}, "
              f"allstops {result['allstops']}, first BHV_ERROR {result['bhv_error']} (release {release}, bearing "
              f"bound {bearing_bound} deg)")
        result["mean_range"] = mean_range
        assert good >= 0.9 * len(errors), helm
        assert abs(result["depth"] - 10) <= 1.0 and abs(result["recovered"][0]) <= 0.1
        assert result["recovered"][1] <= 10.0, helm
        allstops = result["allstops"]  # halted until the first contact report (ours may first show a start-up PARK)
        assert "BehaviorError" in allstops and allstops[allstops.index("BehaviorError") + 1:] == ["clear"], helm
    assert results["pHelmIvP"]["bhv_error"] == results["ivp-helm"]["bhv_error"] == [
        "trail_usv: USV x/y/heading/speed info not found"]
    if release == COURSE_IVP_RELEASE:  # the same geometry: the same side of the trail point within 3 m
        assert abs(results["pHelmIvP"]["mean_range"] - results["ivp-helm"]["mean_range"]) <= 3.0


REPORTER_MOOS = """\
ServerHost = 127.0.0.1
ServerPort = {port}
Community  = auv0
MOOSTimeWarp = 1
LatOrigin  = 43.8253
LongOrigin = -70.3304

ProcessConfig = pNodeReporter
{{
  AppTick = 4
  platform_type = auv
  platform_color = yellow
  platform_length = 2
}}

ProcessConfig = pNodeReporterPy
{{
  AppTick = 4
  platform_type = auv
  platform_color = yellow
  platform_length = 2
  node_report_output = NODE_REPORT_PY
}}
"""


def test_node_reporter_writes_what_pnodereporter_writes(tmp_path: Path) -> None:
    port = free_port()
    mission = tmp_path / "auv0.moos"
    mission.write_text(REPORTER_MOOS.format(port=port))
    clock = MoosClock(1.0)
    ours_cmd = [str(Path(sys.executable).parent / "node-reporter"), str(mission), "--alias", "pNodeReporterPy"]
    with moosdb_process(tmp_path, port=port, program="MOOSDB", community="auv0"), \
            observer(port, clock, ["NODE_REPORT_LOCAL", "NODE_REPORT_PY"]) as obs, \
            ChildProcess(["pNodeReporter", str(mission)], tmp_path / "pNodeReporter.log", cwd=tmp_path), \
            ChildProcess(ours_cmd, tmp_path / "node-reporter.log", cwd=tmp_path):
        def both() -> bool:
            for var, value in (("NAV_X", -12.345), ("NAV_Y", 6.7), ("NAV_SPEED", 1.25), ("NAV_HEADING", 370.5),
                               ("NAV_DEPTH", 12.0), ("NAV_LAT", 43.82494863), ("NAV_LONG", -70.32964602),
                               ("IVPHELM_STATE", "DRIVE"), ("IVPHELM_ALLSTOP", "clear")):
                obs.post(var, value)
            return len(obs.values("NODE_REPORT_LOCAL")) > 3 and len(obs.values("NODE_REPORT_PY")) > 3

        assert obs.wait(both, timeout=30)
    real, ours = str(obs.values("NODE_REPORT_LOCAL")[-1]), str(obs.values("NODE_REPORT_PY")[-1])
    print(f"\npNodeReporter: {real}\nnode-reporter: {ours}")

    def without_clock(line: str) -> list[str]:
        return [item for item in line.split(",") if not item.startswith(("TIME=", "INDEX="))]

    assert without_clock(ours) == without_clock(real)
    assert abs(parse_node_report(ours).time - parse_node_report(real).time) < 5
