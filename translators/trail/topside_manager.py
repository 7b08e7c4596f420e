"""topside-manager's application (goby3-course ``src/bin/manager/topside/app.cpp``): intervehicle ``usv_nav`` and
``auv_nav`` (from the USV's satellite modem) -> NodeStatus on interprocess ``node_status``, names with the optional
``vehicle_name_prefix``, for the shore's GUIs; and the USV's ``HealthStatus`` (``health_status_good`` /
``health_status_failed``, from usv-health-monitor), logged and published on interprocess under the group it came
on, where the topside's goby-liaison shows it."""

from __future__ import annotations

import logging
from typing import Any

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.intervehicle import AckData, Subscriber, TransporterConfig
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import Subscription
from gateway.goby.portal import SingleThreadApplication
from translators.trail import groups
from translators.trail.health_status import health_group
from translators.trail.nav_convert import to_node_status
from translators.trail.nav_links import link_cfg, nav_subscriber, required_geodesy, short
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.manager_config_pb2 import TopsideManager as TopsideManagerConfig
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from util.geodesy import UTMGeodesy

log = logging.getLogger(__name__)


def topside_node_status(nav: NavigationReport, geodesy: UTMGeodesy, clock: Any, prefix: str = "") -> NodeStatus:
    """The NodeStatus the topside publishes for one received report, its name prefixed with ``prefix``."""
    status = to_node_status(nav, geodesy, clock)
    status.name = prefix + status.name
    return status


class TopsideManager(SingleThreadApplication):
    """Shore: every vehicle's nav (the USV's own and the AUVs' it forwards) as NodeStatus for the GUIs."""

    def __init__(self, cfg: TopsideManagerConfig) -> None:
        super().__init__(cfg)
        self._geodesy = required_geodesy(cfg, "topside-manager")
        self._prefix = cfg.vehicle_name_prefix
        usv_cfg = link_cfg(cfg.usv_modem_id, ack_required=False, max_queue=1, newest_first=True)
        self.intervehicle().subscribe(groups.usv_nav, NavigationReport, self._on_nav,
                                      subscriber=nav_subscriber(usv_cfg))
        auv_cfg = link_cfg(cfg.usv_modem_id, ack_required=True, max_queue=10, newest_first=True)
        self.intervehicle().subscribe(groups.auv_nav, NavigationReport, self._on_nav,
                                      subscriber=nav_subscriber(auv_cfg))
        self._subscribe_usv_health(cfg.usv_modem_id)

    def _subscribe_usv_health(self, usv_modem_id: int) -> None:
        """The course's ``subscribe_usv_health``: both groups from the USV's modem (default buffer), the group read
        back from ``state``; the Subscription's ack is logged."""
        health_cfg = TransporterConfig()
        health_cfg.intervehicle.publisher_id.append(usv_modem_id)
        self.intervehicle().subscribe(groups.health_status_good, HealthStatus, self._on_health_good,
                                      subscriber=self._health_subscriber(health_cfg))
        self.intervehicle().subscribe(groups.health_status_failed, HealthStatus, self._on_health_failed,
                                      subscriber=self._health_subscriber(health_cfg))

    def _health_subscriber(self, cfg: TransporterConfig) -> Subscriber:
        return Subscriber(cfg=cfg, group=health_group, on_subscribed=self._on_health_subscribed, republish=False)

    def _on_health_good(self, status: HealthStatus) -> None:
        """Log the USV's health and publish it on interprocess. Runs on the application's thread."""
        log.info("Received HealthStatus: %s", short(status))
        self.interprocess().publish(groups.health_status_good, status)

    def _on_health_failed(self, status: HealthStatus) -> None:
        """As :meth:`_on_health_good`, for ``health_status_failed`` (a warning)."""
        log.warning("Received HealthStatus: %s", short(status))
        self.interprocess().publish(groups.health_status_failed, status)

    def _on_health_subscribed(self, subscription: Subscription, ack: AckData) -> None:
        log.info("Received acknowledgment: %s for subscription: %s", short(ack), short(subscription))

    def _on_nav(self, nav: NavigationReport) -> None:
        """Publish one vehicle's NodeStatus on interprocess. Runs on the application's thread."""
        status = topside_node_status(nav, self._geodesy, self.context.clock, self._prefix)
        log.debug("Received DCCL nav: %s -> %s", short(nav), short(status))
        self.interprocess().publish(frontseat_groups.node_status, status)
