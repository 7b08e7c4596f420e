"""The course's gateway plugin (``libgoby3_course_moos_gateway_plugin.so``) in ``moos-gateway``, with moos-db and
goby-broker as real processes: usv_nav -> NODE_REPORT (rewarped TIME), auv_command -> DEPLOY_DEPTH_UPDATES then
AUV_DEPLOY_STATE, usv_command -> DEPLOY_STATE (the plugin also hosts CommandTranslation, as the course's)."""

from __future__ import annotations

import time
from collections.abc import Callable

import pytest

from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.message import MoosMessage
from gateway.moos.testing import connected_comms, moosdb_process
from translators.testing import GatewayProcess
from translators.trail import groups
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand, USVCommand

REFERENCE_S = 1_700_000_000
WARP = 5
TIMEOUT_S = 60.0
WATCHED = ["NODE_REPORT", "DEPLOY_DEPTH_UPDATES", "AUV_DEPLOY_STATE", "DEPLOY_STATE"]


def gateway_config(interprocess_text: str, moos_port: int) -> str:
    return (f"app {{ simulation {{ time {{ use_sim_time: true warp_factor: {WARP} "
            f"reference_microtime: {REFERENCE_S * 1_000_000} }} }} }}\n"
            f"interprocess {{ {interprocess_text} manager_timeout_seconds: 60 }}\n"
            f'moos {{ server: "127.0.0.1" port: {moos_port} }}\n')


def nav(x: float, real_time: float) -> NavigationReport:
    return NavigationReport(vehicle=1, time=real_time, x=x, y=-20.5, z=-2, speed_over_ground=1.5, heading=90,
                            type=NavigationReport.USV)


@pytest.fixture
def plugin_stack(tmp_path):
    with moosdb_process(tmp_path, community="auv0") as db, broker_process(tmp_path, platform="auv0") as broker, \
            GatewayProcess(tmp_path, ["libgoby3_course_moos_gateway_plugin.so"],
                           gateway_config(broker.interprocess_text(), db.port), extra_args=["-v"]) as gateway, \
            PortalClient(broker.interprocess_config(), name="shore_side") as client, \
            connected_comms(db.port, "watcher", register=WATCHED) as watcher:
        yield gateway, client, watcher


def mail_until(watcher, got: list[MoosMessage], done: Callable[[], bool], gateway: GatewayProcess,  # noqa: ANN001
               what: str) -> None:
    deadline = time.monotonic() + TIMEOUT_S
    while not done():
        assert time.monotonic() < deadline, f"no {what}; got {[(m.key(), m.string()) for m in got]}\n" \
                                            f"{gateway.stderr()[-3000:]}"
        got.extend(watcher.fetch())
        time.sleep(0.02)


def test_course_plugin_posts_contacts_and_commands(plugin_stack):
    gateway, client, watcher = plugin_stack
    got: list[MoosMessage] = []

    def reports() -> list[str]:
        return [m.string() for m in got if m.key() == "NODE_REPORT"]

    # The gateway subscribes once its threads run: publish until the first report shows up.
    x = 0.0
    deadline = time.monotonic() + TIMEOUT_S
    while not reports():
        assert time.monotonic() < deadline, f"no NODE_REPORT\n{gateway.stderr()[-3000:]}"
        x += 1.0
        client.publish(groups.usv_nav, nav(x, REFERENCE_S + 10.0))
        client.poll(0.3)
        got.extend(watcher.fetch())
    assert reports()[0].startswith("NAME=USV,TYPE=USV,TIME=1700000050,X=")
    # the reports of the other fixes published meanwhile may still be on their way (the C++ MOOSDB batches mail)
    mail_until(watcher, got, lambda: any(f",X={x:g}," in r for r in reports()), gateway, "the last first-round report")

    # A DCCL-scheme copy (what Goby's intervehicle publish also puts on interprocess) is not posted: the plugin
    # subscribes PROTOBUF only, as the course's. Same publisher, so the broker keeps the order.
    got.clear()
    client.publish(groups.usv_nav, nav(-7777.7, REFERENCE_S + 10.0), scheme=Scheme.DCCL)
    client.publish(groups.usv_nav, nav(-123.4, REFERENCE_S + 12.5))
    mail_until(watcher, got, lambda: any("X=-123.4" in r for r in reports()), gateway, "second NODE_REPORT")
    assert reports() == ["NAME=USV,TYPE=USV,TIME=1700000062.5,X=-123.4,Y=-20.5,DEPTH=2,HDG=90,SPD=1.5"]

    # A report pHelmIvP could not read (NaN heading) is refused with one line; the next one still goes through.
    got.clear()
    bad = nav(55.5, REFERENCE_S + 13.0)
    bad.heading = float("nan")
    client.publish(groups.usv_nav, bad)
    client.publish(groups.usv_nav, nav(66.6, REFERENCE_S + 14.0))
    mail_until(watcher, got, lambda: any("X=66.6" in r for r in reports()), gateway, "NODE_REPORT after a bad one")
    assert [r for r in reports() if "X=55.5" in r] == []
    assert "not posting NODE_REPORT" in gateway.stderr() and "Traceback" not in gateway.stderr()

    got.clear()
    client.publish(groups.auv_command, AUVCommand(time=REFERENCE_S, desired_state=AUVCommand.RECOVER))
    mail_until(watcher, got, lambda: any(m.key() == "AUV_DEPLOY_STATE" for m in got), gateway, "AUV_DEPLOY_STATE")
    assert [(m.key(), m.string()) for m in got] == [("DEPLOY_DEPTH_UPDATES", "depth=0"),
                                                   ("AUV_DEPLOY_STATE", "RECOVER")]

    got.clear()
    client.publish(groups.usv_command, USVCommand(time=REFERENCE_S, desired_state=USVCommand.WAYPOINTS))
    mail_until(watcher, got, lambda: any(m.key() == "DEPLOY_STATE" for m in got), gateway, "DEPLOY_STATE")
    assert [(m.key(), m.string()) for m in got] == [("DEPLOY_STATE", "WAYPOINTS")]
    assert gateway.proc.running
