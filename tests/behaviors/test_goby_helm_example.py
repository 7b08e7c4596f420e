"""The Goby-side helm example (course homework 3): leg logic alone, then end to end through the real
frontseat path: frontseat-sim <-> frontseat-interface <-> goby-broker <-> goby_helm_example (all processes).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

from behaviors.apps.goby_helm_example import Leg, TriangleLegs
from frontseat import groups
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.testing import basic_simulator_frontseat_cfg, running_simulator
from gateway.goby.portal.testing import PortalClient, app_process, broker_process

WARP = 10
ORIGIN = (41.592344, -70.711260)


def test_legs_switch_on_time_then_stop_when_no_longer_closing() -> None:
    legs = TriangleLegs(speed=1.5, east_duration=100, south_duration=50, window=3)
    assert legs.update(0.0, (0.0, 0.0)) == (90.0, 1.5)
    assert legs.update(100.0, (150.0, 0.0)) == (90.0, 1.5)  # not yet: strictly after the duration
    assert legs.update(100.5, (150.0, 0.0)) == (180.0, 1.5)
    assert legs.update(150.0, (150.0, -75.0)) == (180.0, 1.5)
    assert legs.update(151.0, (150.0, -75.0)) == (315.0, 1.5)
    # closing on the start: ranges 160, 150, 140, 130 ... averaged over 3 samples
    rng = [160, 150, 140, 130, 120, 110, 115, 125, 135]
    commands = [legs.update(152.0 + i, (r, 0.0)) for i, r in enumerate(rng)]
    assert legs.leg is Leg.RECOVER
    # the average over (110, 115, 125) is no longer below the closest average (115): stop at sample 8
    assert commands[:7] == [(315.0, 1.5)] * 7 and commands[7:] == [(0.0, 0.0)] * 2
    assert legs.update(500.0, (0.0, 0.0)) == (0.0, 0.0)  # stays stopped


def test_the_first_node_status_is_the_start() -> None:
    legs = TriangleLegs(speed=2.0, east_duration=1, south_duration=1, window=1)
    legs.update(0.0, None)
    legs.update(5.0, (10.0, 10.0))
    assert legs.start == (10.0, 10.0)


def test_triangle_through_the_real_frontseat_path(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="usv") as broker, running_simulator() as sim:
        iface_cfg = tmp_path / "frontseat.pb.cfg"
        iface_cfg.write_text(
            "app {\n"
            f"  geodesy {{ lat_origin: {ORIGIN[0]} lon_origin: {ORIGIN[1]} }}\n"
            f"  simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }}\n"
            "}\n" + basic_simulator_frontseat_cfg(sim.port, status_period=1))
        helm_cfg = tmp_path / "helm.pb.cfg"
        helm_cfg.write_text(
            f"app {{ simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }} }}\n"
            "speed: 1.5\neast_duration: 40\nsouth_duration: 30\n")
        env = broker.env()
        env["FRONTSEAT_DRIVER_LIBRARY"] = "basic_simulator"
        with PortalClient(broker.interprocess_config(), name="observer") as client, \
                app_process([sys.executable, "-m", "frontseat.apps.frontseat_interface", str(iface_cfg), "-v"], env=env,
                           log_path=tmp_path / "iface.log"), \
                app_process([sys.executable, "-m", "behaviors.apps.goby_helm_example", str(helm_cfg), "-v"],
                           env=broker.env(), log_path=tmp_path / "helm.log"):
            nav = client.collect(groups.node_status, data_pb.NodeStatus)
            courses = client.collect(groups.desired_course, data_pb.DesiredCourse)
            status = client.collect(groups.status, fs.InterfaceStatus)
            assert client.wait_subscribed()
            stopped = client.poll_until(lambda: any(c.speed == 0 for c in courses), timeout_s=60)
            assert stopped, ((tmp_path / "helm.log").read_text()[-2000:], [(c.heading, c.speed) for c in courses[-5:]])
            assert any(s.state == fs.INTERFACE_COMMAND for s in status), (tmp_path / "iface.log").read_text()[-2000:]
            deadline = time.monotonic() + 3
            while time.monotonic() < deadline:  # let the stopped vehicle report a few more fixes
                client.poll(0.05)
    headings = []
    for c in courses:
        key = (c.heading, c.speed)
        if not headings or headings[-1] != key:
            headings.append(key)
    assert headings == [(90.0, 1.5), (180.0, 1.5), (315.0, 1.5), (0.0, 0.0)]
    track = [(n.local_fix.x, n.local_fix.y, n.speed.over_ground) for n in nav if n.HasField("local_fix")]
    x0, y0, _ = track[0]
    east_end = max(track, key=lambda p: p[0])
    south_end = min(track, key=lambda p: p[1])
    # about 1.5 m/s for 40 s east and 30 s south; wide bounds: the simulator's start-up and turns take time
    assert 20 < east_end[0] - x0 < 80
    assert 15 < y0 - south_end[1] < 55
    ranges = [math.hypot(x - x0, y - y0) for x, y, _ in track]
    closest = min(ranges[ranges.index(max(ranges)):])
    assert ranges[-1] < closest + 15  # it stopped soon after it stopped closing on the start
    assert track[-1][2] < 0.3  # and it is (nearly) stopped
