"""FrontSeatTranslation: pHelmIvP <-> the frontseat interface (Goby3's ``goby::moos::FrontSeatTranslation``).

Goby -> MOOS: each ``node_status`` becomes the NAV_* variables pHelmIvP and pNodeReporter read.
MOOS -> Goby: DESIRED_SPEED (with the other buffered DESIRED_*) becomes a ``desired_course``; IVPHELM_STATE
becomes a ``helm_state`` report. Runs as a gateway plugin (``load``/``unload``) and embedded in
frontseat-interface, which launches it with a GobyMOOSGatewayConfig whose ``app.geodesy`` is the datum and
``embedded=True``.

Where the data goes (Goby's layering): ``helm_state`` and ``desired_course`` are published interprocess, which also
hands them by interthread to subscribers of this process (the interface's main thread, when embedded); the broker
carries them to other processes, as gobyd does.  ``node_status`` comes by interthread from the interface's main
thread when embedded (Goby's forwarder threads get it from the portal's inner publication), and interprocess in
moos-gateway.

The thread wakes only for work: MOOS mail and node_status as they arrive, and once per simulated second for
``GOBY_MOOS_TRANSLATOR_TIME`` (it does not override ``loop()``, so the base ticks once per simulated second: Goby's
10 Hz x warp tick would have nothing else to do here).
"""

from __future__ import annotations

import logging

from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from frontseat.protobuf.frontseat_pb2 import HelmState, HelmStateReport
from frontseat.protobuf.navigation_pb2 import DatumUpdate
from gateway.moos import MoosMessage
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.base import Translator, translator_plugin
from translators.frontseat.helm_conversion import (
    BUFFERED_SETPOINTS,
    DESIRED_SPEED,
    IVPHELM_STATE,
    SetpointError,
    desired_course,
    helm_state,
)
from translators.frontseat.nav_conversion import nav_posts
from util.geodesy import UTMGeodesy

log = logging.getLogger(__name__)


def geodesy_from_config(cfg: GobyMOOSGatewayConfig) -> UTMGeodesy | None:
    """The local grid of ``cfg.app.geodesy``, or None when no datum is configured."""
    if not cfg.app.HasField("geodesy"):
        return None
    return UTMGeodesy(cfg.app.geodesy.lat_origin, cfg.app.geodesy.lon_origin)


class FrontSeatTranslation(Translator):
    """Moves navigation to the helm and the helm's setpoints and state to the frontseat interface."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, index: int = -1, *, comms_kind: str | None = None,
                 embedded: bool = False) -> None:
        """``embedded``: in frontseat-interface, whose main thread publishes node_status (taken by interthread, so
        it never leaves the process to come back); otherwise node_status is taken from the broker."""
        super().__init__(cfg, index, comms_kind=comms_kind)
        self.embedded = embedded
        self._geodesy = geodesy_from_config(cfg)
        if self._geodesy is None:
            log.warning("no app.geodesy datum configured: NAV_X/NAV_Y will be copied from node_status local_fix")
        for variable in BUFFERED_SETPOINTS:
            self.moos().add_buffer(variable)
        self.moos().add_trigger(DESIRED_SPEED, self._on_desired_speed)
        self.moos().add_trigger(IVPHELM_STATE, self._on_helm_state)
        interprocess = self.goby().interprocess()
        if embedded:
            self.goby().interthread().subscribe(groups.node_status, NodeStatus, self._on_node_status)
        else:
            interprocess.subscribe(groups.node_status, NodeStatus, self._on_node_status)
        interprocess.subscribe(groups.datum_update, DatumUpdate, self._on_datum_update)

    def _on_node_status(self, status: NodeStatus) -> None:
        """Post NAV_* for one NodeStatus. Runs on the translator's thread."""
        comms = self.moos().comms()
        for name, value in nav_posts(status, self._geodesy):
            comms.notify(name, value)
        log.debug("posted NAV_* for node_status at time %.3f", status.time)

    def _on_datum_update(self, update: DatumUpdate) -> None:
        """Move the local grid's origin, as Goby applications do. Runs on the translator's thread."""
        try:
            self._geodesy = UTMGeodesy(update.datum.lat, update.datum.lon)
        except ValueError as error:
            log.error("ignoring datum_update: %s", error)
            return
        log.info("datum updated to lat=%.8f lon=%.8f", update.datum.lat, update.datum.lon)

    def _on_desired_speed(self, msg: MoosMessage) -> None:
        """Publish a DesiredCourse built from the buffered setpoints. Runs on the translator's thread."""
        try:
            course, errors = desired_course(msg, self.moos().buffer())
        except SetpointError as error:
            log.error("no desired_course published: %s", error)
            return
        for problem in errors:
            log.error("setpoint left out of desired_course: %s", problem)
        self.goby().interprocess().publish(groups.desired_course, course)
        log.debug("posting to Goby: desired_course %s", course)

    def _on_helm_state(self, msg: MoosMessage) -> None:
        """Publish a HelmStateReport for every IVPHELM_STATE. Runs on the translator's thread."""
        report = HelmStateReport(state=helm_state(msg.string()))
        self.goby().interprocess().publish(groups.helm_state, report)
        log.debug("IVPHELM_STATE %r -> helm_state %s", msg.string(), HelmState.Name(report.state))


# The plugin (``GOBY_MOOS_GATEWAY_PLUGINS``): load launches the translator, unload joins it.
load, unload = translator_plugin(FrontSeatTranslation)
