"""``moos-poke``: write variables into a MOOSDB, in the spirit of uPokeDB.

``moos-poke [mission.moos] VAR=value [VAR:=value ...] [--host H] [--port P]``. A value that parses as a number
is sent as a double; ``VAR:=value`` forces a string. Each write is confirmed by reading it back from the DB;
a write the DB rejected (type lock) makes the exit code 1.
"""

from __future__ import annotations

import argparse
import logging
import re
import sys
import time

from gateway.apps.moos_tool_args import (
    add_server_arguments,
    adopt_db_time_warp,
    resolve_server,
    split_mission_file,
)
from gateway.moos.client import comms
from gateway.moos.clock import MoosClock
from util.cli import HelpFormatter
from util.logsetup import add_verbosity_argument, configure_logging

log = logging.getLogger(__name__)

_NUMERIC = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")  # MOOSIsNumeric: no nan/inf


def parse_assignment(text: str) -> tuple[str, float | str]:
    """``VAR=value`` (number → double, else string) or ``VAR:=value`` (always a string)."""
    if ":=" in text and text.index(":=") < text.index("=") + 1:
        name, value = text.split(":=", 1)
        return name.strip(), value
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise ValueError(f"expected VAR=value, got {text!r}")
    if _NUMERIC.fullmatch(value.strip()):
        return name.strip(), float(value)
    return name.strip(), value


def _same(sent: float | str, msg: object) -> bool:
    if isinstance(sent, float):
        return msg.is_double() and msg.double() == sent  # type: ignore[attr-defined]
    return msg.is_string() and msg.string() == sent  # type: ignore[attr-defined]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="moos-poke", description="Write MOOS variables (like uPokeDB).")
    parser.add_argument("items", nargs="+", help="[mission.moos] VAR=value ... (VAR:=value forces a string)")
    parser.add_argument("--name", default="uPokeDB", help="client name (default uPokeDB)")
    parser.add_argument("--confirm_timeout", type=float, default=3.0, help="seconds to wait for read-back")
    add_server_arguments(parser)
    add_verbosity_argument(parser)
    args = parser.parse_intermixed_args(argv)  # options may sit between the mission file and VAR=value
    configure_logging(args.verbose, "moos-poke")
    mission, items = split_mission_file(args.items)
    try:
        pokes = [parse_assignment(item) for item in items]
    except ValueError as exc:
        parser.error(str(exc))
    if not pokes:
        parser.error("nothing to poke: give VAR=value")
    host, port, warp = resolve_server(args, mission)

    clock = MoosClock(warp or 1.0)
    client = comms(clock=clock)
    client.run(host, port, args.name)
    try:
        if not client.wait_until_connected(args.connect_timeout * 1000):
            reason = client.get_fatal_error() or f"no DB at {host}:{port} within {args.connect_timeout:g} s"
            log.error("cannot connect: %s", reason)
            print(f"moos-poke: cannot connect: {reason}", file=sys.stderr)
            return 1
        if warp is None:
            adopt_db_time_warp(client, clock)
        for name, _ in pokes:
            client.register(name, 0)
        for name, value in pokes:
            client.notify(name, value)
        confirmed: dict[str, object] = {}
        deadline = time.monotonic() + args.confirm_timeout
        while len(confirmed) < len(pokes) and time.monotonic() < deadline:
            for msg in client.fetch():
                for name, value in pokes:
                    if msg.key() == name and msg.source() == args.name and _same(value, msg):
                        confirmed[name] = msg
            time.sleep(0.005)
        status = 0
        print(f"{'VarName':<24} {'Type':<7} {'Value':<30} Status")
        for name, value in pokes:
            kind = "double" if isinstance(value, float) else "string"
            ok = name in confirmed
            status |= 0 if ok else 1
            print(f"{name:<24} {kind:<7} {str(value):<30} {'ok' if ok else 'NOT CONFIRMED (type lock?)'}")
        return status
    finally:
        client.close(True)


if __name__ == "__main__":
    sys.exit(main())
