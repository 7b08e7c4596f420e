"""usv-command with ``intervehicle: true``: from the topside's broker over the satellite link (two goby-broker
processes, UDP multicast on loopback) to usv-manager on the USV's broker, which acks; the command reaches the USV's
interprocess, and usv-command reports the link's ack with the slot wait."""

from __future__ import annotations

import sys

from translator_procs import run_cli, start_child, wait_showing_logs

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_pb2 import INTERFACE_COMMAND, InterfaceStatus
from gateway.goby.intervehicle.testing import LoopbackLink, link_brokers
from gateway.goby.portal.testing import PortalClient
from tests.markers import needs_loopback_multicast
from translators.apps.usv_command import EXIT_ACKNOWLEDGED
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

pytestmark = needs_loopback_multicast

WARP = 20
SAT = [(1, 5, 64), (2, 5, 64)]
SIM = f"app {{ simulation {{ time {{ use_sim_time: true warp_factor: {WARP} reference_microtime: 0 }} }} }}\n"


def test_usv_command_over_the_satellite_link(tmp_path):
    sat = LoopbackLink(SAT)
    manager = None
    with link_brokers(tmp_path, {"topside": [sat.block(1)], "usv": [sat.block(2)]}, "cmd", header=SIM) as brokers:
        try:
            manager_cfg = tmp_path / "manager.pb.cfg"
            manager_cfg.write_text(SIM)
            manager = start_child("usv_manager", [sys.executable, "-m", "translators.apps.usv_manager",
                                                 str(manager_cfg), "-v"], tmp_path, brokers["usv"].env())
            with PortalClient(brokers["usv"].interprocess_config(), name="usv_probe") as usv:
                commands = usv.collect(usv_groups.usv_command, USVCommand)
                acks = usv.collect(usv_groups.usv_command_ack, USVCommandAck)
                assert usv.wait_subscribed()
                wait_showing_logs(lambda: "waiting for USV commands" in manager.output(), 30, "usv-manager to start", manager)
                # the manager's subscription crosses the link in the USV's slot; before it arrives the topside has
                # no subscriber and a command expires at once (EXPIRED_NO_SUBSCRIBERS), as in Goby
                topside_log = brokers["topside"].log_path
                wait_showing_logs(lambda: "modem 2 subscribed to DCCL id" in topside_log.read_text(), 30,
                                  "the manager's subscription at the topside", manager)
                tool_cfg = tmp_path / "tool.pb.cfg"
                tool_cfg.write_text(SIM + "intervehicle: true\n")
                result = run_cli(["polygon", "--sides", "5", "--radius", "250", "--timeout", "20", str(tool_cfg)],
                                 brokers["topside"].env(), tmp_path)
                assert result.returncode == EXIT_ACKNOWLEDGED, result.stdout + result.stderr + manager.output()
                assert "acked over the satellite link by satellite modem 2: slot wait" in result.stdout
                usv.poll_until(lambda: bool(commands), 10)
        finally:
            if manager is not None:
                manager.stop()
    assert [(c.polygon_sides, c.polygon_radius) for c in commands] == [(5, 250)]  # checked, then republished once
    assert [a.stage for a in acks] == [USVCommandAck.RECEIVED_BY_MANAGER]


def test_shore_sends_again_a_command_the_link_expired_before_the_usv_subscribed(tmp_path):
    """The mission's scripted shore: at a high warp the USV reaches COMMAND before usv-manager's subscription has
    crossed the link, so the first command is expired at once (EXPIRED_NO_SUBSCRIBERS, as Goby does); the shore
    sends it again until the subscription has arrived, then the USV acks it."""
    warp = 10  # the resend window is 120 sim s: 12 s here, room for usv-manager to start on a loaded machine
    sim = SIM.replace(f"warp_factor: {WARP}", f"warp_factor: {warp}")
    sat = LoopbackLink(SAT)
    children = []
    with link_brokers(tmp_path, {"topside": [sat.block(1)], "usv": [sat.block(2)]}, "shore", header=sim) as brokers:
        try:
            shore_cfg = tmp_path / "shore.pb.cfg"
            shore_cfg.write_text(sim + "intervehicle: true\n")
            shore = start_child("shore", [
                sys.executable, "-m", "launch.usv.shore", str(shore_cfg), "--schedule", "0:polygon:5:250",
                "--vehicle-interprocess", brokers["usv"].interprocess_text()], tmp_path, brokers["topside"].env())
            children.append(shore)
            with PortalClient(brokers["usv"].interprocess_config(), name="usv_probe") as usv:
                commands = usv.collect(usv_groups.usv_command, USVCommand)
                assert usv.wait_subscribed()

                def vehicle_under_command() -> bool:
                    usv.publish(frontseat_groups.status, InterfaceStatus(state=INTERFACE_COMMAND))
                    usv.poll(0.05)
                    return "plan clock started" in shore.output()

                wait_showing_logs(vehicle_under_command, 30, "the shore to see COMMAND", shore)
                wait_showing_logs(lambda: "no subscriber on the satellite link yet" in shore.output(), 30,
                                  "the first command expired for want of a subscriber", shore)
                manager_cfg = tmp_path / "manager.pb.cfg"
                manager_cfg.write_text(sim)
                children.append(start_child("usv_manager", [sys.executable, "-m", "translators.apps.usv_manager",
                                                           str(manager_cfg), "-v"], tmp_path, brokers["usv"].env()))
                wait_showing_logs(lambda: "acked over the satellite link by satellite modem 2" in shore.output(), 30,
                                  "the command sent again and acked", *children)
                usv.poll_until(lambda: bool(commands), 10)
        finally:
            for child in children:
                child.stop()
    text = shore.output()
    assert "NOT delivered" not in text and "ERROR" not in text, text
    assert text.count("sent polygon --sides 5 --radius 250") >= 2, text
    assert [(c.polygon_sides, c.polygon_radius) for c in commands] == [(5, 250)]
