"""``moos-db``: the MOOSDB role as a console script, with MOOSDB's flags.

Differences from the C++ MOOSDB (see docs/moos.md): binds 127.0.0.1 unless ``--moos_address`` says otherwise;
``--moos_port=0`` picks a free port; the chosen address is printed on stdout as
``MOOSDB <community> listening on <host>:<port>``. Options of the C++ DB that have no meaning here
(``-s``, ``-b``, ``--audit_port``, suicide and web-server options, ...) are accepted and ignored with a log line.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path

from gateway.moos import database
from gateway.moos.errors import MissionFileError
from gateway.moos.mission_file import MissionFile
from gateway.moos.server import MoosDB
from util.cli import HelpFormatter, bounded_number, positive_number
from util.logsetup import add_verbosity_argument, configure_logging
from util.process import handle_signals

log = logging.getLogger(__name__)

# --flag / mission-file global / default: the DB's bounds (a flag wins over the file, as for --moos_port)
LIMITS = (
    ("max_packet_bytes", "MaxPacketBytes", 64 * 1024 * 1024,
     "largest packet accepted from a client before it is dropped (also the most unfinished input one connection "
     "may buffer)"),
    ("max_outbox_bytes", "MaxOutboxBytes", 16 * 1024 * 1024,
     "unsent bytes one client may have queued before it is dropped as too slow"),
    ("max_buffered_bytes", "MaxBufferedBytes", 256 * 1024 * 1024,
     "input and output buffered for all connections together; past it the connection holding the most is dropped"),
    ("max_variables", "MaxVariables", database.MAX_VARIABLES,
     "variables the DB holds; a write or registration that would create more is refused and logged"),
    ("max_variables_per_client", "MaxVariablesPerClient", database.MAX_VARIABLES_PER_CLIENT,
     "variables one client name may create; past it its new variables are refused and logged"),
    ("max_name_bytes", "MaxNameBytes", database.MAX_NAME_BYTES,
     "longest client, variable, source, aux or community name; longer ones are refused"),
    ("max_stored_bytes", "MaxStoredBytes", database.MAX_STORED_BYTES,
     "bytes of names, values and aux stored for all variables; a write past it is refused and logged"),
)

_IGNORED_FLAGS = ("-s", "--single_threaded", "-b", "--moos_boost", "-d", "--dns", "--tcpnodelay",
                  "--print_heart_beat", "--moos_suicide_disable", "--moos_suicide_print", "--moos_no_colour")
_IGNORED_VALUES = ("--warning_latency", "--audit_port", "--event_log", "--webserver_port",
                   "--moos_suicide_channel", "--moos_suicide_port", "--moos_suicide_phrase")


def parse_response(text: str) -> dict[str, float]:
    """``x_app:20,*_instrument:0`` -> {name or pattern: seconds}; raises ValueError naming the bad entry."""
    result: dict[str, float] = {}
    for entry in filter(None, (part.strip() for part in text.split(","))):
        name, sep, ms = entry.rpartition(":")
        try:
            if not sep or not name:
                raise ValueError
            result[name] = float(ms) / 1000.0
        except ValueError:
            raise ValueError(f"--response entry {entry!r} is not name:milliseconds") from None
    return result


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="moos-db", description="A MOOSDB-compatible MOOS v10 server.")
    parser.add_argument("mission_file", nargs="?", help="mission file (.moos) for ServerPort, Community, "
                        "MOOSTimeWarp and ClientTimeout (default Mission.moos if present)")
    parser.add_argument("--moos_file", help="mission file (same as the positional argument)")
    parser.add_argument("--moos_port", type=bounded_number(int, 0, 65535),
                        help="port to listen on (default ServerPort or 9000; 0 = any free)")
    parser.add_argument("--moos_community", help="community name (default Community or #1)")
    parser.add_argument("--moos_time_warp", type=positive_number,
                        help="time warp (default MOOSTimeWarp or 1)")
    parser.add_argument("--moos_timeout", type=positive_number,
                        help="seconds of client silence before disconnect (default 5)")
    parser.add_argument("--moos_address", default="127.0.0.1",
                        help="address to bind (default 127.0.0.1; 0.0.0.0 for every interface like the C++ DB)")
    for flag, param, default, text in LIMITS:
        parser.add_argument(f"--{flag}", type=bounded_number(int, 1),
                            help=f"{text} (default {param} in the mission file, else {default})")
    parser.add_argument("--response", default="",
                        help="name:ms or pattern:ms, comma separated: ask those async clients to write no more "
                        "often than that (sent in the timing reply, as MOOSDB does)")
    parser.add_argument("--moos_print_version", action="store_true", help="print the version and exit")
    for flag in _IGNORED_FLAGS:
        parser.add_argument(flag, action="store_true", dest="ignored_" + flag.strip("-"), help=argparse.SUPPRESS)
    for flag in _IGNORED_VALUES:
        parser.add_argument(flag, dest="ignored_" + flag.strip("-"), help=argparse.SUPPRESS)
    add_verbosity_argument(parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    configure_logging(args.verbose, "moos-db")
    if args.moos_print_version:
        print("moos-db (goby-moos-py) speaking MOOS v10 wire protocol \"ELKS CAN'T DANCE 2/8/10\"")
        return 0
    for name, value in vars(args).items():
        if name.startswith("ignored_") and value:
            log.info("option --%s has no effect here and is ignored", name[len("ignored_"):])

    port, community, warp, timeout = 9000, "#1", 1.0, 5.0
    limits = {flag: default for flag, _, default, _ in LIMITS}
    path = args.moos_file or args.mission_file
    if path is None and Path("Mission.moos").exists():
        path = "Mission.moos"
    if path is not None:
        try:  # a DB on the wrong port or warp serves nobody: a bad mission file is fatal (exit 2), not a warning
            mission = MissionFile(path)
            mission.check()
            port, community, warp = mission.server_port, mission.community, mission.time_warp
            timeout = mission.global_number("ClientTimeout", 0, math.inf, low_inclusive=False) or timeout
            for flag, param, _, _ in LIMITS:
                value = mission.global_number(param, 1, 2**62)
                if value is not None:
                    if value != int(value):
                        raise MissionFileError(f"{path}: {param} = {value:g} is not a whole number")
                    limits[flag] = int(value)
        except MissionFileError as exc:
            log.error("mission file not usable: %s", exc)
            return 2
    if args.moos_port is not None:
        port = args.moos_port
    if args.moos_community:
        community = args.moos_community
    if args.moos_time_warp is not None:
        warp = args.moos_time_warp
    if args.moos_timeout is not None:
        timeout = args.moos_timeout
    for flag in limits:
        if getattr(args, flag) is not None:
            limits[flag] = getattr(args, flag)

    try:
        response = parse_response(args.response)
        server = MoosDB(args.moos_address, port, community, time_warp=warp, client_timeout=timeout,
                        response=response, **limits)
        server.start()
    except (OSError, ValueError) as exc:
        log.error("cannot start the MOOSDB on %s:%d: %s", args.moos_address, port, exc)
        return 1

    with handle_signals(lambda _signum: server.stop()):
        print(f"MOOSDB {community} listening on {server.host}:{server.port}", flush=True)
        server.serve_forever()
        server.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
