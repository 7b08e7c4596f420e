"""CoronerTranslation: the coroner's VehicleHealth reports into MOOS as ``GOBY_PROCESS_HEALTH``.

Goby3's coroner gateway plugin (``libgoby_coroner_moos_gateway_plugin.so``, src/moos/middleware/coroner): every
``goby.middleware.protobuf.VehicleHealth`` goby-coroner publishes on ``goby::health::report`` is posted in the
gateway's ``moos_parser_technique`` (serialize_for_moos: by default ``@PB[goby.middleware.protobuf.VehicleHealth]``
and the text format; binary techniques go out as binary mail), so MOOS apps and viewers see the platform's health.
It is this direction only: MOOS processes are not themselves asked for their health (docs/health.md).
"""

from __future__ import annotations

import logging

from gateway.goby.portal.health import HEALTH_REPORT
from gateway.goby.portal.protobuf.coroner_pb2 import VehicleHealth
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.base import Translator, translator_plugin

log = logging.getLogger(__name__)

PROCESS_HEALTH_VAR = "GOBY_PROCESS_HEALTH"


class CoronerTranslation(Translator):
    """Posts every VehicleHealth report seen on interprocess as ``GOBY_PROCESS_HEALTH``."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, index: int = -1, *, comms_kind: str | None = None) -> None:
        super().__init__(cfg, index, comms_kind=comms_kind)
        self.goby().interprocess().subscribe(HEALTH_REPORT, VehicleHealth, self._on_health)

    def _on_health(self, health: VehicleHealth) -> None:
        """Runs on the translator's thread."""
        log.debug("To MOOS: %s", health)
        self.moos().notify_protobuf(PROCESS_HEALTH_VAR, health)


# The plugin (``GOBY_MOOS_GATEWAY_PLUGINS``): load launches the translator, unload joins it.
load, unload = translator_plugin(CoronerTranslation)
