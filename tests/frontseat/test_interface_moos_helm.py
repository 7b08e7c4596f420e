"""frontseat-interface with a [goby.moos.protobuf.moos_helm] block: the FrontSeatTranslation thread inside.

A MOOS client in the test plays pHelmIvP (IVPHELM_STATE, DESIRED_*) against our MOOSDB; NAV_* must come back
to it, and its setpoints must reach the simulator as CMD lines.
"""

from __future__ import annotations

import time
from pathlib import Path

from frontseat import groups
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.testing import running_simulator, start_interface_with_moos_helm
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.testing import connected_comms, running_moosdb

WARP = 10


def test_moos_helm_drives_the_simulator_through_the_interface(tmp_path: Path) -> None:
    with (
        broker_process(tmp_path, platform="usv") as broker,
        running_simulator() as sim,
        running_moosdb(community="usv", warp=WARP) as db,
    ):
        iface = start_interface_with_moos_helm(tmp_path, broker.env(), sim.port, db.port, warp=WARP,
                                               helm_running_timeout=60)
        try:
            with (
                PortalClient(broker.interprocess_config(), name="observer") as client,
                connected_comms(db.port, "pHelmIvP", register=["NAV_X", "NAV_HEADING", "NAV_SPEED"]) as helm,
            ):
                status = client.collect(groups.status, fs.InterfaceStatus)
                raw_out = client.collect(groups.raw_out, fs.Raw)
                assert client.wait_subscribed()
                nav: dict[str, float] = {}
                deadline = time.monotonic() + 60
                last_post = 0.0
                while time.monotonic() < deadline:
                    if time.monotonic() - last_post > 0.1:
                        last_post = time.monotonic()
                        helm.notify("IVPHELM_STATE", "DRIVE")
                        helm.notify("DESIRED_HEADING", 90.0)
                        helm.notify("DESIRED_DEPTH", 0.0)
                        helm.notify("DESIRED_SPEED", 2.0)
                    for msg in helm.fetch():
                        nav[msg.key()] = msg.double()
                    client.poll(0.02)
                    commanding = status and status[-1].state == fs.INTERFACE_COMMAND
                    sent = any(r.raw == b"CMD,HEADING:90,SPEED:2,DEPTH:0" for r in raw_out)
                    if commanding and sent and nav.get("NAV_HEADING", 0) > 45:
                        break
                else:
                    raise AssertionError(
                        f"no COMMAND/CMD/NAV: states {[s.state for s in status[-3:]]}, nav {nav}, "
                        f"log tail {iface.stderr_text()[-2000:]}"
                    )
                assert status[-1].helm_state == fs.HELM_DRIVE
                assert nav["NAV_SPEED"] > 0 and "NAV_X" in nav
        finally:
            code = iface.stop()
        assert code == 0, iface.stderr_text()[-3000:]
