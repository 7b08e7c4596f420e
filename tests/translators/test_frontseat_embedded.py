"""FrontSeatTranslation embedded in another application, as frontseat-interface runs it:
``launch_thread(FrontSeatTranslation, gateway_cfg, embedded=True)`` with the datum in ``gateway_cfg.app.geodesy``.

The host's main thread plays the interface: it publishes node_status and takes desired_course and helm_state by
interthread, while another process still sees those two through the broker (Goby publishes them interprocess)."""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import partial

import pytest

from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import DesiredCourse, NodeStatus
from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, HelmStateReport
from frontseat.protobuf.navigation_pb2 import DatumUpdate
from gateway.goby.portal import MultiThreadApplication
from gateway.goby.portal.testing import PortalClient, broker_process, running_app
from gateway.moos.testing import connected_comms, running_moosdb
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.frontseat.translation import FrontSeatTranslation
from translators.testing import gateway_config
from translators.usv.protobuf.usv_config_pb2 import USVManager as HostConfig

# ivp_helm.md §7.3: origin 43.8253, -70.3304; (100, 100) <-> (43.82621460, -70.32917667)
ORIGIN = (43.8253, -70.3304)
LAT, LON = 43.82621460, -70.32917667
TIMEOUT_S = 30.0


class Host(MultiThreadApplication):
    """The interface's main thread, as far as the translation can tell: it launches the translation embedded."""

    def __init__(self, cfg: HostConfig, gateway_cfg: GobyMOOSGatewayConfig) -> None:
        super().__init__(cfg)
        self.courses: list[DesiredCourse] = []
        self.reports: list[HelmStateReport] = []
        self.interthread().subscribe(groups.desired_course, DesiredCourse, self.courses.append)
        self.interthread().subscribe(groups.helm_state, HelmStateReport, self.reports.append)
        self.translation = self.launch_thread(FrontSeatTranslation, gateway_cfg, embedded=True)


def until(condition: Callable[[], bool], step: Callable[[], None], what: str) -> None:
    deadline = time.monotonic() + TIMEOUT_S
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        step()


def test_embedded_translator_uses_interthread_the_datum_it_was_given_and_datum_updates(tmp_path):
    with running_moosdb(community="usv") as db, broker_process(tmp_path, platform="usv") as broker:
        host_cfg = HostConfig()
        host_cfg.app.name = "frontseat_host"
        host_cfg.interprocess.CopyFrom(broker.interprocess_config())
        gateway_cfg = gateway_config(db.port, broker.interprocess_config())
        gateway_cfg.app.geodesy.lat_origin, gateway_cfg.app.geodesy.lon_origin = ORIGIN
        with running_app(partial(Host, gateway_cfg=gateway_cfg), host_cfg) as host:
            assert isinstance(host.translation, FrontSeatTranslation) and host.translation.embedded
            with connected_comms(db.port, "watch_embedded", register=["NAV_X", "NAV_Y"]) as watcher, \
                    PortalClient(broker.interprocess_config(), name="other_process") as client:
                courses = client.collect(groups.desired_course, DesiredCourse)
                reports = client.collect(groups.helm_state, HelmStateReport)
                assert client.wait_subscribed()

                status = NodeStatus(time=1.0)
                status.global_fix.lat, status.global_fix.lon = LAT, LON
                status.pose.heading = 0.0
                status.speed.over_ground = 0.0
                latest: dict[str, float] = {}

                def publish_from_the_host() -> None:
                    host.call_soon(lambda: host.interprocess().publish(groups.node_status, status))
                    client.poll(0.2)
                    latest.update((m.key(), m.double()) for m in watcher.fetch())

                def nav_is(x: float, y: float) -> Callable[[], bool]:
                    return lambda: (latest.get("NAV_X"), latest.get("NAV_Y")) == pytest.approx((x, y), abs=0.005)

                until(nav_is(100.0, 100.0), publish_from_the_host, "NAV_X/NAV_Y at (100, 100)")
                # Move the datum onto the vehicle: Goby apps re-project after goby::datum_update (from any process).
                update = DatumUpdate()
                update.datum.lat, update.datum.lon = LAT, LON
                client.publish(groups.datum_update, update)
                until(nav_is(0.0, 0.0), publish_from_the_host, "NAV_X/NAV_Y at (0, 0) after the datum update")

                # The helm's side: the host takes them by interthread, the other process from the broker.
                def helm_posts() -> None:
                    watcher.notify("IVPHELM_STATE", "DRIVE")
                    watcher.notify("DESIRED_SPEED", 1.5, time=500.0)
                    client.poll(0.2)

                until(lambda: bool(host.courses and host.reports and courses and reports), helm_posts,
                      "desired_course and helm_state at the host and at the other process")
                assert host.courses[-1].speed == 1.5 and host.courses[-1].time == 500.0
                assert host.reports[-1].state == HELM_DRIVE
                assert (courses[-1].speed, reports[-1].state) == (1.5, HELM_DRIVE)
