"""``frontseat-sim``: the basic frontseat simulator (goby_basic_frontseat_simulator) as a console script."""

from __future__ import annotations

import argparse
import sys

from frontseat.simulator.server import SimulatorServer
from util.cli import HelpFormatter
from util.logsetup import add_verbosity_argument, configure_logging
from util.process import handle_signals


def main(argv: list[str] | None = None) -> int:
    """``frontseat-sim <tcp listen port>``: run the basic frontseat simulator until SIGINT/SIGTERM."""
    parser = argparse.ArgumentParser(
        formatter_class=HelpFormatter,
        prog="frontseat-sim",
        description="Basic frontseat simulator (goby_basic_frontseat_simulator): START/CTRL/NAV/CMD over TCP.",
    )
    parser.add_argument("port", nargs="?", help="TCP port to listen on (0: pick a free port)")
    parser.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    add_verbosity_argument(parser)
    args = parser.parse_args(argv)
    configure_logging(args.verbose, "frontseat-sim")
    if args.port is None:
        print("usage: frontseat-sim [tcp listen port]")
        return 1
    try:
        port = int(args.port)
        if not 0 <= port <= 65535:
            raise ValueError
    except ValueError:
        print(f"frontseat-sim: invalid port {args.port!r} (expected 0..65535)", file=sys.stderr)
        return 1
    try:
        server = SimulatorServer(args.host, port)
    except OSError as exc:
        print(f"frontseat-sim: cannot listen on {args.host}:{port}: {exc}", file=sys.stderr)
        return 1
    with handle_signals(lambda _signum: server.stop()):
        print(f"frontseat-sim listening on {server.host}:{server.port}", flush=True)
        try:
            server.run()  # on this thread, until a signal stops it
        except Exception as exc:  # logged with its traceback by the server
            print(f"frontseat-sim: server failed: {exc}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
