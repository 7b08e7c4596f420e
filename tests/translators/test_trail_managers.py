"""The course's managers and homework 3's RECOVER chain on real links: three goby-broker processes (topside on the
satellite link, the USV on both links, an AUV on the acoustic link; UDP multicast on loopback, the course's slot
plans, warp 10), with usv-manager, auv-manager, topside-manager, goby-helm-example, moos-db and moos-gateway (the
course's plugin) as processes. Test clients only play the frontseats (node_status) and watch."""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from translator_procs import ORIGIN, running

from frontseat import groups as frontseat_groups
from frontseat.protobuf import frontseat_data_pb2 as fs
from frontseat.protobuf.frontseat_data_pb2 import DesiredCourse, NodeStatus
from gateway.goby.intervehicle.testing import LoopbackLink, link_brokers
from gateway.goby.portal.testing import BrokerProcess, PortalClient
from gateway.goby.portal.timeutil import SystemClock
from gateway.moos.message import MoosMessage
from gateway.moos.testing import connected_comms, moosdb_process
from tests.markers import needs_loopback_multicast
from translators.testing import GatewayProcess
from translators.trail import groups
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand
from util.geodesy import UTMGeodesy
from util.process import ChildProcess

pytestmark = needs_loopback_multicast

WARP = 10
TOPSIDE_SAT, USV_SAT, USV_ACOMMS, AUV_ACOMMS = 1, 2, 258, 259  # the course's modem ids (AUV 0 has vehicle id 2)
SAT_SLOTS = [(TOPSIDE_SAT, 5, 64), (USV_SAT, 5, 64)]
ACOMMS_SLOTS = [(USV_ACOMMS, 10, 128), (AUV_ACOMMS, 10, 128)]
TIMEOUT_S = 60.0
MOOS_VARS = ["NODE_REPORT", "DEPLOY_DEPTH_UPDATES", "AUV_DEPLOY_STATE"]


def app_block() -> str:
    return (f"app {{ geodesy {{ lat_origin: {ORIGIN[0]} lon_origin: {ORIGIN[1]} }} "
            f"simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }} }}\n")


def interprocess_block(broker: BrokerProcess) -> str:
    # A loaded machine may take longer than Goby's default 5 s to answer a new client (ten processes start at once).
    return f"interprocess {{ {broker.interprocess_text()} manager_timeout_seconds: 60 }}\n"


@dataclass
class Fleet:
    workdir: Path
    brokers: dict[str, BrokerProcess]
    moos_port: int
    children: list[ChildProcess | GatewayProcess] = field(default_factory=list)

    def logs(self) -> str:
        parts = []
        for child in self.children:
            text = child.output() if isinstance(child, ChildProcess) else child.stderr()
            parts.append(f"--- {getattr(child, 'name', 'moos-gateway')} ---\n{text[-2500:]}")
        return "\n".join(parts)

    def process(self, name: str, module: str, broker: str, config: str) -> contextlib.AbstractContextManager:
        """A Goby-style app on ``broker``'s interprocess with ``config`` (after the common ``app {}`` block)."""
        path = self.workdir / f"{name}.pb.cfg"
        path.write_text(app_block() + interprocess_block(self.brokers[broker]) + config)
        return running(name, [sys.executable, "-m", module, str(path), "-v"], self.workdir, self.brokers[broker].env())

    def app(self, name: str, module: str, broker: str, config: str) -> None:
        """The same, for the whole module."""
        self.children.append(self._exits.enter_context(self.process(name, module, broker, config)))

    _exits: contextlib.ExitStack = field(default_factory=contextlib.ExitStack)


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Fleet]:
    workdir = tmp_path_factory.mktemp("trail_fleet")
    sat, acomms = LoopbackLink(SAT_SLOTS), LoopbackLink(ACOMMS_SLOTS)
    links = {"topside": [sat.block(TOPSIDE_SAT)], "usv": [sat.block(USV_SAT), acomms.block(USV_ACOMMS)],
             "auv0": [acomms.block(AUV_ACOMMS)]}
    with contextlib.ExitStack() as exits:
        brokers = exits.enter_context(link_brokers(workdir, links, "trail", warp=WARP, startup_timeout=90.0))
        db = exits.enter_context(moosdb_process(workdir, community="AUV0", warp=WARP))
        built = Fleet(workdir, brokers, db.port, _exits=exits)
        built.app("topside_manager", "translators.apps.topside_manager", "topside",
                  f'usv_modem_id: {USV_SAT}\nvehicle_name_prefix: "trail_"\n')
        built.app("usv_manager", "translators.apps.usv_manager", "usv", f"vehicle_id: 1\nauv_modem_id: {AUV_ACOMMS}\n")
        built.app("auv_manager", "translators.apps.auv_manager", "auv0", f"usv_modem_id: {USV_ACOMMS}\nvehicle_id: 2\n")
        gateway_cfg = (app_block() + interprocess_block(brokers["auv0"]) +
                       f'moos {{ server: "127.0.0.1" port: {db.port} }}\n')
        built.children.append(exits.enter_context(
            GatewayProcess(workdir, ["libgoby3_course_moos_gateway_plugin.so"], gateway_cfg, extra_args=["-v"])))
        yield built
        for child in built.children:
            alive = child.running if isinstance(child, ChildProcess) else child.proc.running
            assert alive, f"a process died during the tests\n{built.logs()}"


