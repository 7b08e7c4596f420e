"""NodeReportTranslation: node_status -> NODE_REPORT, so trailing vehicles and viewers see the vehicle as a contact.

The Goby3 course's IvPHelmTranslation posts the USV's navigation as ``NODE_REPORT`` in the AUVs' MOOSDBs
(``NAME=..,TYPE=..,TIME=..,X=..,Y=..,DEPTH=..,HDG=..,SPD=..``); pHelmIvP's contact ledger and BHV_Trail read it.
Here the source is the ``node_status`` group on interprocess (what the course carries as usv_nav over acomms),
and X/Y are computed on the receiving MOOSDB's datum (``app.geodesy``) when one is configured.
"""

from __future__ import annotations

import logging

from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.base import Translator, translator_plugin
from translators.frontseat.nav_conversion import node_report
from translators.frontseat.translation import geodesy_from_config

log = logging.getLogger(__name__)

NODE_REPORT = "NODE_REPORT"


class NodeReportTranslation(Translator):
    """Posts every NodeStatus seen on interprocess as a NODE_REPORT line."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, index: int = -1, *, comms_kind: str | None = None) -> None:
        super().__init__(cfg, index, comms_kind=comms_kind)
        self._geodesy = geodesy_from_config(cfg)
        self.goby().interprocess().subscribe(groups.node_status, NodeStatus, self._on_node_status)

    def _on_node_status(self, status: NodeStatus) -> None:
        """Post one NODE_REPORT. Runs on the translator's thread."""
        report = node_report(status, self._geodesy)
        log.debug("NODE_REPORT: %s", report)
        self.moos().comms().notify(NODE_REPORT, report)


# The plugin (``GOBY_MOOS_GATEWAY_PLUGINS``): load launches the translator, unload joins it.
load, unload = translator_plugin(NodeReportTranslation)
