"""The course's vehicle managers (goby3-course ``src/bin/manager/{auv,usv,topside}/app.cpp``, post-homework3):
who sends which navigation report and command over which link, and what lands on interprocess.

- :class:`AUVManager`: own ``node_status`` -> intervehicle ``auv_nav``; intervehicle ``usv_nav`` (broadcast from
  the USV's modem) -> interprocess ``usv_nav`` as PROTOBUF (IvPHelmTranslation turns it into NODE_REPORT);
  intervehicle ``auv_command`` (acked) -> interprocess ``auv_command``.
- :class:`TopsideManager`: intervehicle ``usv_nav`` and ``auv_nav`` (from the USV's satellite modem) ->
  NodeStatus on interprocess ``node_status``, names with the optional ``vehicle_name_prefix``.
- :func:`forward_own_nav` and :func:`forward_auv_nav`: the USV manager's navigation part (own nav -> ``usv_nav``;
  each AUV's ``auv_nav`` forwarded topside).

Libraries only: the console scripts are in ``translators/apps/``.
"""

from __future__ import annotations

import logging
from typing import Any

from google.protobuf import text_format

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.intervehicle import Publisher, Subscriber, TransporterConfig
from gateway.goby.portal import Group, Scheme, SimpleThread, SingleThreadApplication, StartError
from translators.trail import groups
from translators.trail.nav_convert import (
    NavGroupError,
    nav_group,
    nav_set_group,
    to_navigation_report,
    to_node_status,
)
from translators.trail.protobuf.manager_config_pb2 import AUVManager as AUVManagerConfig
from translators.trail.protobuf.manager_config_pb2 import TopsideManager as TopsideManagerConfig
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand
from util.geodesy import UTMGeodesy

log = logging.getLogger(__name__)


def _short(msg: Any) -> str:
    return text_format.MessageToString(msg, as_one_line=True)


def required_geodesy(cfg: Any, app: str) -> UTMGeodesy:
    """The application's ``app.geodesy`` grid; Goby's ``geodesy()`` refuses to run without a datum, and so do we."""
    if not cfg.app.HasField("geodesy"):
        raise StartError(f"{app}: no lat_origin and lon_origin defined (app {{ geodesy {{ ... }} }}): "
                         "navigation reports carry x/y on that grid")
    try:
        return UTMGeodesy(cfg.app.geodesy.lat_origin, cfg.app.geodesy.lon_origin)
    except ValueError as error:
        raise StartError(f"{app}: app.geodesy: {error}") from error


def link_cfg(publisher_id: int, *, broadcast: bool = False, ack_required: bool = False, max_queue: int = 1,
             newest_first: bool | None = None) -> TransporterConfig:
    """A subscriber's ``TransporterConfig`` (``intervehicle { publisher_id broadcast buffer {...} }``)."""
    cfg = TransporterConfig()
    cfg.intervehicle.publisher_id.append(publisher_id)
    if broadcast:
        cfg.intervehicle.broadcast = True
    cfg.intervehicle.buffer.ack_required = ack_required
    cfg.intervehicle.buffer.max_queue = max_queue
    if newest_first is not None:
        cfg.intervehicle.buffer.newest_first = newest_first
    return cfg


def nav_publisher() -> Publisher:
    """The course's ``nav_publisher()``: empty config, the group written into ``type``."""
    return Publisher(set_group=nav_set_group)


def received_nav_group(nav: NavigationReport) -> Group:
    """:func:`nav_group` for received reports: a type no navigation group has (the course would throw) is logged
    and matches no navigation subscription, so the link keeps serving."""
    try:
        return nav_group(nav)
    except NavGroupError as error:
        log.error("dropping a received NavigationReport from vehicle %d: %s", nav.vehicle, error)
        return Group("", 0)


def nav_subscriber(cfg: TransporterConfig, *, republish: bool = True) -> Subscriber:
    """The course's ``nav_subscriber(cfg)``: the group read back from ``type``. ``republish=False`` where the
    application republishes on interprocess itself (as the course's managers do), so nothing arrives twice."""
    return Subscriber(cfg=cfg, group=received_nav_group, republish=republish)


