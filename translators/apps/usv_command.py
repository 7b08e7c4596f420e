"""usv-command: send a USVCommand from shore and report whether it reached the vehicle's MOOSDB.

    usv-command polygon --sides 6 --radius 300 [--timeout 10] [goby options: config file, --interprocess ...]
    usv-command waypoints

Exit codes: 0 acknowledged (posted to MOOS, or with ``intervehicle: true`` acked over the satellite link by the
USV's modem), 1 refused (here, by usv-manager or by CommandTranslation), 2 bad command line or configuration,
3 no acknowledgement within the timeout (or expired on the satellite link).

With ``intervehicle: true`` in its config (the topside's broker has the satellite link), the command goes out on
intervehicle as the course's topside sends it, and the answer is the link's ack, with the slot wait and the ack
time; otherwise it is published on the shore group of a broker shared with the USV and the answer is usv-manager's
and CommandTranslation's USVCommandAck.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time

from google.protobuf import text_format

from gateway.goby.portal import SingleThreadApplication, run_application
from gateway.goby.portal.config import example_config
from translators.usv import groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from translators.usv.protobuf.usv_config_pb2 import CommandTool
from translators.usv.satellite import SatelliteCommander, describe_link_ack
from translators.usv.validation import DcclBoundsError, check_dccl_bounds
from util.cli import HelpFormatter, positive_number

log = logging.getLogger(__name__)

EXIT_ACKNOWLEDGED = 0
EXIT_REFUSED = 1
EXIT_USAGE = 2
EXIT_UNACKNOWLEDGED = 3
PROG = "usv-command"


def build_parser() -> argparse.ArgumentParser:
    """The command part of the command line; anything it does not know goes to the Goby config parser."""
    parser = argparse.ArgumentParser(
        formatter_class=HelpFormatter,
        prog=PROG,
        description="Send a goby3_course.dccl.USVCommand to usv-manager and wait for its acknowledgement.",
        epilog="Other options (config file, --interprocess, -v, ...) are the usual Goby application options.",
    )
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--timeout", type=positive_number, help="seconds to wait for the acknowledgement (default: "
                        "ack_timeout of the config, 10)")
    states = parser.add_subparsers(dest="state", required=True, metavar="{polygon,waypoints}")
    polygon = states.add_parser("polygon", parents=[common], help="loiter on a radial polygon centred at (0, 0)")
    polygon.add_argument("--sides", type=int, required=True, help="number of sides (DCCL bounds 3..10)")
    polygon.add_argument("--radius", type=int, required=True, help="radius in metres (100..2000, 10 m steps)")
    states.add_parser("waypoints", parents=[common], help="follow the waypoint track")
    return parser


def build_command(args: argparse.Namespace, now: float) -> USVCommand:
    """The USVCommand the arguments ask for, stamped ``now`` (the stamp also identifies its acknowledgement)."""
    command = USVCommand(time=now)
    if args.state == "polygon":
        command.desired_state = USVCommand.POLYGON
        command.polygon_sides = args.sides
        command.polygon_radius = args.radius
    else:
        command.desired_state = USVCommand.WAYPOINTS
    return command


def describe_ack(ack: USVCommandAck) -> str:
    """One line for the user about one acknowledgement."""
    if ack.stage in (USVCommandAck.LINK_ACKED, USVCommandAck.LINK_EXPIRED):
        return describe_link_ack(ack)
    if ack.stage == USVCommandAck.REFUSED:
        return f"refused by {ack.responder}: {ack.error}"
    if ack.stage == USVCommandAck.RECEIVED_BY_MANAGER:
        return f"received by {ack.responder}"
    return f"acknowledged by {ack.responder}: posted {', '.join(ack.moos_post)}"


class CommandSender(SingleThreadApplication):
    """Publishes one command, then waits for the acknowledgement that settles it (or for the timeout)."""

    def __init__(self, cfg: CommandTool, command: USVCommand, timeout_s: float) -> None:
        super().__init__(cfg, loop_frequency_hz=10.0)
        command.time = self.context.clock.now()  # the application's clock: warped if app.simulation says so
        self._command = command
        self._deadline = time.monotonic() + timeout_s
        self._timeout_s = timeout_s
        self._satellite: SatelliteCommander | None = None
        if cfg.intervehicle:
            self._satellite = SatelliteCommander(self, self._on_ack)
            self._satellite.send(command)
        else:
            self.interprocess().subscribe(groups.usv_command_ack, USVCommandAck, self._on_ack)
            # Buffered until the broker releases the hold, so it cannot overtake our ack subscription.
            self.interprocess().publish(groups.shore_usv_command, command)
        print(f"sent: {text_format.MessageToString(command, as_one_line=True)}", flush=True)

    def _on_ack(self, ack: USVCommandAck) -> None:
        """Report acknowledgements of our command; quit on a settling one. Runs on the main thread."""
        if not ack.HasField("command_time") or ack.command_time != self._command.time:
            return  # someone else's command
        print(describe_ack(ack), flush=True)
        if ack.stage in (USVCommandAck.POSTED_TO_MOOS, USVCommandAck.LINK_ACKED):
            self.quit(EXIT_ACKNOWLEDGED)
        elif ack.stage == USVCommandAck.REFUSED:
            self.quit(EXIT_REFUSED)
        elif ack.stage == USVCommandAck.LINK_EXPIRED:
            self.quit(EXIT_UNACKNOWLEDGED)

    def loop(self) -> None:
        """Send once the hold is released (intervehicle); give up at the deadline. Runs on the main thread at 10 Hz."""
        if self._satellite is not None:
            self._satellite.service()
        if time.monotonic() >= self._deadline:
            print(f"NOT acknowledged within {self._timeout_s:g} s (is usv-manager running, and moos-gateway "
                  "with the usv_command plugin?)", flush=True)
            self.quit(EXIT_UNACKNOWLEDGED)


def main(argv: list[str] | None = None) -> int:
    """Console script ``usv-command``."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if {"-e", "--example_config"} & set(argv):  # the Goby option works without a command
        print(example_config(CommandTool))
        return 0
    parser = build_parser()
    args, goby_argv = parser.parse_known_args(argv)
    notices: list[str] = []
    try:
        command = check_dccl_bounds(build_command(args, 0.0), notices)
    except DcclBoundsError as error:
        print(f"{PROG}: refused, nothing sent: {error}", file=sys.stderr)
        return EXIT_REFUSED
    for notice in notices:
        print(f"{PROG}: note: {notice}", file=sys.stderr)

    def make_app(cfg: CommandTool) -> CommandSender:
        timeout = args.timeout if args.timeout is not None else cfg.ack_timeout
        return CommandSender(cfg, command, timeout)

    return run_application(make_app, CommandTool, goby_argv, prog=PROG)


if __name__ == "__main__":
    raise SystemExit(main())
