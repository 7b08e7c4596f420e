"""usv-manager: USV commands from shore onto the vehicle's interprocess; the USV's and the AUVs' nav out.

As the Goby3 course's goby3_course_usv_manager, it subscribes to ``usv_command`` on intervehicle (the satellite
link of the vehicle's goby-broker, from the topside's modem 1, with ack) and republishes each command on interprocess,
where CommandTranslation picks it up. It also takes commands from a shore sharing the vehicle's broker (the group
``goby3_course::shore::usv_command``, used by goby-liaison's commander and ``usv-command`` without intervehicle).
Commands outside their DCCL bounds are refused here, with an acknowledgement that says why, so they never reach
the vehicle's interprocess. Navigation as the course's manager: its own ``node_status`` goes out as ``usv_nav``
(satellite to topside, acoustic broadcast to the AUVs), and each AUV's ``auv_nav`` is forwarded topside.
"""

from __future__ import annotations

import logging

from google.protobuf import text_format

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.portal import SingleThreadApplication, run_application
from translators.trail import groups as trail_groups
from translators.trail.nav_convert import to_navigation_report
from translators.trail.nav_links import link_cfg, nav_publisher, nav_subscriber, required_geodesy
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv import groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from translators.usv.protobuf.usv_config_pb2 import USVManager as USVManagerConfig
from translators.usv.satellite import TOPSIDE_MODEM_ID, usv_subscriber
from translators.usv.validation import DcclBoundsError, check_dccl_bounds

log = logging.getLogger(__name__)


class USVManager(SingleThreadApplication):
    """Forwards shore commands to the vehicle's interprocess, acknowledging (or refusing) each one."""

    def __init__(self, cfg: USVManagerConfig) -> None:
        super().__init__(cfg)
        self._subscribe_nav(cfg)  # the course's subscribe_our_nav and subscribe_auv_nav
        self.interprocess().subscribe(groups.shore_usv_command, USVCommand, self._on_shore_command)
        self.intervehicle().subscribe(groups.usv_command, USVCommand, self._on_shore_command, usv_subscriber())
        log.info("waiting for USV commands on %s and on intervehicle %s (from satellite modem %d)",
                 groups.shore_usv_command, groups.usv_command, TOPSIDE_MODEM_ID)

    def _on_shore_command(self, command: USVCommand) -> None:
        """Check, republish and acknowledge one command. Runs on the application's main thread."""
        text = text_format.MessageToString(command, as_one_line=True)
        log.info("Received USVCommand: %s", text)
        ack = USVCommandAck(responder=self.app_name(), command=text)
        if command.HasField("time"):
            ack.command_time = command.time
        try:
            checked = check_dccl_bounds(command, codec=self.context.dccl)
        except DcclBoundsError as error:
            log.error("refusing USVCommand %s: %s", text, error)
            ack.stage = USVCommandAck.REFUSED
            ack.error = str(error)
            self.interprocess().publish(groups.usv_command_ack, ack)
            return
        # Ack first: from one publisher the broker keeps order, so the sender hears from us before the translator.
        ack.stage = USVCommandAck.RECEIVED_BY_MANAGER
        self.interprocess().publish(groups.usv_command_ack, ack)
        self.interprocess().publish(groups.usv_command, checked)

    def _subscribe_nav(self, cfg: USVManagerConfig) -> None:
        """Own nav out as ``usv_nav``; each ``auv_modem_id``'s ``auv_nav`` (no ack, newest only) forwarded topside.
        Without ``app.geodesy`` (the course's manager requires it) only commands are carried, with a warning."""
        if not cfg.app.HasField("geodesy"):
            log.warning("no app.geodesy: navigation is not forwarded (usv_nav, auv_nav)")
            return
        self._vehicle_id = cfg.vehicle_id
        self._geodesy = required_geodesy(cfg, "usv-manager")
        self.interprocess().subscribe(frontseat_groups.node_status, NodeStatus, self._on_our_nav)
        for modem_id in cfg.auv_modem_id:  # one Subscription per AUV; as in Goby the handler is the same one
            auv_cfg = link_cfg(modem_id, ack_required=False, max_queue=1, newest_first=True)
            self.intervehicle().subscribe(trail_groups.auv_nav, NavigationReport, self._on_auv_nav,
                                          subscriber=nav_subscriber(auv_cfg, republish=False))

    def _on_our_nav(self, status: NodeStatus) -> None:
        """Send our own nav as ``usv_nav``. Runs on the application's main thread."""
        nav = to_navigation_report(status, self._vehicle_id, self._geodesy, self.context.clock)
        self.intervehicle().publish(trail_groups.usv_nav, nav, publisher=nav_publisher())

    def _on_auv_nav(self, nav: NavigationReport) -> None:
        """Forward an AUV's nav topside. Runs on the application's main thread."""
        log.debug("Received DCCL nav: %s", text_format.MessageToString(nav, as_one_line=True))
        self.intervehicle().publish(trail_groups.auv_nav, nav, publisher=nav_publisher())


def main(argv: list[str] | None = None) -> int:
    """Console script ``usv-manager``: Goby-style config file / ``--interprocess`` / ``GOBY_INTERPROCESS``."""
    return run_application(USVManager, USVManagerConfig, argv, prog="usv-manager")


if __name__ == "__main__":
    raise SystemExit(main())