def forward_own_nav(thread: SimpleThread, group: Any, vehicle_id: int, geodesy: UTMGeodesy) -> None:
    """Send every own ``node_status`` over intervehicle ``group`` (``usv_nav`` or ``auv_nav``) as a DCCL report.

    The callback runs on ``thread``'s own thread.
    """
    def on_node_status(status: NodeStatus) -> None:
        nav = to_navigation_report(status, vehicle_id, geodesy, thread.context.clock)
        log.debug("own nav %s -> %s", _short(status), _short(nav))
        thread.intervehicle().publish(group, nav, publisher=nav_publisher())

    thread.interprocess().subscribe(frontseat_groups.node_status, NodeStatus, on_node_status)


def forward_auv_nav(thread: SimpleThread, auv_modem_ids: list[int]) -> None:
    """The USV's ``subscribe_auv_nav``: each AUV's ``auv_nav`` (no ack, newest only) forwarded topside.

    One subscription per AUV modem id (each goes to that AUV); as in Goby the last one's handler is the one kept,
    and all are the same forwarding. The callback runs on ``thread``'s own thread.
    """
    def on_auv_nav(nav: NavigationReport) -> None:
        log.debug("Received DCCL nav: %s", _short(nav))
        thread.intervehicle().publish(groups.auv_nav, nav, publisher=nav_publisher())

    for modem_id in auv_modem_ids:
        cfg = link_cfg(modem_id, ack_required=False, max_queue=1, newest_first=True)
        thread.intervehicle().subscribe(groups.auv_nav, NavigationReport, on_auv_nav,
                                        subscriber=nav_subscriber(cfg, republish=False))


def forward_usv_nav(thread: SimpleThread, cfg: Any) -> None:
    """usv-manager's navigation part (``cfg``: ``goby3_course.config.USVManager``): own nav out as ``usv_nav``
    (``vehicle_id``), each of ``auv_modem_id``'s ``auv_nav`` forwarded topside. Without ``app.geodesy`` (which the
    course's manager requires) nothing is forwarded, with a warning: usv-manager still carries commands."""
    if not cfg.app.HasField("geodesy"):
        log.warning("no app.geodesy: navigation is not forwarded (usv_nav, auv_nav)")
        return
    forward_own_nav(thread, groups.usv_nav, cfg.vehicle_id, required_geodesy(cfg, "usv-manager"))
    forward_auv_nav(thread, list(cfg.auv_modem_id))


class AUVManager(SingleThreadApplication):
    """An AUV's link manager: its nav out, the USV's nav and the AUV commands in."""

    def __init__(self, cfg: AUVManagerConfig) -> None:
        super().__init__(cfg)
        geodesy = required_geodesy(cfg, "auv-manager")
        forward_own_nav(self, groups.auv_nav, cfg.vehicle_id, geodesy)
        # The USV broadcasts its nav: the AUVs trailing it are within reception of the acoustic modem.
        usv_nav_cfg = link_cfg(cfg.usv_modem_id, broadcast=True, ack_required=False, max_queue=1, newest_first=True)
        self.intervehicle().subscribe(groups.usv_nav, NavigationReport, self._on_usv_nav,
                                      subscriber=nav_subscriber(usv_nav_cfg, republish=False))
        command_cfg = link_cfg(cfg.usv_modem_id, ack_required=True, max_queue=1)
        self.intervehicle().subscribe(groups.auv_command, AUVCommand, self._on_command,
                                      subscriber=Subscriber(cfg=command_cfg, republish=False))

    def _on_usv_nav(self, nav: NavigationReport) -> None:
        """Republish the USV's nav on interprocess as PROTOBUF. Runs on the application's thread."""
        log.debug("Received USV DCCL nav: %s", _short(nav))
        self.interprocess().publish(groups.usv_nav, nav, scheme=Scheme.PROTOBUF)

    def _on_command(self, command: AUVCommand) -> None:
        """Republish an AUVCommand on interprocess. Runs on the application's thread."""
        log.info("Received AUVCommand: %s", _short(command))
        self.interprocess().publish(groups.auv_command, command)


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

    def _on_nav(self, nav: NavigationReport) -> None:
        """Publish one vehicle's NodeStatus on interprocess. Runs on the application's thread."""
        status = topside_node_status(nav, self._geodesy, self.context.clock, self._prefix)
        log.debug("Received DCCL nav: %s -> %s", _short(nav), _short(status))
        self.interprocess().publish(frontseat_groups.node_status, status)
