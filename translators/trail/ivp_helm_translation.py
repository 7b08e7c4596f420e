"""IvPHelmTranslation: the course's contacts and AUV commands into pHelmIvP's MOOSDB (goby3-course
``src/lib/moos_gateway/goby3_course_gateway_plugin.cpp``, post-homework3).

- ``goby3_course::usv_nav`` (NavigationReport, PROTOBUF on interprocess: the AUV manager republishes what came
  over the acoustic link) -> ``NODE_REPORT = NAME=USV,TYPE=USV,TIME=<rewarped>,X=..,Y=..,DEPTH=..,HDG=..,SPD=..``,
  the contact BHV_Trail follows.
- ``goby3_course::auv_command`` (AUVCommand) -> ``DEPLOY_DEPTH_UPDATES = depth=0`` and then
  ``AUV_DEPLOY_STATE = <desired_state>`` (``RECOVER`` or ``TRAIL``), in that order, so the depth behaviour already
  has its new depth when the mode switches.
"""

from __future__ import annotations

import logging

from google.protobuf import text_format

from gateway.goby.portal import Scheme
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.base import Translator
from translators.node_report_codec import NodeReportError, format_course_report
from translators.trail import groups
from translators.trail.nav_convert import contact_report
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand

log = logging.getLogger(__name__)

NODE_REPORT = "NODE_REPORT"
DEPLOY_DEPTH_UPDATES = "DEPLOY_DEPTH_UPDATES"
AUV_DEPLOY_STATE = "AUV_DEPLOY_STATE"


def command_posts(command: AUVCommand) -> list[tuple[str, str]]:
    """The MOOS (variable, value) pairs for one AUVCommand, in the order the course posts them."""
    return [(DEPLOY_DEPTH_UPDATES, "depth=0"),
            (AUV_DEPLOY_STATE, AUVCommand.AutonomyState.Name(command.desired_state))]


class IvPHelmTranslation(Translator):
    """Posts the USV's navigation as a NODE_REPORT contact and AUV commands as the behaviour file's variables."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, index: int = -1, *, comms_kind: str | None = None) -> None:
        super().__init__(cfg, index, comms_kind=comms_kind)
        interprocess = self.goby().interprocess()
        interprocess.subscribe(groups.usv_nav, NavigationReport, self._on_usv_nav, scheme=Scheme.PROTOBUF)
        interprocess.subscribe(groups.auv_command, AUVCommand, self._on_auv_command)

    def _on_usv_nav(self, nav: NavigationReport) -> None:
        """Post one contact NODE_REPORT. Runs on the translator's thread."""
        try:
            report = format_course_report(contact_report(nav, self.context.clock))
        except NodeReportError as error:
            log.error("not posting NODE_REPORT for %s: %s", text_format.MessageToString(nav, as_one_line=True),
                      error)
            return
        log.debug("NODE_REPORT: %s", report)
        self.moos().comms().notify(NODE_REPORT, report)

    def _on_auv_command(self, command: AUVCommand) -> None:
        """Post DEPLOY_DEPTH_UPDATES then AUV_DEPLOY_STATE. Runs on the translator's thread."""
        log.info("Posting to MOOS: AUVCommand: %s", text_format.MessageToString(command, as_one_line=True))
        comms = self.moos().comms()
        for variable, value in command_posts(command):
            comms.notify(variable, value)
