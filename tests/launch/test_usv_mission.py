"""The whole USV mission end to end: real processes from launch/usv/usv.launch, commands from shore, the track
read from the run's logs (goby-logger's .goby per platform, moos-logger's .alog), which also export to MCAP.

Runs with our moos-db and ivp-helm always, and with the real MOOSDB and pHelmIvP when both are on PATH
(run the real one inside a private network namespace: the C++ MOOSDB listens on every address).
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest

from gateway.goby.intervehicle.testing import random_multicast
from gateway.goby.portal.interface_registry import ENV_VAR as REGISTRY_ENV
from gateway.goby.portal.interface_registry import read_entries
from gateway.moos.testing import real_moos_skip_reason
from launch.interfaces.deployment import DEFAULT_INTERFACES_DIR
from launch.interfaces.drift import covered_threads, drift_problems
from launch.interfaces.interface_yaml import load as load_interface
from launch.record import shifted, until
from launch.usv.analysis import (
    bhv_waypoints,
    command_effects,
    helm_timeline,
    interface_timeline,
    link_acks,
    loiter_phases,
    waypoint_approach,
)
from launch.usv.config import data_log_dir
from launch.usv.mission import MissionResult, UsvMission, read_mission_logs
from launch.usv.settings import UsvSettings
from launch.usv.summary import summary_text
from tests.launch.mission_logs import assert_logs_per_platform, assert_mcap_export_has_every_group
from util.process import free_port

WARP = 30
DURATION_S = 1150.0
SCHEDULE = "0:polygon:6:200,450:waypoints,700:polygon:8:400"

REAL_MOOS_SKIP = real_moos_skip_reason("MOOSDB", "pHelmIvP")


def run_mission(run_dir: Path, moosdb: str, helm: str) -> tuple[MissionResult, UsvSettings, float]:
    """The result, the settings and the mission's time origin (its records' t=0 before the shift to COMMAND)."""
    socket_dir = Path(tempfile.mkdtemp(prefix="usvt-", dir="/tmp"))  # AF_UNIX paths must stay short
    settings = UsvSettings(
        run_dir=run_dir,
        warp=WARP,
        moos_port=free_port(),
        sim_port=free_port(),
        liaison_port=free_port(),
        moosdb=moosdb,
        helm=helm,
        schedule=SCHEDULE,
        socket_name=str(socket_dir / "goby_usv"),
        sat_port=random_multicast()[1],  # the satellite link: a port no parallel run shares
    )
    lines: list[str] = []
    mission = UsvMission(settings, report=lines.append)
    failure = None
    try:
        mission.start()
        mission.run(DURATION_S)
    except Exception as exc:  # the result carries it; the assertions below report it with the summary
        failure = f"{type(exc).__name__}: {exc}"
    finally:
        result = mission.stop(failure)
        shutil.rmtree(socket_dir, ignore_errors=True)
    return result, settings, mission.clock.origin


@pytest.mark.parametrize(
    ("moosdb", "helm"),
    [
        pytest.param("moos-db", "ivp-helm", id="ours"),
        pytest.param(
            "MOOSDB", "pHelmIvP", id="real-moos-ivp",
            marks=[pytest.mark.interop,
                   pytest.mark.skipif(REAL_MOOS_SKIP is not None, reason=str(REAL_MOOS_SKIP))],
        ),
    ],
)
def test_vehicle_obeys_commands_from_shore(tmp_path, moosdb, helm, monkeypatch):
    registry_dir = tmp_path / "interface_registry"
    registry_dir.mkdir()
    monkeypatch.setenv(REGISTRY_ENV, str(registry_dir))  # every app records the calls it made (see below)
    result, settings, origin = run_mission(tmp_path / "run", moosdb, helm)
    record = result.record
    waypoints = bhv_waypoints(UsvSettings().bhv_file)
    report = summary_text(result, waypoints)
    assert result.failure is None, report

    # The interface reached COMMAND and the helm drove the vehicle.
    states = [state for _, state in interface_timeline(record)]
    assert "INTERFACE_COMMAND" in states, report
    assert states[states.index("INTERFACE_COMMAND"):] == ["INTERFACE_COMMAND"], report  # and stayed there
    assert "DRIVE" in [state for _, state in helm_timeline(record)], report
    assert len(record.nav) > 200, report

    # Three commands reached MOOS, in order, with the postings CommandTranslation makes.
    effects = command_effects(record)
    assert [e.state for e in effects] == ["POLYGON", "WAYPOINTS", "POLYGON"], report
    first, waypoints_cmd, second = effects
    assert [p.name for p in waypoints_cmd.posts] == ["DEPLOY_STATE"], report
    assert second.polygon_before_state, report
    assert "radius=400" in second.posts[0].value and "pts=8" in second.posts[0].value, report

    # Each reached the USV over the satellite link: acked once, within a 10 s (sim) cycle of slots.
    links = link_acks(record)
    assert [a.acked for a in links] == [True, True, True], report
    # (the ack is sent at once by the USV's modem: it follows the slot within the delivery time; on a loaded machine
    # a slot may start up to half a real second late, WARP / 2 sim seconds)
    late = WARP / 2
    assert all(0 <= a.slot_wait <= 10 + late and a.slot_wait <= a.latency <= a.slot_wait + late for a in links), report
    assert all(a.responder == "satellite modem 2" for a in links), report

    # It converged on the hexagon of radius 200 before the waypoints command.
    phases = loiter_phases(record)
    assert len(phases) == 2, report
    hexagon, octagon = phases
    assert len(hexagon.ring.vertices) == 6 and abs(hexagon.ring.mean_radius - 200) < 10, report
    assert hexagon.settled_at is not None and hexagon.settled_at < waypoints_cmd.t - 100, report
    assert hexagon.mean_distance is not None and hexagon.mean_distance < 10.0, report

    # After WAYPOINTS it turned toward the first waypoint and closed on it.
    approach = waypoint_approach(record, waypoints)
    assert approach is not None, report
    assert approach.min_heading_error is not None and approach.min_heading_error < 20.0, report
    assert approach.min_range < approach.start_range - 100.0, report

    # After the second polygon command it moved out to the larger ring and stayed on it.
    assert len(octagon.ring.vertices) == 8 and abs(octagon.ring.mean_radius - 400) < 20, report
    assert octagon.start >= second.t - 1.0, report
    assert octagon.final_center_distance is not None and octagon.final_center_distance > 300.0, report
    assert octagon.settled_at is not None and octagon.mean_distance is not None, report
    assert octagon.mean_distance < 15.0, report

    # The record is the logs': a .goby per platform (the USV's, the topside's), an .alog for the USV's MOOS
    # community; read again they give the same record; exported to MCAP (the demo's command), every group.
    log_dirs = {platform: data_log_dir(settings, platform) for platform in ("usv", "topside")}
    by_platform = {platform: [p for p in result.logs if log_dirs[platform] in p.parents] for platform in log_dirs}
    assert_logs_per_platform(by_platform, log_dirs, {"usv"})
    again, _ = read_mission_logs(settings, origin)
    last = max([s.t for s in record.nav] + [e.t for e in record.events]) + result.command_time + 1e-6
    again = shifted(until(again, last), result.command_time)
    assert again.nav == record.nav and again.events == record.events
    topics = assert_mcap_export_has_every_group(settings.log_dir, [p for p in result.logs if p.suffix == ".goby"])
    usv_topics = next(t for mcap, t in topics.items() if mcap.name.startswith("usv_"))
    assert {"goby::middleware::frontseat::status", "goby3_course::usv_command_ack"} <= usv_topics, usv_topics

    # Every process stopped cleanly and no log holds an unexpected error.
    # 11 + goby-coroner, usv-health-monitor, topside-manager, the two goby-loggers and moos-logger
    assert len(result.outcomes) == 17, report
    assert all(o.clean for o in result.outcomes), report
    assert result.log_errors == [], report

    # The USV's health reached the topside over the satellite link (goby-coroner -> usv-health-monitor ->
    # topside-manager; docs/health.md): GOOD while every expected application answers (topside-manager runs with -v:
    # a GOOD status is logged at INFO, a FAILED one as a warning).
    manager_log = next(o.log_path for o in result.outcomes if o.name == "topside.manager").read_text()
    assert "Received HealthStatus: state: GOOD" in manager_log, report

    # What the apps really published and subscribed is what their interface files say (no drift).
    runtime = [entry for path in registry_dir.glob("*.json") for entry in read_entries(path)]
    interfaces = [load_interface(path) for path in sorted(DEFAULT_INTERFACES_DIR.glob("*_interface.yml"))]
    covered = covered_threads(runtime, interfaces)
    assert {"FrontSeatInterface", "FrontSeatTranslation", "CommandTranslation", "USVManager", "ShoreOperator"} <= covered
    assert drift_problems(runtime, interfaces) == []
