"""FrontSeatTranslation, NodeReportTranslation and CoronerTranslation in moos-gateway, with a real MOOSDB and broker.

node_status on interprocess -> NAV_* (and NODE_REPORT) in MOOS; DESIRED_* and IVPHELM_STATE posted in MOOS ->
desired_course and helm_state on interprocess; the coroner's VehicleHealth -> GOBY_PROCESS_HEALTH in MOOS.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import pytest
from google.protobuf import text_format

from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import USV, DesiredCourse, NodeStatus
from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, HELM_NOT_RUNNING, HELM_PARK, HelmStateReport
from gateway.goby.portal.health import HEALTH_REPORT
from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__FAILED, VehicleHealth
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.testing import connected_comms, running_moosdb
from translators.frontseat.translation import FrontSeatTranslation
from translators.testing import gateway_config, hosted_translators

NAV_VARS = ["NAV_X", "NAV_Y", "NAV_LAT", "NAV_LONG", "NAV_DEPTH", "NAV_HEADING", "NAV_YAW", "NAV_SPEED",
            "NAV_PITCH", "NAV_ROLL", "GPS_UPDATE_RECEIVED", "NODE_REPORT"]
TIMEOUT_S = 30.0
# ivp_helm.md §7.3, origin 43.8253, -70.3304: (60, -40) <-> (43.82494863, -70.32964602)
REF_LAT, REF_LON, REF_X, REF_Y = 43.82494863, -70.32964602, 60.0, -40.0


def node_status(stamp: float) -> NodeStatus:
    status = NodeStatus(time=stamp, name="usv", type=USV)
    status.global_fix.lat = REF_LAT
    status.global_fix.lon = REF_LON
    status.global_fix.depth = 0.5
    status.pose.heading = 120.0
    status.pose.pitch = 2.0
    status.pose.roll = -3.0
    status.speed.over_ground = 1.25
    status.local_fix.x = 9999.0  # a wrong local fix: NAV_X/NAV_Y must come from lat/lon on the datum's grid
    status.local_fix.y = 9999.0
    return status


def post_until(client: PortalClient, arrived: Callable[[], bool], post: Callable[[], None], what: str,
               logs: Callable[[], str] = str) -> None:
    """``post()`` every half second until ``arrived()``: the gateway registers for MOOS variables some time after
    it connects, so the first posts may be lost."""
    deadline = time.monotonic() + TIMEOUT_S
    while not arrived():
        assert time.monotonic() < deadline, f"no {what} arrived\n{logs()}"
        post()
        client.poll_until(arrived, 0.5)


def test_node_status_becomes_nav_variables_and_a_node_report(stack):
    stamp = 1754431234.25
    latest: dict[str, object] = {}
    with connected_comms(stack.moos_port, "watch_nav", register=NAV_VARS) as watcher, \
            PortalClient(stack.broker.interprocess_config(), name="nav_source") as client:
        assert client.wait_subscribed()

        def arrived() -> bool:
            for msg in watcher.fetch():
                value = msg.double() if msg.is_double() else msg.string()
                if msg.key() != "GPS_UPDATE_RECEIVED" or value == f"Timestamp={stamp:.15g}":
                    latest[msg.key()] = value
            return latest.get("GPS_UPDATE_RECEIVED") == f"Timestamp={stamp:.15g}" and "NODE_REPORT" in latest \
                and str(latest["NODE_REPORT"]).count(f"TIME={stamp:.15g}") == 1

        deadline = time.monotonic() + TIMEOUT_S
        while not arrived():  # republish until the translators' subscriptions are in place
            assert time.monotonic() < deadline, f"no NAV_* arrived\n{stack.logs()}"
            client.publish(groups.node_status, node_status(stamp))
            client.poll(0.3)
    assert latest["NAV_X"] == pytest.approx(REF_X, abs=0.005)
    assert latest["NAV_Y"] == pytest.approx(REF_Y, abs=0.005)
    assert latest["NAV_LAT"] == REF_LAT and latest["NAV_LONG"] == REF_LON
    assert latest["NAV_DEPTH"] == 0.5
    assert latest["NAV_HEADING"] == 120.0
    assert latest["NAV_YAW"] == pytest.approx(-math.radians(120.0))
    assert latest["NAV_SPEED"] == 1.25
    assert latest["NAV_PITCH"] == pytest.approx(math.radians(2.0))
    assert latest["NAV_ROLL"] == pytest.approx(math.radians(-3.0))
    report = dict(item.split("=", 1) for item in str(latest["NODE_REPORT"]).split(","))
    assert list(report) == ["NAME", "TYPE", "TIME", "X", "Y", "DEPTH", "HDG", "SPD"]
    assert (report["NAME"], report["TYPE"], report["HDG"], report["SPD"], report["DEPTH"]) == (
        "usv", "USV", "120", "1.25", "0.5")
    assert float(report["X"]) == pytest.approx(REF_X, abs=0.005)
    assert float(report["Y"]) == pytest.approx(REF_Y, abs=0.005)


def test_vehicle_health_reaches_moos_as_goby_process_health(stack):
    """Goby's coroner gateway plugin (loaded by its library name): the report, in the gateway's technique."""
    health = VehicleHealth(time=1754431234250000, platform="usv", state=HEALTH__FAILED)
    process = health.process.add(name="usv-manager", pid=4242)
    process.main.name = "usv-manager"
    process.main.state = HEALTH__FAILED
    got: list[str] = []
    with connected_comms(stack.moos_port, "watch_health", register=["GOBY_PROCESS_HEALTH"]) as watcher, \
            PortalClient(stack.broker.interprocess_config(), name="coroner_double") as client:
        assert client.wait_subscribed()
        post_until(client, lambda: bool(got.extend(m.string() for m in watcher.fetch()) or got),
                   lambda: client.publish(HEALTH_REPORT, health), "GOBY_PROCESS_HEALTH", stack.logs)
    prefix = "@PB[goby.middleware.protobuf.VehicleHealth] "
    assert got[0].startswith(prefix), got[0]
    parsed = text_format.Parse(got[0][len(prefix):], VehicleHealth())
    assert parsed == health


def test_desired_setpoints_become_desired_course_with_goby_fallback(stack):
    with connected_comms(stack.moos_port, "fake_helm") as helm, \
            PortalClient(stack.broker.interprocess_config(), name="interface") as client:
        courses: list[DesiredCourse] = client.collect(groups.desired_course, DesiredCourse)
        assert client.wait_subscribed()
        # Readiness: DESIRED_SPEED alone until a course comes back (the gateway registered for it by then).
        post_until(client, lambda: any(c.time == 100.0 for c in courses),
                   lambda: helm.notify("DESIRED_SPEED", 0.5, time=100.0), "desired_course", stack.logs)

        helm.notify("DESIRED_HEADING", 270.0, time=200.0)
        helm.notify("DESIRED_DEPTH", 12.0, time=200.0)
        helm.notify("DESIRED_PITCH", 4.0, time=200.0)
        helm.notify("DESIRED_ROLL", -2.0, time=200.0)
        helm.notify("DESIRED_Z_RATE", 0.25, time=200.0)
        helm.notify("DESIRED_ALTITUDE", 7.0, time=200.0)
        helm.notify("DESIRED_SPEED", 1.5, time=201.5)
        assert client.poll_until(lambda: any(c.time == 201.5 for c in courses), TIMEOUT_S), stack.logs()
        helm.notify("DESIRED_SPEED", 1.75, time=202.5)  # nothing else posted since: only speed this time
        assert client.poll_until(lambda: any(c.time == 202.5 for c in courses), TIMEOUT_S), stack.logs()
    full = next(c for c in courses if c.time == 201.5)
    assert (full.speed, full.heading, full.depth, full.pitch, full.roll, full.z_rate, full.altitude) == (
        1.5, 270.0, 12.0, 4.0, -2.0, 0.25, 7.0)
    bare = next(c for c in courses if c.time == 202.5)
    assert bare.speed == 1.75
    for name in ("heading", "depth", "pitch", "roll", "z_rate", "altitude"):
        assert not bare.HasField(name), name
    assert bare.altitude == 10.0  # the proto default a frontseat sees


def test_ivphelm_state_becomes_helm_state(stack):
    with connected_comms(stack.moos_port, "pHelmIvP") as helm, \
            PortalClient(stack.broker.interprocess_config(), name="interface_helm") as client:
        reports: list[HelmStateReport] = client.collect(groups.helm_state, HelmStateReport)
        assert client.wait_subscribed()
        post_until(client, lambda: bool(reports), lambda: helm.notify("IVPHELM_STATE", "STANDBY"), "helm_state",
                   stack.logs)
        for value in ("DRIVE", " park ", "DRIVE+", "drive", "MALCONFIG"):
            helm.notify("IVPHELM_STATE", value)
        expected = [HELM_DRIVE, HELM_PARK, HELM_NOT_RUNNING, HELM_DRIVE, HELM_NOT_RUNNING]
        # MOOS keeps one client's order, so late readiness reports (STANDBY) can only come before ours.
        assert client.poll_until(lambda: [r.state for r in reports][-5:] == expected, TIMEOUT_S), (
            [r.state for r in reports], stack.logs())
    assert all(r.state == HELM_NOT_RUNNING for r in reports[:-5])



def test_a_string_setpoint_is_reported_and_the_translator_keeps_serving(tmp_path, caplog):
    """A fresh MOOSDB (MOOS locks a variable's type at its first write, so this cannot share the stack's)."""
    with running_moosdb(community="usv") as db, broker_process(tmp_path, platform="usv") as broker, \
            hosted_translators(gateway_config(db.port, broker.interprocess_config()), FrontSeatTranslation), \
            connected_comms(db.port, "sloppy_helm") as helm, \
            PortalClient(broker.interprocess_config(), name="interface_bad") as client:
        courses: list[DesiredCourse] = client.collect(groups.desired_course, DesiredCourse)
        assert client.wait_subscribed()

        def post_setpoints() -> None:
            helm.notify("DESIRED_HEADING", "north", time=299.0)
            helm.notify("DESIRED_DEPTH", 4.0, time=299.0)
            helm.notify("DESIRED_SPEED", 0.75, time=300.0)

        post_until(client, lambda: any(c.time == 300.0 for c in courses), post_setpoints, "desired_course")
    course = next(c for c in courses if c.time == 300.0)
    assert course.speed == 0.75 and course.depth == 4.0 and not course.HasField("heading")
    assert "DESIRED_HEADING must be a number, got the string 'north' from 'sloppy_helm'" in caplog.text
