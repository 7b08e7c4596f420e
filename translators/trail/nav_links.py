"""What the course's managers share (goby3-course ``src/lib/nav/intervehicle.h`` and the managers' link settings):
the navigation publisher/subscriber options, a subscriber's link config, and the geodesy every manager needs."""

from __future__ import annotations

import logging
from typing import Any

from google.protobuf import text_format

from gateway.goby.intervehicle import Publisher, Subscriber, TransporterConfig
from gateway.goby.portal import Group, StartError
from translators.trail.nav_convert import NavGroupError, nav_group, nav_set_group
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from util.geodesy import UTMGeodesy

log = logging.getLogger(__name__)


def short(msg: Any) -> str:
    """A message on one line, for logs."""
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
