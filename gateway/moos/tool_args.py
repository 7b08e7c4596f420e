"""Command-line conventions shared by moos-poke and moos-scope (uPokeDB / uXMS style)."""

from __future__ import annotations

import argparse
import logging

from .errors import MissionFileError
from .mission_file import MissionFile

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
