"""auv-manager's application (goby3-course ``src/bin/manager/auv/app.cpp``, post-homework3): own ``node_status`` ->
intervehicle ``auv_nav``; intervehicle ``usv_nav`` (broadcast from the USV's acoustic modem) -> interprocess
``usv_nav`` as PROTOBUF, which IvPHelmTranslation turns into NODE_REPORT; intervehicle ``auv_command`` (acked) ->
interprocess ``auv_command``. Each publish/subscribe names its group and type here, as the course's, so the
interface file lists them."""

from __future__ import annotations

import logging

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.intervehicle import Subscriber
from gateway.goby.portal import Scheme, SingleThreadApplication
from translators.trail import groups
from translators.trail.nav_convert import to_navigation_report
from translators.trail.nav_links import link_cfg, nav_publisher, nav_subscriber, required_geodesy, short
from translators.trail.protobuf.manager_config_pb2 import AUVManager as AUVManagerConfig
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand

log = logging.getLogger(__name__)


class AUVManager(SingleThreadApplication):
    """An AUV's link manager: its nav out, the USV's nav and the AUV commands in."""

    def __init__(self, cfg: AUVManagerConfig) -> None:
        super().__init__(cfg)
        self._vehicle_id = cfg.vehicle_id
        self._geodesy = required_geodesy(cfg, "auv-manager")
        self.subscribe_our_nav()
        self.subscribe_usv_nav(cfg.usv_modem_id)
        self.subscribe_commands(cfg.usv_modem_id)

    def subscribe_our_nav(self) -> None:
        self.interprocess().subscribe(frontseat_groups.node_status, NodeStatus, self._on_our_nav)

    def _on_our_nav(self, status: NodeStatus) -> None:
        """Send our own nav as ``auv_nav``. Runs on the application's thread."""
        nav = to_navigation_report(status, self._vehicle_id, self._geodesy, self.context.clock)
        log.debug("own nav %s -> %s", short(status), short(nav))
        self.intervehicle().publish(groups.auv_nav, nav, publisher=nav_publisher())

    def subscribe_usv_nav(self, usv_modem_id: int) -> None:
        # The USV broadcasts its nav: the AUVs trailing it are within reception of the acoustic modem.
        cfg = link_cfg(usv_modem_id, broadcast=True, ack_required=False, max_queue=1, newest_first=True)
        self.intervehicle().subscribe(groups.usv_nav, NavigationReport, self._on_usv_nav,
                                      subscriber=nav_subscriber(cfg, republish=False))

    def _on_usv_nav(self, nav: NavigationReport) -> None:
        """Republish the USV's nav on interprocess as PROTOBUF. Runs on the application's thread."""
        log.debug("Received USV DCCL nav: %s", short(nav))
        self.interprocess().publish(groups.usv_nav, nav, scheme=Scheme.PROTOBUF)

    def subscribe_commands(self, usv_modem_id: int) -> None:
        cfg = link_cfg(usv_modem_id, ack_required=True, max_queue=1)
        self.intervehicle().subscribe(groups.auv_command, AUVCommand, self._on_command,
                                      subscriber=Subscriber(cfg=cfg, republish=False))

    def _on_command(self, command: AUVCommand) -> None:
        """Republish an AUVCommand on interprocess. Runs on the application's thread."""
        log.info("Received AUVCommand: %s", short(command))
        self.interprocess().publish(groups.auv_command, command)
