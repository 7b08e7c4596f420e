"""``python -m launch.usv.demo`` (``make demo``): run the USV mission headless and show what the vehicle did.

Starts every process of ``launch/usv/usv.launch`` with generated configs, lets the shore script command
the vehicle (loiter on a hexagon, then the waypoints, then an octagon of radius 400; ``--schedule none``: no
commands, the user sends them with the printed ``usv-command`` lines); goby-logger and moos-logger log every
platform (``<out>/run/logs/usv``, ``<out>/run/logs/topside``). After the run the track and events are read from
those logs, ``track.csv``, ``events.csv`` and ``track.png`` are written into the output directory and a summary is
printed, with where the logs are and the command that turns them into MCAP for Foxglove. Exit status 0 only if the mission ran and every process
stopped cleanly.
"""

from __future__ import annotations

import argparse
import logging
import math
import shlex
import shutil
import socket
import sys
import time
from pathlib import Path

from gateway.goby.acomms.udp_multicast import random_multicast
from launch.demo import (
    add_run_arguments,
    demo_main,
    fresh_run_dir,
    plotting,
    run_mission,
    schedule_type,
    whole_number,
)
from launch.recorder import logs_lines
from launch.usv.analysis import bhv_waypoints, command_effects, loiter_phases, transitions
from launch.usv.mission import MissionResult, UsvMission, choose_program, liaison_page_urls
from launch.usv.settings import DEFAULT_SCHEDULE, KAUAI_ORIGIN, UsvSettings
from launch.usv.shore import SCHEDULE_HELP, parse_schedule
from launch.usv.summary import progress_line, summary_text
from util.cli import HelpFormatter
from util.logsetup import add_verbosity_argument
from util.process import free_port

log = logging.getLogger(__name__)
PLOT = "launch.usv.plot"  # matplotlib: the [demo] extra, imported by plotting() when a run draws

DEFAULT_DURATION_S = 1400.0
DEFAULT_WARP = 20
MAX_SOCKET_BASE = 90  # AF_UNIX paths are limited to ~107 bytes


_warp = whole_number(1)


def _origin(text: str) -> tuple[float, float]:
    """``LAT,LON`` in degrees."""
    parts = text.split(",")
    try:
        lat, lon = (float(v) for v in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not LAT,LON in degrees (e.g. 21.590491,-159.534166)") from None
    if not (math.isfinite(lat) and math.isfinite(lon) and -90 <= lat <= 90 and -180 <= lon <= 180):
        raise argparse.ArgumentTypeError(f"{text!r} is not a latitude,longitude (-90..90, -180..180)")
    return lat, lon


# The shore's own parser, so a schedule the shore would refuse is refused before anything starts.
_schedule = schedule_type(parse_schedule)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="python -m launch.usv.demo", description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=DEFAULT_DURATION_S,
                        help=f"sim seconds to run after the helm takes command (default {DEFAULT_DURATION_S:g}; "
                        "0 = until Ctrl-C)")
    parser.add_argument("--forever", action="store_true", help="run until Ctrl-C or SIGTERM (same as --duration 0)")
    parser.add_argument("--warp", type=_warp, default=DEFAULT_WARP, help=f"time warp (default {DEFAULT_WARP})")
    add_run_arguments(parser)
    parser.add_argument("--schedule", type=_schedule, default=DEFAULT_SCHEDULE,
                        help=f"shore commands: {SCHEDULE_HELP} (default {DEFAULT_SCHEDULE})")
    parser.add_argument("--origin", type=_origin, default=f"{KAUAI_ORIGIN[0]},{KAUAI_ORIGIN[1]}", metavar="LAT,LON",
                        help="lat,lon of the local grid (default %(default)s)")
    parser.add_argument("--moos-port", type=int, default=0, help="MOOSDB port (default 9001 if free)")
    parser.add_argument("--sim-port", type=int, default=0, help="frontseat simulator port (default 55001 if free)")
    parser.add_argument("--liaison-port", type=int, default=0,
                        help="goby-liaison's web page port (default 50001, the course's, if free)")
    parser.add_argument("--topside-liaison-port", type=int, default=0,
                        help="the topside's goby-liaison (Commander over the satellite link) port "
                        "(default 50000, the course's, if free)")
    parser.add_argument("--listen", default="127.0.0.1", metavar="ADDRESS",
                        help="address goby-liaison's page listens on (default 127.0.0.1, this machine only). "
                        "RISK: another address (0.0.0.0 = every interface) lets anyone who can reach it watch "
                        "all traffic and command the vehicle: the page has no login")
    add_verbosity_argument(parser)
    return parser


def _port(requested: int, preferred: int) -> int:
    if requested:
        return requested
    try:
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", preferred))
        return preferred
    except OSError:
        return free_port()


def make_settings(args: argparse.Namespace, run_dir: Path, socket_dir: Path) -> UsvSettings:
    lat, lon = args.origin
    return UsvSettings(
        run_dir=run_dir,
        warp=args.warp,
        lat_origin=lat,
        lon_origin=lon,
        moos_port=_port(args.moos_port, 9001),
        sim_port=_port(args.sim_port, 55001),
        liaison_address=args.listen,
        liaison_port=_port(args.liaison_port, 50001),
        topside_liaison_port=_port(args.topside_liaison_port, 50000),
        moosdb=choose_program(args.moosdb, "MOOSDB", "moos-db"),
        helm=choose_program(args.helm, "pHelmIvP", "ivp-helm"),
        schedule=args.schedule,
        socket_name=str(socket_dir / "goby_usv"),
        sat_port=random_multicast()[1],  # the satellite link's port: not shared with another run on this machine
    )


