"""usv-health-monitor (the course's goby3_course_usv_health_monitor) and the topside's view of it (docs/health.md).

The mapping (OK -> health_status_good, anything else -> health_status_failed, the course's buffer options, the
timestamp in µs, the DCCL bytes) as functions; then real processes: two goby-brokers on a loopback satellite link
(topside modem 1, USV modem 2, the course's 5 s slots, warp 10), goby-coroner + an application + usv-health-monitor
on the USV, topside-manager on the topside; killing the application turns what the topside receives to FAILED.
"""

from __future__ import annotations

import asyncio
import contextlib
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from gateway.goby.dccl import Codec
from gateway.goby.intervehicle.testing import LoopbackLink, link_brokers
from gateway.goby.portal.protobuf.coroner_pb2 import (
    HEALTH__DEGRADED,
    HEALTH__FAILED,
    HEALTH__OK,
    HealthState,
    VehicleHealth,
)
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process
from gateway.goby.portal.timeutil import SystemClock
from tests.markers import needs_loopback_multicast
from translators.trail import groups
from translators.trail.health_status import health_group, health_publisher, health_status, set_health_group
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from util.process import ChildProcess

WARP = 10
TOPSIDE_SAT, USV_SAT = 1, 2
SAT_SLOTS = [(TOPSIDE_SAT, 5, 64), (USV_SAT, 5, 64)]  # the course's satellite slots: one cycle is 10 s (1 s real)
NOW_US = 1_700_000_000_123_456


# ----------------------------------------------------------------------------------------------- the mapping
@pytest.mark.parametrize(("state", "group", "expected"), [
    (HEALTH__OK, groups.health_status_good, HealthStatus.GOOD),
    (HEALTH__DEGRADED, groups.health_status_failed, HealthStatus.FAILED),
    (HEALTH__FAILED, groups.health_status_failed, HealthStatus.FAILED),
])
def test_report_state_chooses_group_and_state(state: HealthState.ValueType, group: object, expected: int) -> None:
    chosen, status = health_status(VehicleHealth(time=1, platform="usv", state=state), NOW_US)
    assert chosen == group
    assert status.state == expected
    assert status.timestamp == NOW_US  # microseconds, as given
    assert health_group(status) == group  # the topside's group function reads back the same group


def test_publication_options_are_the_courses() -> None:
    good = health_publisher(groups.health_status_good).transporter_config().intervehicle.buffer
    failed = health_publisher(groups.health_status_failed).transporter_config().intervehicle.buffer
    assert (good.max_queue, good.value_base) == (1, 50)
    assert (failed.max_queue, failed.value_base) == (1, 500)
    assert not good.HasField("ack_required") and not failed.HasField("ack_required")  # Goby's default


def test_group_functions_round_trip_every_state() -> None:
    for state in (HealthStatus.DEGRADED, HealthStatus.FAILING, HealthStatus.FAILED):
        assert health_group(HealthStatus(state=state, timestamp=NOW_US)) == groups.health_status_failed
    status = HealthStatus(state=HealthStatus.FAILED, timestamp=NOW_US)
    set_health_group(status, groups.health_status_good)
    assert status.state == HealthStatus.GOOD


def test_health_status_dccl_bytes() -> None:
    """Id 125 in 4 bytes: the bytes of the C++ DCCL (tests/dccl/dccl_vectors.json: GOOD at 1700000000 s is
    fa00e204), FAILED in the state's 2 bits; time2 keeps the second of the day, decoded against now."""
    codec = Codec()
    assert codec.load(HealthStatus).dccl_id == 125
    assert codec.encode(HealthStatus(state=HealthStatus.GOOD, timestamp=1_700_000_000_000_000)).hex() == "fa00e204"
    _, status = health_status(VehicleHealth(state=HEALTH__FAILED), NOW_US)
    data = codec.encode(status)
    assert data.hex() == "fa03e204"
    decoded = codec.decode(data, HealthStatus, now=NOW_US / 1e6)
    assert decoded.state == HealthStatus.FAILED
    assert decoded.timestamp == NOW_US // 1_000_000 * 1_000_000


# ------------------------------------------------------------------------------------------- real processes
def start(workdir: Path, broker: BrokerProcess, name: str, args: list[str], config: str = "",
          app: str = "") -> ChildProcess:
    """A Goby-style application on ``broker``: warped ``app {}`` (plus ``app``), its interprocess, ``config``."""
    path = workdir / f"{name}.pb.cfg"
    path.write_text(f"app {{ {app} simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }} }}\n"
                    f"interprocess {{ {broker.interprocess_text()} manager_timeout_seconds: 60 }}\n" + config)
    return app_process([sys.executable, "-m", *args, str(path), "-v"], workdir / f"{name}.log", env=broker.env())


@contextlib.contextmanager
def stopped(children: list[ChildProcess]) -> Iterator[list[ChildProcess]]:
    try:
        yield children
    finally:
        for child in reversed(children):
            child.stop()


def logs(children: list[ChildProcess]) -> str:
    return "\n".join(f"--- {child.name} ---\n{child.stderr_text()[-2000:]}" for child in children)