def node_status(geodesy: UTMGeodesy, x: float, y: float, depth: float, vehicle_type: int) -> NodeStatus:
    status = NodeStatus(time=SystemClock(use_sim_time=True, warp_factor=WARP).now(), type=vehicle_type)
    status.global_fix.lat, status.global_fix.lon = geodesy.to_geo(x, y)
    status.global_fix.depth = depth
    status.local_fix.x, status.local_fix.y = x, y
    status.pose.heading = 45.0
    status.speed.over_ground = 1.5
    return status


def test_every_vehicle_reaches_topside_and_the_usv_reaches_the_auv_helm(fleet: Fleet) -> None:
    geodesy = UTMGeodesy(*ORIGIN)
    with PortalClient(fleet.brokers["topside"].interprocess_config(), name="topside_gui") as gui, \
            PortalClient(fleet.brokers["usv"].interprocess_config(), name="usv_frontseat") as usv, \
            PortalClient(fleet.brokers["auv0"].interprocess_config(), name="auv_frontseat") as auv, \
            connected_comms(fleet.moos_port, "auv_helm", register=MOOS_VARS) as helm:
        seen = gui.collect(frontseat_groups.node_status, NodeStatus)
        assert gui.wait_subscribed()
        reports: list[MoosMessage] = []

        def arrived() -> bool:
            for client in (gui, usv, auv):
                client.poll(0.02)
            reports.extend(m for m in helm.fetch() if m.key() == "NODE_REPORT")
            names = {s.name for s in seen}
            return {"trail_USV", "trail_AUV_0"} <= names and bool(reports)

        deadline = time.monotonic() + TIMEOUT_S
        last = 0.0
        sent: list[float] = []
        while not arrived():
            assert time.monotonic() < deadline, (f"names {sorted({s.name for s in seen})}, "
                                                 f"{len(reports)} NODE_REPORTs\n{fleet.logs()}")
            if time.monotonic() - last > 0.2:  # the frontseats' nav at 5 Hz real
                sent.append(node_status(geodesy, 120.3, -40.6, 0.0, fs.USV).time)
                usv.publish(frontseat_groups.node_status, node_status(geodesy, 120.3, -40.6, 0.0, fs.USV))
                auv.publish(frontseat_groups.node_status, node_status(geodesy, 80.2, -75.4, 20.0, fs.AUV))
                last = time.monotonic()
    usv_status = next(s for s in seen if s.name == "trail_USV")
    auv_status = next(s for s in seen if s.name == "trail_AUV_0")
    assert usv_status.type == fs.USV and auv_status.type == fs.AUV
    assert (usv_status.local_fix.x, usv_status.local_fix.y) == pytest.approx((120.3, -40.6), abs=0.051)
    assert (auv_status.local_fix.x, auv_status.local_fix.y) == pytest.approx((80.2, -75.4), abs=0.051)
    assert (usv_status.global_fix.depth, auv_status.global_fix.depth) == (0.0, 20.0)
    assert auv_status.pose.heading == 45.0 and auv_status.speed.over_ground == 1.5
    # Goby's NODE_REPORT on the AUV: the USV's position, its time rewarped to when it was measured (DCCL keeps
    # whole seconds of the real clock: one real second is WARP warped ones)
    report = reports[0].string()
    assert report.startswith("NAME=USV,TYPE=USV,TIME=") and ",X=120.3,Y=-40.6,DEPTH=-0,HDG=45,SPD=1.5" in report
    report_time = float(report.split("TIME=")[1].split(",")[0])
    assert min(sent) - WARP <= report_time <= max(sent) + WARP, (report_time, min(sent), max(sent))
    assert min(sent) - WARP <= usv_status.time <= max(sent) + WARP  # the topside rewarps too