# What the usv_command config depends on (besides the run directory and warp, which are always given).
_COMMAND_VARS = ("lat_origin", "lon_origin", "platform")


def command_env(settings: UsvSettings) -> dict[str, str]:
    """The USV_* variables that make ``python -m launch.usv.config usv_command`` talk to this run's broker."""
    env = settings.to_env()
    default = UsvSettings()
    out = {"USV_RUN_DIR": env["USV_RUN_DIR"], "USV_WARP": env["USV_WARP"]}
    for name in _COMMAND_VARS:
        if getattr(settings, name) != getattr(default, name):
            var = f"USV_{name.upper()}"
            out[var] = env[var]
    if settings.ipc_base != settings.replace(socket_name="").ipc_base:
        out["USV_SOCKET_NAME"] = env["USV_SOCKET_NAME"]
    return out


def command_lines(settings: UsvSettings) -> list[str]:
    """Bash lines that send commands to this run from another terminal.

    The variables are exported on a line of their own: a ``VAR=value cmd <(...)`` prefix reaches ``cmd`` but
    not the ``<(...)`` process substitution that generates the config. The programs are named by absolute path
    (this interpreter's bin directory), so the lines work without an activated virtualenv.
    """
    bin_dir = Path(sys.executable).parent
    tool = bin_dir / "usv-command"
    usv_command = str(tool) if tool.exists() else (shutil.which("usv-command") or "usv-command")
    config = f"<({shlex.quote(sys.executable)} -m launch.usv.config usv_command)"
    exports = " ".join(f"{var}={shlex.quote(value)}" for var, value in command_env(settings).items())
    return [
        f"export {exports}",
        f"{shlex.quote(usv_command)} waypoints {config}",
        f"{shlex.quote(usv_command)} polygon --sides 8 --radius 400 {config}",
    ]


def write_outputs(result: MissionResult, settings: UsvSettings, out: Path) -> tuple[Path, Path]:
    """track.csv, events.csv and track.png in ``out``; returns the csv and png paths."""
    record = result.record
    track_csv, png = out / "track.csv", out / "track.png"
    record.write_csv(track_csv, out / "events.csv")
    deploy = transitions(record.events_named("DEPLOY_STATE", source="moos"))
    title = (f"USV mission: {settings.helm} + {settings.moosdb}, warp {settings.warp}, "
             f"{len(command_effects(record))} commands from shore")
    plotting(PLOT, "track.png").write_track_png(png, record.snapshot()[0], deploy, loiter_phases(record), bhv_waypoints(settings.bhv_file),
                    command_effects(record), title)
    return track_csv, png


def run_demo(args: argparse.Namespace) -> int:
    plotting(PLOT, "track.png")  # before any process starts
    out: Path = args.out.resolve()
    run_dir, socket_dir = fresh_run_dir(out, "usv-", MAX_SOCKET_BASE)
    settings = make_settings(args, run_dir, socket_dir)
    duration = args.duration if args.duration > 0 and not args.forever else None
    planned = len(parse_schedule(settings.schedule))
    print(f"USV mission: {settings.moosdb}, {settings.helm}, warp {settings.warp}, MOOS port {settings.moos_port}, "
          f"simulator port {settings.sim_port}; logs in {settings.log_dir}", flush=True)
    print(f"shore schedule: {settings.schedule}" + ("" if planned else " (no commands: send them from the "
                                                      "commander page or with usv-command)"), flush=True)
    mission = UsvMission(settings)
    started = time.monotonic()

    def body() -> None:
        mission.start()
        print("waiting for the frontseat interface to reach COMMAND ...", flush=True)
        urls = mission.liaison_urls()
        print("web pages of this run (goby-liaison): " + ", ".join(f"{view} {url}" for view, url in urls.items()),
              flush=True)
        # its port is settled (make_settings): no wait for a second page's start on a loaded machine
        host = "127.0.0.1" if settings.liaison_address in ("", "0.0.0.0", "::") else settings.liaison_address
        topside = liaison_page_urls(f"http://{host}:{settings.topside_liaison_port}")
        print("topside page (goby-liaison, commands over the satellite link): "
              + ", ".join(f"{view} {url}" for view, url in topside.items()), flush=True)
        if mission.wait_for_command() is not None:
            print(f"the vehicle is under helm command. Command it from the browser: {topside['commander']} "
                  f"(over the satellite link) or {urls['commander']} (the shore's interprocess leg)\n"
                  "or, in another terminal (bash):\n"
                  + "\n".join(f"  {line}" for line in command_lines(settings)), flush=True)
        mission.run(duration, lambda t: print(progress_line(mission.record, t, duration), flush=True))

    result, failure = run_mission(mission, body, run_dir, socket_dir)
    out.mkdir(parents=True, exist_ok=True)
    track_csv, png = write_outputs(result, settings, out)
    print(summary_text(result, bhv_waypoints(settings.bhv_file)), flush=True)
    print(f"wrote {track_csv}, {out / 'events.csv'} and {png} ({time.monotonic() - started:.0f} s real time)")
    print("\n".join(logs_lines(settings.log_dir, result.logs)), flush=True)
    clean = all(o.clean for o in result.outcomes)
    return 0 if failure is None and clean else 1


def main(argv: list[str] | None = None) -> int:
    return demo_main(build_parser(), run_demo, "usv-demo", argv)


if __name__ == "__main__":
    sys.exit(main())