@needs_loopback_multicast
def test_killed_application_reaches_topside_as_failed(tmp_path: Path) -> None:
    sat = LoopbackLink(SAT_SLOTS)
    links = {"topside": [sat.block(TOPSIDE_SAT)], "usv": [sat.block(USV_SAT)]}
    with link_brokers(tmp_path, links, "health", warp=WARP, startup_timeout=90.0) as brokers, \
            PortalClient(brokers["topside"].interprocess_config(), name="topside_gui") as topside, \
            PortalClient(brokers["usv"].interprocess_config(), name="usv_watch") as usv, \
            stopped([]) as children:
        at_topside_good = topside.collect(groups.health_status_good, HealthStatus)
        at_topside_failed = topside.collect(groups.health_status_failed, HealthStatus)
        on_usv_failed = usv.collect(groups.health_status_failed, HealthStatus)
        assert topside.wait_subscribed() and usv.wait_subscribed()
        children.append(start(tmp_path, brokers["topside"], "topside_manager",
                              ["translators.apps.topside_manager"], f"usv_modem_id: {USV_SAT}\n",
                              app="geodesy { lat_origin: 21.59 lon_origin: -159.53 }"))
        victim = start(tmp_path, brokers["usv"], "victim", ["tests.health.apps.health_app", "--role=single"],
                       app='name: "victim"')
        children.append(victim)
        children.append(start(tmp_path, brokers["usv"], "monitor", ["translators.apps.usv_health_monitor"]))
        children.append(start(tmp_path, brokers["usv"], "coroner", ["gateway.apps.goby_coroner"],
                              'expected_name: "victim"\nrequest_interval: 10\nresponse_timeout: 5\n'))

        # GOOD reaches the topside (the first reports may say died while the victim's answer is on its way)
        assert topside.poll_until(lambda: bool(at_topside_good), 120), logs(children)
        good = at_topside_good[-1]
        assert good.state == HealthStatus.GOOD
        # µs of the applications' warped clock, not seconds or real time. time2 carries the second of the day only,
        # and DCCL decodes the day against the real clock (gateway/goby/dccl/codec.py), so compare within the day.
        sim_now_s = SystemClock(use_sim_time=True, warp_factor=WARP).now_micro() // 1_000_000
        assert good.timestamp % 1_000_000 == 0
        assert 0 <= (sim_now_s - good.timestamp // 1_000_000) % 86400 < 60 * WARP

        at_topside_failed.clear()
        killed_at = time.monotonic()
        victim.kill()
        # within two request intervals (2 s real) plus a satellite cycle (1 s real), with room for a busy machine
        assert topside.poll_until(lambda: bool(at_topside_failed), 60), logs(children)
        latency = time.monotonic() - killed_at
        assert at_topside_failed[-1].state == HealthStatus.FAILED
        assert usv.poll_until(lambda: bool(on_usv_failed), 10)  # the monitor's own inner publication on the USV
        assert on_usv_failed[-1].state == HealthStatus.FAILED
        print(f"kill -> FAILED at the topside: {latency:.1f} s real ({latency * WARP:.0f} s sim)")
        topside_log = children[0].stderr_text()
        assert "Received HealthStatus: state: GOOD" in topside_log
        assert "Received HealthStatus: state: FAILED" in topside_log
        for child in children:
            if child is not victim:
                assert child.running, logs(children)


# ----------------------------------------------------------------------------------------- the topside's page
LIAISON_CONFIG = 'http_address: "127.0.0.1"\nhttp_port: {port}\nupdate_freq: 20\n'


def test_liaison_map_shows_the_last_health_with_its_age(tmp_path: Path) -> None:
    """goby-liaison on a real broker: a HealthStatus as topside-manager publishes it (PROTOBUF, the group it came
    on) becomes the map's health row, state and age, over the page's WebSocket; the newest one replaces it."""
    aiohttp = pytest.importorskip("aiohttp")
    from google.protobuf import text_format

    from gateway.goby.portal.testing import broker_process, running_app
    from launch.liaison.portal_side import LiaisonApp
    from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
    from util.process import free_port

    with broker_process(tmp_path, platform="topside") as broker:
        cfg = text_format.Parse(LIAISON_CONFIG.format(port=free_port()), LiaisonConfig())
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with running_app(LiaisonApp, cfg) as app, PortalClient(broker.interprocess_config()) as client:
            assert client.wait_subscribed()

            async def receive_health(ws: Any, state: str) -> list[dict[str, Any]]:
                deadline = time.monotonic() + 20
                while True:
                    msg = await asyncio.wait_for(ws.receive_json(), max(0.01, deadline - time.monotonic()))
                    rows = msg.get("health") if msg.get("op") == "map" else None
                    if rows and rows[0]["state"] == state:
                        return list(rows)

            async def scenario() -> None:
                url = f"http://127.0.0.1:{app.web.port}/ws"
                async with aiohttp.ClientSession() as session, session.ws_connect(url) as ws:
                    await ws.send_json({"op": "subscribe", "views": ["map"]})
                    client.publish(groups.health_status_good, HealthStatus(state=HealthStatus.GOOD, timestamp=NOW_US))
                    client.poll(0.01)
                    rows = await receive_health(ws, "GOOD")
                    assert rows == [{"vehicle": "USV", "state": "GOOD", "time_of_day": NOW_US // 10**6 % 86400,
                                     "age": rows[0]["age"]}]
                    assert 0 <= rows[0]["age"] < 60
                    client.publish(groups.health_status_failed,
                                   HealthStatus(state=HealthStatus.FAILED, timestamp=NOW_US + 10**7))
                    client.poll(0.01)
                    rows = await receive_health(ws, "FAILED")
                    assert [(r["vehicle"], r["time_of_day"]) for r in rows] == [("USV", NOW_US // 10**6 % 86400 + 10)]

            asyncio.run(scenario())