def test_homework_helm_sends_recover_once_and_the_auv_helm_gets_it_in_order(fleet: Fleet) -> None:
    geodesy = UTMGeodesy(*ORIGIN)
    with contextlib.ExitStack() as stack, \
            PortalClient(fleet.brokers["usv"].interprocess_config(), name="usv_frontseat2") as usv, \
            connected_comms(fleet.moos_port, "auv_helm2", register=MOOS_VARS) as helm:
        courses = usv.collect(frontseat_groups.desired_course, DesiredCourse)
        on_usv = usv.collect(groups.auv_command, AUVCommand)
        assert usv.wait_subscribed()
        # The AUV's subscriptions (usv_nav, auv_command) go out together in its first slots: once the USV's nav
        # reaches the AUV's MOOSDB, one more acoustic cycle and the USV's link knows the command subscriber too.
        deadline = time.monotonic() + TIMEOUT_S
        while not any(m.key() == "NODE_REPORT" for m in helm.fetch()):
            assert time.monotonic() < deadline, fleet.logs()
            usv.publish(frontseat_groups.node_status, node_status(geodesy, 0.0, 0.0, 0.0, fs.USV))
            usv.poll(0.2)
        usv.poll_until(lambda: False, 20.0 / WARP)
        helm_app = stack.enter_context(fleet.process("goby_helm_example", "behaviors.apps.goby_helm_example", "usv",
                                                     "speed: 1.5\neast_duration: 2\nsouth_duration: 2\n"))
        # The frontseat: the start (0, 0) until the helm drives, then a point it never closes on.
        position = (0.0, 0.0)
        started = time.monotonic()
        mail: list[MoosMessage] = []
        deadline = time.monotonic() + TIMEOUT_S
        while not any(m.key() == "AUV_DEPLOY_STATE" for m in mail):
            assert time.monotonic() < deadline, (f"{[(m.key(), m.string()) for m in mail]}\n{fleet.logs()}\n"
                                                 f"{helm_app.output()[-2000:]}")
            if courses and position == (0.0, 0.0) and time.monotonic() > started + 0.5:
                position = (50.0, -50.0)
            elif not courses:
                started = time.monotonic()
            usv.publish(frontseat_groups.node_status, node_status(geodesy, *position, 0.0, fs.USV))
            usv.poll(0.1)
            mail.extend(m for m in helm.fetch() if m.key() != "NODE_REPORT")
        usv.poll_until(lambda: False, 3.0)  # a few more acoustic slots: nothing is sent twice
        mail.extend(m for m in helm.fetch() if m.key() != "NODE_REPORT")
        helm_log = helm_app.output()
    assert helm_log.count("sending AUVCommand RECOVER") == 1, helm_log[-2000:]
    assert [(m.key(), m.string()) for m in mail] == [("DEPLOY_DEPTH_UPDATES", "depth=0"),
                                                    ("AUV_DEPLOY_STATE", "RECOVER")], fleet.logs()
    assert [c.desired_state for c in on_usv] == [AUVCommand.RECOVER]  # published once (Goby also shows it here)
    assert courses[-1].speed == 0.0 and courses[0].heading == 90.0
