"""One AUV of the trail mission on its own: auv.launch's real processes (broker, frontseat simulator and interface,
moos-db, ivp-helm with the rendered auv.bhv, node-reporter, the goby3_course gateway plugin, liaison).

The USV's nav and the RECOVER command normally reach this AUV over the acoustic link, through the AUV manager,
which republishes them on interprocess. Here a test double stands in for that hop: a portal client on the AUV's
broker publishes ``goby3_course::usv_nav`` (NavigationReport, PROTOBUF scheme, as the manager does) for a USV
driving east at 1.5 m/s, and later ``goby3_course::auv_command`` RECOVER. Everything after that hop is real.
Midway the AUV's simulator is killed and a new one started on its port (the run keeps going past the death, as
the demo's ``--keep-going``): the interface reconnects, returns to COMMAND and the AUV rejoins the trail.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import PortalClient
from launch.trail.mission import TrailMission, auv_slice_env, platform_entries, with_free_ports
from launch.trail.settings import TrailSettings, Vehicle
from translators.trail import groups
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand

WARP = 20
LOG_TIME_SLACK_S = 1.0  # sim seconds between the demo's clock and the times read back from the logs
USV_SPEED = 1.5


def test_one_auv_trails_the_usv_contact_survives_a_simulator_restart_and_recovers(tmp_path):
    vehicle = Vehicle("auv", 2, 1)  # index 1 of 2: trail angle 270 (the USV's port beam), depth 20 m
    settings = with_free_ports(TrailSettings(run_dir=tmp_path, warp=WARP, socket_dir=tmp_path), 2,
                               prefer_course=False)
    # the AUV manager's hop (acomms in, interprocess out) is the one the test double replaces
    entries = [e for e in platform_entries(vehicle) if not e.command.startswith("auv-manager")]
    mission = TrailMission(settings, 2, entries=entries, vehicles=[vehicle], extra_env=auv_slice_env(vehicle),
                           platform=vehicle.name, launch_delay_s=0.1, report=lambda line: None, keep_going=True)
    new_sim: subprocess.Popen[bytes] | None = None
    usv_start = (0.0, 60.0)
    client: PortalClient | None = None
    state = {"last": -1e9, "t_recover": None}

    def usv_position(t: float) -> tuple[float, float]:
        return usv_start[0] + USV_SPEED * t, usv_start[1]

    def publish_usv_nav() -> None:
        now = mission.now()
        if client is None or now - state["last"] < 2.0:
            return
        state["last"] = now
        x, y = usv_position(now)
        nav = NavigationReport(vehicle=1, time=time.time(), x=x, y=y, z=0, speed_over_ground=USV_SPEED, heading=90,
                               type=NavigationReport.USV)
        client.publish(groups.usv_nav, nav, scheme=Scheme.PROTOBUF)
        client.poll()

    try:
        mission.start()
        client = PortalClient(_interprocess(settings, vehicle), name="acomms_stand_in")
        assert client.wait_ready(30)
        mission.add_hook(publish_usv_nav)
        mission.wait_for_command(timeout_s=120)
        mission.run(150)
        # the simulator restarts: the interface leaves COMMAND, reconnects, and the AUV (back at the origin) rejoins
        assert mission.group is not None
        sim = next(p for p in mission.group.processes if p.name.endswith("frontseat-sim"))
        os.killpg(sim.pid, signal.SIGKILL)
        t_kill = mission.now()
        new_sim = subprocess.Popen([sys.executable, "-m", "frontseat.apps.frontseat_sim",
                                    str(vehicle.sim_port(settings))], stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
        record = mission.runs[vehicle.name].record
        states_after = lambda: [e.value for e in record.events_named("interface_state", "interface") if e.t > t_kill]  # noqa: E731
        mission.run(None, until=lambda: "INTERFACE_COMMAND" in states_after() or mission.now() - t_kill > 400)
        assert states_after()[-1] == "INTERFACE_COMMAND" and len(states_after()) > 1, states_after()
        assert [name for _, name, _ in mission.deaths] == [sim.name]
        t_back = mission.now()
        mission.run(None, until=lambda: mission.now() - t_back > 250)
        nav = record.snapshot()[0]
        t_end = mission.now()
        # trailing again: within the last 100 s, near the trail point 50 m off the USV's port beam, at 20 m
        recent = [s for s in nav if s.t > t_end - 100]
        ux, uy = usv_position(t_end)
        last = nav[-1]
        target = (ux, uy + 50.0)  # relative 270 with the USV heading east = north of it
        miss = math.hypot(last.x - target[0], last.y - target[1])
        assert miss < 25, f"AUV at ({last.x:.0f},{last.y:.0f}), trail point ({target[0]:.0f},{target[1]:.0f})"
        assert all(s.depth is not None and abs(s.depth - 20) < 3 for s in recent), [s.depth for s in recent][-5:]
        # RECOVER: the gateway posts depth=0 then AUV_DEPLOY_STATE=RECOVER; the AUV surfaces and heads for (100,-100)
        # Taken before the command (the gateway may post within ms), less a slack: the record's times are the logs'
        # (the gateway's posting time; the alog's LOGSTART has 0.1 s resolution), not the demo's clock.
        t_recover = mission.now() - LOG_TIME_SLACK_S
        client.publish(groups.auv_command, AUVCommand(time=time.time(), desired_state=AUVCommand.RECOVER))
        client.poll()
        mission.run(None, until=lambda: mission.now() - t_recover > 200)
        events = [(e.name, e.value) for e in record.snapshot()[1] if e.name in ("DEPLOY_DEPTH_UPDATES",
                                                                             "AUV_DEPLOY_STATE") and e.t >= t_recover]
        assert events[:2] == [("DEPLOY_DEPTH_UPDATES", "depth=0"), ("AUV_DEPLOY_STATE", "RECOVER")], events
        final = record.snapshot()[0][-1]
        assert final.depth is not None and final.depth < 2, final
        start = next(s for s in record.snapshot()[0] if s.t >= t_recover)
        before = math.hypot(start.x - 100, start.y + 100)
        after = math.hypot(final.x - 100, final.y + 100)
        assert after < before - 150 or after < 20, (before, after)
    finally:
        if client is not None:
            client.close()
        result = mission.stop()
        if new_sim is not None:
            new_sim.terminate()
            new_sim.wait(timeout=30)
    assert result.command_times[vehicle.name] is not None
    assert all(o.clean for o in result.outcomes if not o.name.endswith("frontseat-sim")), result.outcomes
    assert not result.log_errors, result.log_errors[:10]


def _interprocess(settings: TrailSettings, vehicle: Vehicle):
    from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig

    cfg = InterProcessPortalConfig()
    cfg.platform = vehicle.name
    cfg.socket_name = vehicle.ipc_base(settings)
    return cfg


