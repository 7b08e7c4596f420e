"""The AUV side of the trail mission in closed loop: one USV and two AUVs, each with its own ``moos-db`` and
``ivp-helm`` process, vehicles simulated by the kinematic double, the USV's ``node-reporter`` process, and the
acomms link double carrying the USV's report to the AUVs every 20 s.

The USV runs a straight waypoint line at 1.5 m/s; the AUVs run ``behaviors/auv.bhv.in`` filled in for n = 2
(trail angles 90 and 270, depths 10 and 20). MOOSTimeWarp 20 keeps ~9 simulated minutes to about half a minute.
"""

from __future__ import annotations

import contextlib
import math
import sys
from collections.abc import Iterator
from pathlib import Path

from gateway.moos import MoosClock
from gateway.moos.testing import moosdb_process
from launch.config import render

from .acomms_link_double import AcommsLinkDouble
from .moos_harness import REPO, helm_process, observer, vehicle, write_mission

WARP = 20.0
SETTLE_S, MEASURE_S, RECOVER_S = 150.0, 300.0, 120.0
N_AUVS = 2
NODE_REPORTER = Path(sys.executable).parent / "node-reporter"

REPORTER_BLOCK = """
ProcessConfig = pNodeReporter
{{
  AppTick   = 4
  CommsTick = 4
  platform_type   = {vtype}
  platform_length = 4
}}
"""
DEPTH_DOMAIN = "  domain     = depth:0:200:201\n"

USV_LINE = """\
initialize MOOS_MANUAL_OVERRIDE = false
Behavior = BHV_Waypoint
{
  name           = line
  speed          = 1.5
  lead           = 8
  capture_radius = 5
  points         = 2000,-100
}
"""
USV_START = {"x": -520.0, "y": -100.0, "heading": 90.0}
STATION = (100.0, -100.0)


def auv_values(index: int, n: int = N_AUVS) -> dict[str, float]:
    """The course's auv.pb.cfg.py: a fan of trail angles from 90 to 270, depths 10 m apart."""
    return {"trail_angle": 90 + (270 - 90) / (n - 1) * index, "deploy_depth": 10 + 10 * index}


def auv_mission(directory: Path, port: int, community: str, bhv: Path, auv: bool, warp: float = WARP) -> Path:
    """The course's AUV (or USV) .moos: helm at AppTick 1 (depth domain for an AUV) and a pNodeReporter block."""
    return write_mission(directory, port, bhv, warp, community, max_speed="4" if auv else "2",
                         extra=DEPTH_DOMAIN if auv else "", app_tick=1, name=f"{community}.moos",
                         blocks=REPORTER_BLOCK.format(vtype="auv" if auv else "usv"))


@contextlib.contextmanager
def vehicle_stack(tmp_path: Path, community: str, bhv_text: str, auv: bool, clock: MoosClock,
                  start: dict[str, float]) -> Iterator[tuple]:
    """moos-db, ivp-helm (and for the USV node-reporter) as processes, plus the kinematic vehicle double."""
    directory = tmp_path / community
    directory.mkdir()
    bhv = directory / f"{community}.bhv"
    bhv.write_text(bhv_text)
    with moosdb_process(directory, community, WARP) as db:
        mission = auv_mission(directory, db.port, community, bhv, auv)
        with contextlib.ExitStack() as stack:
            stack.enter_context(helm_process(mission, directory))
            if not auv:
                reporter_dir = directory / "node_reporter"
                reporter_dir.mkdir()
                stack.enter_context(helm_process(mission, reporter_dir, [str(NODE_REPORTER), str(mission), "-v"]))
            sim = stack.enter_context(vehicle(db.port, clock, **start))
            obs = stack.enter_context(observer(db.port, clock, ["IVPHELM_STATE", "IVPHELM_ALLSTOP", "BHV_ERROR",
                                                                "REGION", "NODE_REPORT", "DESIRED_DEPTH"]))
            yield db, sim, obs


