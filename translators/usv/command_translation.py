"""CommandTranslation: a USVCommand from shore changes pHelmIvP's mission (the Goby3 course's day-3 plugin).

POLYGON posts ``POLYGON_UPDATES=polygon=radial::x=0,y=0,radius=<R>,pts=<N>`` and then ``DEPLOY_STATE=POLYGON``;
WAYPOINTS posts ``DEPLOY_STATE=WAYPOINTS``. Each handled command is acknowledged on ``usv_command_ack`` so that
usv-command can tell its user whether it reached MOOS.
"""

from __future__ import annotations

import logging

from google.protobuf import text_format

from gateway.goby.dccl import Codec as DcclCodec
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.base import Translator, translator_plugin
from translators.errors import TranslatorError
from translators.usv import groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from translators.usv.validation import DcclBoundsError, check_dccl_bounds

log = logging.getLogger(__name__)


class CommandRefusedError(TranslatorError, ValueError):
    """A USVCommand that must not reach the helm (out of DCCL bounds, or a polygon without its shape)."""


def command_posts(command: USVCommand, codec: DcclCodec | None = None) -> list[tuple[str, str]]:
    """The MOOS (variable, value) pairs for one command, in the order they must be posted.

    The polygon update goes first so that the loiter behaviour already has its new shape when DEPLOY_STATE
    activates it. Unlike the course, a POLYGON without sides or radius is refused: the course would post
    ``radius=0,pts=0``, which BHV_Loiter cannot use. ``codec``: the DCCL codec that checks the bounds (see
    ``check_dccl_bounds``).
    """
    try:
        command = check_dccl_bounds(command, codec=codec)
    except DcclBoundsError as error:
        raise CommandRefusedError(str(error)) from error
    state = USVCommand.AutonomyState.Name(command.desired_state)
    posts: list[tuple[str, str]] = []
    if command.desired_state == USVCommand.POLYGON:
        missing = [f for f in ("polygon_sides", "polygon_radius") if not command.HasField(f)]
        if missing:
            raise CommandRefusedError(f"POLYGON command without {' and '.join(missing)}")
        update = f"polygon=radial::x=0,y=0,radius={command.polygon_radius},pts={command.polygon_sides}"
        posts.append(("POLYGON_UPDATES", update))
    posts.append(("DEPLOY_STATE", state))
    return posts


class CommandTranslation(Translator):
    """Turns ``goby3_course::usv_command`` into the MOOS variables the USV's behaviour file listens to."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, index: int = -1, *, comms_kind: str | None = None) -> None:
        super().__init__(cfg, index, comms_kind=comms_kind)
        self.goby().interprocess().subscribe(groups.usv_command, USVCommand, self._on_usv_command)
        log.info("Command Translation starting up")

    def _on_usv_command(self, command: USVCommand) -> None:
        """Post one command to MOOS and acknowledge it. Runs on the translator's thread."""
        ack = USVCommandAck(responder=self.translator_name(), command=text_format.MessageToString(
            command, as_one_line=True))
        if command.HasField("time"):
            ack.command_time = command.time
        try:
            posts = command_posts(command, self.context.dccl)
        except CommandRefusedError as error:
            log.error("refusing USVCommand %s: %s", ack.command, error)
            ack.stage = USVCommandAck.REFUSED
            ack.error = str(error)
        else:
            comms = self.moos().comms()
            for variable, value in posts:
                log.info("%s: %s", variable, value)
                comms.notify(variable, value)
                ack.moos_post.append(f"{variable}={value}")
            ack.stage = USVCommandAck.POSTED_TO_MOOS
        self.goby().interprocess().publish(groups.usv_command_ack, ack)


# The plugin (``GOBY_MOOS_GATEWAY_PLUGINS``): load launches the translator, unload joins it.
load, unload = translator_plugin(CommandTranslation)
