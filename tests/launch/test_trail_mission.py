"""The whole trail mission, as ``./all.launch`` runs it, reduced for CI: topside, USV and 2 AUVs at warp 10.

Every process is real (one goby-launch per platform, brokers with the satellite and acomms links on UDP multicast,
frontseat simulators and interfaces, moos-db, ivp-helm, node-reporter, gateways, managers, liaison pages). The
demo's operator sends POLYGON then WAYPOINTS from the topside over the satellite link and RECOVER from the USV over
the acoustic link. Asserted from the recorded run, the course_and_peers §1.10 checklist items that apply:
every vehicle reaches COMMAND; the topside republishes every vehicle's nav as NodeStatus; the USV obeys both
commands (POLYGON_UPDATES before DEPLOY_STATE) and every command is acked; the AUVs trail at their angle and depth;
RECOVER reaches every AUV (depth=0 first), which surfaces and heads for the station; every process exits cleanly
with no error line in any log. The vehicles' records are read from the run's logs (a .goby per platform, an .alog
per MOOS community), and those logs export to MCAP with every platform's groups.
"""

from __future__ import annotations

import shutil

import pytest

from launch.process_group import child_environment
from launch.record import MissionRecord, shifted, until
from launch.recorder import read_platform
from launch.trail.analysis import command_outcomes, recover_outcome, trail_performance
from launch.trail.links import LinkMonitor
from launch.trail.mission import TrailMission, with_free_ports
from launch.trail.operator import Operator, PortalWorker, parse_trail_schedule
from launch.trail.settings import TrailSettings, Vehicle
from tests.launch.mission_logs import assert_logs_per_platform, assert_mcap_export_has_every_group

N_AUVS = 2
WARP = 10
SCHEDULE = "0:polygon:6:200,150:waypoints,300:recover"
DURATION = 480.0
NEEDED = ("auv-manager", "topside-manager", "usv-manager")

pytestmark = pytest.mark.skipif(any(shutil.which(p, path=child_environment()["PATH"]) is None for p in NEEDED),
                                reason=f"the course's managers ({', '.join(NEEDED)}) are not installed yet")


def test_trail_mission_two_auvs(tmp_path):
    settings = with_free_ports(TrailSettings(run_dir=tmp_path, warp=WARP, socket_dir=tmp_path), N_AUVS,
                               prefer_course=False)
    mission = TrailMission(settings, N_AUVS, report=lambda line: None, launch_delay_s=0.5)
    links = LinkMonitor(settings, N_AUVS)
    mission.add_hook(links.poll)

    operator_record = MissionRecord()
    workers: list[PortalWorker] = []
    try:
        mission.start()
        topside = PortalWorker("topside", Vehicle("topside", N_AUVS).ipc_base(settings), WARP)
        usv = PortalWorker("usv", Vehicle("usv", N_AUVS).ipc_base(settings), WARP)
        workers = [topside, usv]
        for worker in workers:
            worker.start()
        operator = Operator(parse_trail_schedule(SCHEDULE), operator_record, mission.clock, topside, usv)
        mission.add_hook(operator.poll)
        t0 = mission.wait_for_command(timeout_s=120)
        assert t0 is not None
        operator.start(t0)
        mission.run(DURATION)
    finally:
        for worker in workers:
            worker.close()
        links.close()
        result = mission.stop()

    records = result.records
    assert all(t is not None for name, t in result.command_times.items() if name != "topside"), result.command_times
    operator_events = shifted(operator_record, result.t0)
    seen = {e.value for e in records["topside"].events_named("node_status", "topside")}
    assert {"USV", "AUV_0", "AUV_1"} <= seen, seen

    # The records are the logs': a .goby per platform, an .alog per MOOS community, in each platform's log
    # directory; read again, they give the same records; exported to MCAP, every platform's groups.
    vehicles = {name: run.vehicle for name, run in mission.runs.items()}
    assert_logs_per_platform(result.logs, {name: v.log_dir(settings) for name, v in vehicles.items()},
                             {"usv", "auv0", "auv1"})
    for name, vehicle in vehicles.items():
        again = read_platform(vehicle.log_dir(settings), name, WARP, moos=vehicle.kind != "topside",
                              node_status=vehicle.kind == "topside", origin=mission.clock.origin).record
        last = max([s.t for s in records[name].nav] + [e.t for e in records[name].events]) + result.t0 + 1e-6
        again = shifted(until(again, last), result.t0)
        assert again.nav == records[name].nav and again.events == records[name].events, name
    topics = assert_mcap_export_has_every_group(tmp_path / "logs", [p for paths in result.logs.values()
                                                                   for p in paths if p.suffix == ".goby"])
    by_platform = {mcap.name.split("_")[0]: groups for mcap, groups in topics.items()}
    assert "goby::middleware::frontseat::node_status" in by_platform["topside"], by_platform["topside"]
    for name in ("usv", "auv0", "auv1"):
        assert "goby::middleware::frontseat::status" in by_platform[name], by_platform[name]

    for i in range(N_AUVS):
        vehicle = Vehicle("auv", N_AUVS, i)
        trail = trail_performance(vehicle, records[vehicle.name], records["usv"])
        assert trail.settled_at is not None, f"{vehicle.name} never came within 20 m of its trail point"
        assert trail.range_error is not None and trail.range_error.mean < 25, (vehicle.name, trail.range_error)
        assert trail.depth_error is not None and trail.depth_error.mean < 3, trail.depth_error
        recover = recover_outcome(vehicle.name, records[vehicle.name])
        assert recover.depth_updates_first, recover
        assert recover.final_depth is not None and recover.final_depth < 3, recover
        assert recover.min_distance_to_station is not None
    assert links.stats["satellite"].acks > 0 and links.stats["acomms"].frames > 0
    assert all(o.clean for o in result.outcomes), result.outcomes
    assert not result.log_errors, result.log_errors[:10]

    # RECOVER went from the USV over acomms to both AUVs, acked
    commands = command_outcomes(operator_events, records)
    assert [c.what.split()[0] for c in commands] == ["polygon", "waypoints", "recover"], commands
    assert commands[2].acks and set(commands[2].arrived_at) == {"auv0", "auv1"}, commands[2]
    # the USV commands went from the topside over satellite to usv-manager, acked, and drove the USV's MOOSDB
    assert all(c.acked_at is not None for c in commands), commands
    assert "usv" in commands[0].arrived_at and "usv" in commands[1].arrived_at, commands
    usv_posts = [e.name for e in records["usv"].snapshot()[1]
                 if e.name in ("POLYGON_UPDATES", "DEPLOY_STATE") and e.t >= commands[0].sent_at]
    assert usv_posts[:2] == ["POLYGON_UPDATES", "DEPLOY_STATE"], usv_posts
