"""FrontSeatTranslation embedded in another application, as frontseat-interface runs it:
``launch_thread(FrontSeatTranslation, gateway_cfg)`` with the datum in ``gateway_cfg.app.geodesy``."""

from __future__ import annotations

import threading
import time

import pytest

from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from frontseat.protobuf.navigation_pb2 import DatumUpdate
from gateway.goby.portal import MultiThreadApplication, ProcessContext, use_context
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.testing import connected_comms, running_moosdb
from translators.frontseat.translation import FrontSeatTranslation
from translators.testing import gateway_config
from translators.usv.protobuf.usv_config_pb2 import USVManager as HostConfig

# ivp_helm.md §7.3: origin 43.8253, -70.3304; (100, 100) <-> (43.82621460, -70.32917667)
ORIGIN = (43.8253, -70.3304)
LAT, LON = 43.82621460, -70.32917667


def test_embedded_translator_uses_the_datum_it_was_given_and_follows_datum_updates(tmp_path):
    with running_moosdb(community="usv") as db, broker_process(tmp_path, platform="usv") as broker:
        host_cfg = HostConfig()
        host_cfg.app.name = "frontseat_host"
        host_cfg.interprocess.CopyFrom(broker.interprocess_config())
        gateway_cfg = gateway_config(db.port, broker.interprocess_config())
        gateway_cfg.app.geodesy.lat_origin, gateway_cfg.app.geodesy.lon_origin = ORIGIN
        context = ProcessContext(host_cfg.interprocess, application="frontseat_host", hold_settle_s=0.2)
        app = None
        runner = None
        try:
            with use_context(context):
                app = MultiThreadApplication(host_cfg)
                app.launch_thread(FrontSeatTranslation, gateway_cfg)
            runner = threading.Thread(target=app.run, name="embedded-host-main")
            runner.start()
            with connected_comms(db.port, "watch_embedded", register=["NAV_X", "NAV_Y"]) as watcher, \
                    PortalClient(broker.interprocess_config(), name="nav_source") as client:
                assert client.wait_subscribed()

                status = NodeStatus(time=1.0)
                status.global_fix.lat, status.global_fix.lon = LAT, LON
                status.pose.heading = 0.0
                status.speed.over_ground = 0.0
                latest: dict[str, float] = {}

                def nav_reaches(x: float, y: float) -> None:
                    deadline = time.monotonic() + 30
                    while (latest.get("NAV_X"), latest.get("NAV_Y")) != pytest.approx((x, y), abs=0.005):
                        assert time.monotonic() < deadline, f"NAV_X/NAV_Y never reached ({x}, {y}): {latest}"
                        client.publish(groups.node_status, status)
                        client.poll(0.2)
                        latest.update((m.key(), m.double()) for m in watcher.fetch())

                nav_reaches(100.0, 100.0)
                # Move the datum onto the vehicle: Goby apps re-project after goby::datum_update.
                update = DatumUpdate()
                update.datum.lat, update.datum.lon = LAT, LON
                client.publish(groups.datum_update, update)
                nav_reaches(0.0, 0.0)
        finally:
            if app is not None:
                app.quit()
                if runner is not None:
                    runner.join(30)
                app.close()
            context.close()
