"""``moos-scope``: a live table of MOOS variables, in the spirit of uXMS.

``moos-scope [mission.moos] VAR ... [--all] [--once | --duration S]`` (options may come anywhere): shows each
variable's value, source, time and community. Times are MOOS seconds since the scope started, on a clock at
the DB's time warp (inferred from its WELCOME, as moos-poke does) unless ``--moos_time_warp`` or the mission
file's ``MOOSTimeWarp`` names one. ``--once`` prints one table as soon as every variable has been seen (or after
``--timeout``); ``--duration`` refreshes the table for that many seconds; with neither it runs until Ctrl-C.
"""

from __future__ import annotations

import argparse
import logging
import signal
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
from gateway.moos.message import MoosMessage
from util.cli import HelpFormatter
from util.logsetup import add_verbosity_argument, configure_logging
from util.process import handle_signals

log = logging.getLogger(__name__)


def format_value(msg: MoosMessage | None, width: int = 40) -> str:
    if msg is None:
        return "n/a"
    if msg.is_binary():
        return f"*binary* {msg.binary_data_size()} B"
    if msg.is_double():
        return f"{msg.double():g}"
    text = msg.string().replace("\n", "\\n")
    return f'"{text}"' if len(text) <= width else f'"{text[: width - 3]}..."'


def render_table(names: list[str], latest: dict[str, MoosMessage], start_time: float) -> str:
    """The table uXMS prints: name, source, time (MOOS seconds since scope start), community, value.

    Each column is as wide as its widest cell, so long names and sources (``goby::moos::Translator::10335``)
    keep the columns aligned.
    """
    header = ("VarName", "(S)ource", "(T)ime", "(C)ommunity", "VarValue")
    cells: list[tuple[str, str, str, str, str]] = []
    for name in names:
        msg = latest.get(name)
        if msg is None:
            cells.append((name, "n/a", "n/a", "n/a", "n/a"))
        else:
            cells.append((name, msg.source(), f"{msg.time() - start_time:.2f}", msg.community(), format_value(msg)))
    widths = [max(len(row[i]) for row in (header, *cells)) for i in range(4)]
    widths.append(max(20, *(len(row[4]) for row in cells)) if cells else 20)

    def line(row: tuple[str, ...]) -> str:
        name, source, stamp, community, value = row
        return (f"  {name:<{widths[0]}} {source:<{widths[1]}} {stamp:>{widths[2]}}  "
                f"{community:<{widths[3]}} {value}").rstrip()

    rows = [line(header), line(tuple("-" * w for w in widths))]
    rows.extend(line(row) for row in cells)
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="moos-scope", description="Watch MOOS variables (like uXMS).")
    parser.add_argument("items", nargs="*", help="[mission.moos] VAR ...")
    parser.add_argument("--all", action="store_true", help="show every variable (wildcard registration)")
    parser.add_argument("--name", default="uXMS", help="client name (default uXMS)")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--once", action="store_true", help="print one table and exit")
    mode.add_argument("--duration", type=float, help="refresh for this many seconds, then exit")
    parser.add_argument("--timeout", type=float, default=5.0, help="--once: longest wait for the variables")
    parser.add_argument("--refresh", type=float, default=1.0, help="seconds between live refreshes")
    add_server_arguments(parser)
    add_verbosity_argument(parser)
    args = parser.parse_intermixed_args(argv)  # `moos-scope mission.moos --once NAV_X` works
    configure_logging(args.verbose, "moos-scope")
    mission, names = split_mission_file(args.items)
    if not names and not args.all:
        parser.error("give variable names, or --all")
    host, port, warp = resolve_server(args, mission)

    clock = MoosClock(warp or 1.0)
    client = comms(clock=clock)
    latest: dict[str, MoosMessage] = {}
    watched = list(names)

    def on_connect() -> bool:
        for name in names:
            client.register(name, 0)
        if args.all:
            client.register("*", "*", 0)
        return True

    client.set_on_connect_callback(on_connect)
    client.run(host, port, args.name)
    with handle_signals(signals=(signal.SIGINT,)) as stop:
        try:
            if not client.wait_until_connected(args.connect_timeout * 1000):
                reason = client.get_fatal_error() or f"no DB at {host}:{port} within {args.connect_timeout:g} s"
                print(f"moos-scope: cannot connect: {reason}", file=sys.stderr)
                return 1
            if warp is None:  # neither --moos_time_warp nor MOOSTimeWarp: use the DB's, as moos-poke does
                adopt_db_time_warp(client, clock)
            start = clock.time()
            if args.once:
                deadline = time.monotonic() + args.timeout
            elif args.duration is not None:
                deadline = time.monotonic() + args.duration
            else:
                deadline = float("inf")
            next_draw = time.monotonic()
            while not stop.is_set():
                for msg in client.fetch():
                    latest[msg.key()] = msg
                    if args.all and msg.key() not in watched:
                        watched.append(msg.key())
                now = time.monotonic()
                if args.once:
                    if (names and all(n in latest for n in names)) or now >= deadline:
                        print(render_table(watched, latest, start), flush=True)
                        return 0 if all(n in latest for n in names) else 2
                elif now >= next_draw:
                    clear = "\x1b[2J\x1b[H" if sys.stdout.isatty() else ""
                    print(clear + render_table(sorted(watched) if args.all else watched, latest, start), flush=True)
                    next_draw = now + args.refresh
                if now >= deadline:
                    return 0
                stop.wait(0.02)
            return 0
        finally:
            client.close(True)


if __name__ == "__main__":
    sys.exit(main())
