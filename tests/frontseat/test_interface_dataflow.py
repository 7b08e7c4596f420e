"""Which way the interface's data travels: a fix is published when it arrives (not at the 10 Hz tick), and the
embedded MOOS helm interface talks to the main thread by interthread (as Goby's threads do), not through the broker.
"""

from __future__ import annotations

import time
from functools import partial
from pathlib import Path

import pytest
from google.protobuf import text_format

from frontseat import groups
from frontseat.interface import FrontSeatInterface
from frontseat.loading import driver_factory, load_driver_library
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.testing import basic_simulator_frontseat_cfg, running_simulator, start_interface_with_moos_helm
from gateway.goby.portal.testing import PortalClient, broker_process, running_app
from gateway.moos.testing import connected_comms, running_moosdb

LAT, LON = 41.592344, -70.711260
WARP = 10


def test_a_nav_fix_is_published_when_it_arrives_not_at_the_loop_tick(tmp_path: Path) -> None:
    """The interface's loop is slowed to once in ~12 days: the first tick (which publishes the first status) never
    comes during the test, yet the simulator's NAV lines reach node_status and data_from_frontseat."""
    with broker_process(tmp_path, platform="usv") as broker, running_simulator() as sim:
        factory = driver_factory(load_driver_library("basic_simulator"))  # registers its Config extensions
        cfg = app_pb.FrontSeatInterfaceConfig()
        text_format.Parse(basic_simulator_frontseat_cfg(sim.port, lat=LAT, lon=LON), cfg)
        cfg.app.name = "frontseat_interface"
        cfg.app.geodesy.lat_origin, cfg.app.geodesy.lon_origin = LAT, LON
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with (
            PortalClient(broker.interprocess_config(), name="observer") as client,
            running_app(partial(FrontSeatInterface, driver_factory=factory, loop_frequency_hz=1e-6), cfg) as app,
        ):
            nav = client.collect(groups.node_status, data_pb.NodeStatus)
            data = client.collect(groups.data_from_frontseat, fs.InterfaceData)
            raw_out = client.collect(groups.raw_out, fs.Raw)
            status = client.collect(groups.status, fs.InterfaceStatus)
            assert client.wait_subscribed()
            assert client.poll_until(lambda: len(nav) >= 3 and len(data) >= 3, 30), "no NAV published"
            assert status == []  # the loop has not ticked: the fixes did not wait for it
            assert app.driver.state() == fs.INTERFACE_STANDBY  # the state machine runs only in the tick
            fix = nav[-1]
            assert (fix.name, fix.global_fix.lat, fix.global_fix.lon) == ("usv", pytest.approx(LAT, abs=1e-4),
                                                                         pytest.approx(LON, abs=1e-4))  # START: %g
            assert data[-1].node_status == fix
            # START went out when the link came up, without a tick either (if our subscription was in place)
            assert all(r.raw.startswith(b"START,") for r in raw_out)


def test_the_embedded_helm_talks_to_the_interface_by_interthread(tmp_path: Path) -> None:
    """The MOOS helm drives the simulator through the embedded FrontSeatTranslation. While the broker is up, it
    carries node_status, helm_state and desired_course to other processes, as gobyd does (Goby publishes all three
    interprocess). Then the broker stops: the loop helm -> interface -> simulator -> interface -> helm goes on, so
    none of it went through the broker."""
    with (
        broker_process(tmp_path, platform="usv") as broker,
        running_simulator() as sim,
        running_moosdb(community="usv", warp=WARP) as db,
    ):
        iface = start_interface_with_moos_helm(tmp_path, broker.env(), sim.port, db.port, warp=WARP,
                                               helm_running_timeout=5, lat=LAT, lon=LON)
        try:
            with connected_comms(db.port, "pHelmIvP", register=["NAV_HEADING", "NAV_SPEED"]) as helm:
                nav: dict[str, float] = {}
                posted = [0.0]

                def drive(heading: float) -> None:
                    """pHelmIvP's iteration, every 0.1 s (AppTick 1 at warp 10)."""
                    if time.monotonic() - posted[0] > 0.1:
                        posted[0] = time.monotonic()
                        helm.notify("IVPHELM_STATE", "DRIVE")
                        helm.notify("DESIRED_HEADING", heading)
                        helm.notify("DESIRED_DEPTH", 0.0)
                        helm.notify("DESIRED_SPEED", 2.0)
                    for msg in helm.fetch():
                        nav[msg.key()] = msg.double()

                with PortalClient(broker.interprocess_config(), name="observer") as client:
                    status = client.collect(groups.status, fs.InterfaceStatus)
                    reports = client.collect(groups.helm_state, fs.HelmStateReport)
                    courses = client.collect(groups.desired_course, data_pb.DesiredCourse)
                    fixes = client.collect(groups.node_status, data_pb.NodeStatus)
                    assert client.wait_subscribed()

                    deadline = time.monotonic() + 60
                    # (the helm thread's first publications may precede our subscription at its socket: wait for some)
                    while not (status and status[-1].state == fs.INTERFACE_COMMAND
                               and 80 < nav.get("NAV_HEADING", 0) < 100 and reports and courses and fixes):
                        assert time.monotonic() < deadline, (
                            f"no COMMAND heading east: {status[-1:]}, {nav}, {len(reports)} helm_state, "
                            f"{len(courses)} desired_course, {len(fixes)} node_status\n{iface.stderr_text()[-2000:]}")
                        drive(90.0)
                        client.poll(0.02)
                    assert reports[-1].state == fs.HELM_DRIVE
                    assert courses[-1].heading == 90.0 and courses[-1].speed == 2.0
                    assert fixes[-1].name == "usv"

                assert broker.stop() == 0
                # Longer than helm_running_timeout (5 s simulated): without helm_state reports by interthread the
                # interface would be in HELM_ERROR now and forward no course.
                held = time.monotonic() + 1.0
                while time.monotonic() < held:
                    drive(90.0)
                    time.sleep(0.01)
                deadline = time.monotonic() + 30
                while not 260 < nav.get("NAV_HEADING", 0) < 280:
                    assert time.monotonic() < deadline, (
                        f"no turn west without the broker: {nav}\n{iface.stderr_text()[-2000:]}")
                    drive(270.0)
                    time.sleep(0.01)
                assert nav["NAV_SPEED"] > 1.0
            assert iface.running, iface.stderr_text()[-3000:]
        finally:
            code = iface.stop()
        assert code == 0, iface.stderr_text()[-3000:]
