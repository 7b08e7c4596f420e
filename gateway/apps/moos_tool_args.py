"""Command-line conventions of the MOOS tools and apps: moos-poke and moos-scope (uPokeDB / uXMS style) and a MOOS
application's ``MISSION [--alias NAME]`` (ivp-helm, node-reporter)."""

from __future__ import annotations

import argparse
import logging
import time

from gateway.moos.client import comms
from gateway.moos.clock import MAX_WARP, MoosClock
from gateway.moos.errors import MissionFileError
from gateway.moos.mission_file import MissionFile
from util.cli import HelpFormatter
from util.logsetup import add_verbosity_argument, configure_logging

log = logging.getLogger(__name__)


def add_server_arguments(parser: argparse.ArgumentParser) -> None:
    """``--host``/``--port``/``--moos_time_warp`` (also read from a mission file) and ``--name``."""
    parser.add_argument("--host", "--server_host", dest="host", help="DB host (default ServerHost or localhost)")
    parser.add_argument("--port", "--server_port", dest="port", type=int, help="DB port (default ServerPort or 9000)")
    parser.add_argument("--moos_time_warp", type=float, help="time warp (default MOOSTimeWarp, else the DB's)")
    parser.add_argument("--connect_timeout", type=float, default=5.0, help="seconds to wait for the DB")


def split_mission_file(items: list[str]) -> tuple[str | None, list[str]]:
    """Take a leading ``*.moos`` argument out of the free arguments, as uPokeDB and uXMS accept one."""
    if items and items[0].endswith(".moos"):
        return items[0], items[1:]
    return None, items


def resolve_server(args: argparse.Namespace, mission_path: str | None) -> tuple[str, int, float | None]:
    """Host, port and warp: the command line wins over the mission file, which wins over the defaults."""
    host, port, warp = "localhost", 9000, None
    if mission_path is not None:
        try:
            mission = MissionFile(mission_path)
            host, port = mission.server_host, mission.server_port
            if mission.global_value("MOOSTimeWarp") is not None:
                warp = mission.time_warp
        except (MissionFileError, ValueError) as exc:
            log.warning("mission file not used: %s", exc)
    if args.host:
        host = args.host
    if args.port is not None:
        port = args.port
    if args.moos_time_warp:
        warp = args.moos_time_warp
    return host, port, warp


def adopt_db_time_warp(client: comms, clock: MoosClock) -> float:
    """Give ``clock`` the connected DB's time warp, inferred from the DB time in its WELCOME, as uPokeDB does.

    The DB stamps its WELCOME with its warped MOOS time (unix time x warp), so ``db_time / now`` is the warp,
    rounded to 0.001. Used by moos-poke and moos-scope when neither ``--moos_time_warp`` nor the mission file
    gives one. A skew already taken from the WELCOME (measured at the old warp) is re-based on the new warp.
    Returns the warp now in force.
    """
    welcome = client.welcome
    if welcome is None or welcome.db_time <= 0:
        return clock.warp
    now = time.time()
    warp = min(MAX_WARP, max(0.001, round(welcome.db_time / now, 3)))
    if warp != clock.warp:
        clock.set_warp(warp)
        if clock.skew != 0.0:  # time correction is on (remote DB or quiet): skew = DB time - our warped time
            clock.skew = welcome.db_time - now * warp
    return warp


def parse_moos_app_args(argv: list[str] | None, prog: str, description: str, process: str) -> argparse.Namespace:
    """A MOOS application's command line, as a CMOOSApp takes it: the mission file, ``--alias NAME`` (MOOS name and
    ProcessConfig block instead of ``process``) and ``-v``; configures logging under that name."""
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog=prog, description=description)
    parser.add_argument("mission", help=f".moos mission file with a ProcessConfig = {process} block")
    parser.add_argument("--alias", help=f"MOOS name (and ProcessConfig block) to use instead of {process}")
    add_verbosity_argument(parser)
    args = parser.parse_args(argv)
    configure_logging(args.verbose, args.alias or process)
    return args