def interpolate(track, t: float) -> tuple[float, float, float]:
    """(x, y, heading) of a (t, x, y, heading, speed) track at time t (linear; heading of the nearest sample)."""
    lo, hi = 0, len(track) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if track[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    (t0, x0, y0, h0, _), (t1, x1, y1, h1, _) = track[lo], track[hi]
    f = 0.0 if t1 == t0 else min(1.0, max(0.0, (t - t0) / (t1 - t0)))
    return x0 + f * (x1 - x0), y0 + f * (y1 - y0), h0 if f < 0.5 else h1


def trail_errors(usv_track, auv_track, trail_angle: float, start: float, end: float) -> list[tuple[float, float]]:
    """(range error m, relative-bearing error deg) once per simulated second between start and end."""
    errors = []
    t = start
    while t <= end:
        ux, uy, uh = interpolate(usv_track, t)
        ax, ay, _ = interpolate(auv_track, t)
        relative = (math.degrees(math.atan2(ax - ux, ay - uy)) - uh) % 360.0
        errors.append((math.hypot(ax - ux, ay - uy) - 50.0, (relative - trail_angle + 180.0) % 360.0 - 180.0))
        t += 1.0
    return errors


def test_two_auvs_trail_the_usv_then_recover(tmp_path: Path) -> None:
    clock = MoosClock(WARP)
    template = REPO / "behaviors" / "auv.bhv.in"
    with contextlib.ExitStack() as stack:
        usv_db, usv, _ = stack.enter_context(vehicle_stack(tmp_path, "trail_usv", USV_LINE, False, clock,
                                                           USV_START))
        auvs = []
        for i in range(N_AUVS):
            start = {"x": USV_START["x"], "y": USV_START["y"] + (10 if i else -10), "heading": 90.0}
            auvs.append(stack.enter_context(vehicle_stack(tmp_path, f"AUV{i}", render(template, auv_values(i)),
                                                          True, clock, start)))
        link = stack.enter_context(AcommsLinkDouble(usv_db.port, [db.port for db, _, _ in auvs], clock))
        obs0 = auvs[0][2]
        began = clock.time()
        assert obs0.wait(lambda: obs0.last("IVPHELM_STATE") == "DRIVE", timeout=30), log_tail(tmp_path)
        obs0.wait_moos(SETTLE_S + MEASURE_S - (clock.time() - began), timeout=120)
        measured_to = clock.time()
        depths = [sim.model.depth for _, sim, _ in auvs]
        for _, _, obs in auvs:
            obs.post("DEPLOY_DEPTH_UPDATES", "depth=0")
            obs.post("AUV_DEPLOY_STATE", "RECOVER")
        obs0.wait_moos(RECOVER_S, timeout=60)
        recovered = [(sim.model.depth, math.hypot(sim.model.x - STATION[0], sim.model.y - STATION[1]))
                     for _, sim, _ in auvs]
        usv_track = usv.track
        auv_tracks = [sim.track for _, sim, _ in auvs]
        for _, _, obs in auvs:
            obs.poll()
        auv_mail = [obs.mail for _, _, obs in auvs]

    deliveries = [t for t, _ in link.delivered]
    gaps = [b - a for a, b in zip(deliveries, deliveries[1:], strict=False)]
    assert deliveries and all(19.0 < gap < 22.0 for gap in gaps), gaps
    assert link.delivered[0][1].startswith("NAME=USV,TYPE=USV,TIME=")
    for mail in auv_mail:  # the AUV helms had the contact only from the link's reports
        assert {v for _, n, v, _ in mail if n == "NODE_REPORT"} <= {line for _, line in link.delivered}
        regions = {v for _, n, v, _ in mail if n == "REGION"}
        assert regions <= {"Outside nm_radius", "Inside nm_radius", "Inside radius"} and "Inside radius" in regions
    for i, track in enumerate(auv_tracks):
        angle = auv_values(i)["trail_angle"]
        errors = trail_errors(usv_track, track, angle, measured_to - MEASURE_S, measured_to)
        good = [abs(dr) <= 10.0 and abs(db) <= 15.0 for dr, db in errors]
        ranges = sorted(abs(dr) for dr, _ in errors)
        bearings = sorted(abs(db) for _, db in errors)
        print(f"AUV{i} trail angle {angle:.0f}: {sum(good)}/{len(good)} fixes in tolerance; |range error| "
              f"median {ranges[len(ranges) // 2]:.1f} m, max {ranges[-1]:.1f} m; |bearing error| median "
              f"{bearings[len(bearings) // 2]:.1f} deg, max {bearings[-1]:.1f} deg; depth {depths[i]:.2f} m")
        assert sum(good) >= 0.9 * len(good), (i, errors[:10], errors[-10:])
        assert abs(depths[i] - auv_values(i)["deploy_depth"]) <= 1.0
        depth, distance = recovered[i]
        print(f"AUV{i} after RECOVER: depth {depth:.2f} m, {distance:.1f} m from the station")
        assert abs(depth) <= 0.1 and distance <= 10.0, recovered


def log_tail(tmp_path: Path) -> str:
    return "\n".join(f"{p}: {p.read_text()[-1500:]}" for p in sorted(tmp_path.glob("*/helm.log")))
