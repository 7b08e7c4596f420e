"""``python -m launch.usv.demo`` (``make demo``): run the USV mission headless and show what the vehicle did.

Starts every process of ``launch/usv/usv.launch`` with generated configs, lets the shore script command
the vehicle (loiter on a hexagon, then the waypoints, then an octagon of radius 400), records the track
through a MOOS client and a portal subscriber, then writes ``track.csv``, ``events.csv`` and ``track.png``
into the output directory and prints a summary. Exit status 0 only if the mission ran and every process
stopped cleanly.
"""

from __future__ import annotations

import argparse
import logging
import shutil
import signal
import socket
import sys
import tempfile
import time
from pathlib import Path

from gateway.logsetup import add_verbosity_argument, configure_logging
from launch.config import free_tcp_port
from launch.errors import LaunchError
from launch.usv.analysis import bhv_waypoints, command_effects, loiter_phases, transitions
from launch.usv.mission import MissionResult, UsvMission, choose_program
from launch.usv.plot import write_track_png
from launch.usv.settings import DEFAULT_SCHEDULE, KAUAI_ORIGIN, UsvSettings
from launch.usv.summary import progress_line, summary_text

log = logging.getLogger(__name__)

DEFAULT_DURATION_S = 1400.0
DEFAULT_WARP = 20
MAX_SOCKET_BASE = 90  # AF_UNIX paths are limited to ~107 bytes


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m launch.usv.demo", description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=DEFAULT_DURATION_S,
                        help=f"sim seconds to run after the helm takes command (default {DEFAULT_DURATION_S:g}; "
                        "0 = until Ctrl-C)")
    parser.add_argument("--forever", action="store_true", help="run until Ctrl-C or SIGTERM (same as --duration 0)")
    parser.add_argument("--warp", type=int, default=DEFAULT_WARP, help=f"time warp (default {DEFAULT_WARP})")
    parser.add_argument("--out", type=Path, default=Path("out"), help="output directory (default ./out)")
    parser.add_argument("--moosdb", choices=("auto", "real", "ours"), default="auto",
                        help="MOOSDB when on PATH (auto), force it (real) or our moos-db (ours)")
    parser.add_argument("--helm", choices=("auto", "real", "ours"), default="auto",
                        help="pHelmIvP when on PATH (auto), force it (real) or our ivp-helm (ours)")
    parser.add_argument("--schedule", default=DEFAULT_SCHEDULE,
                        help=f"shore commands, T:waypoints / T:polygon:SIDES:RADIUS (default {DEFAULT_SCHEDULE})")
    parser.add_argument("--origin", default=f"{KAUAI_ORIGIN[0]},{KAUAI_ORIGIN[1]}", help="lat,lon of the local grid")
    parser.add_argument("--moos-port", type=int, default=0, help="MOOSDB port (default 9001 if free)")
    parser.add_argument("--sim-port", type=int, default=0, help="frontseat simulator port (default 55001 if free)")
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
        return free_tcp_port()


def make_settings(args: argparse.Namespace, run_dir: Path, socket_dir: Path) -> UsvSettings:
    lat, lon = (float(v) for v in args.origin.split(","))
    return UsvSettings(
        run_dir=run_dir,
        warp=args.warp,
        lat_origin=lat,
        lon_origin=lon,
        moos_port=_port(args.moos_port, 9001),
        sim_port=_port(args.sim_port, 55001),
        moosdb=choose_program(args.moosdb, "MOOSDB", "moos-db"),
        helm=choose_program(args.helm, "pHelmIvP", "ivp-helm"),
        schedule=args.schedule,
        socket_name=str(socket_dir / "goby_usv"),
    )


def write_outputs(result: MissionResult, settings: UsvSettings, out: Path) -> tuple[Path, Path]:
    """track.csv, events.csv and track.png in ``out``; returns the csv and png paths."""
    record = result.record
    track_csv, png = out / "track.csv", out / "track.png"
    record.write_csv(track_csv, out / "events.csv")
    deploy = transitions(record.events_named("DEPLOY_STATE", source="moos"))
    title = (f"USV mission: {settings.helm} + {settings.moosdb}, warp {settings.warp}, "
             f"{len(command_effects(record))} commands from shore")
    write_track_png(png, record.snapshot()[0], deploy, loiter_phases(record), bhv_waypoints(settings.bhv_file),
                    command_effects(record), title)
    return track_csv, png


def run_demo(args: argparse.Namespace) -> int:
    out: Path = args.out.resolve()
    run_dir = out / "run"
    if run_dir.exists():
        shutil.rmtree(run_dir)
    socket_dir = run_dir if len(str(run_dir)) < MAX_SOCKET_BASE else Path(tempfile.mkdtemp(prefix="usv-", dir="/tmp"))
    settings = make_settings(args, run_dir, socket_dir)
    duration = args.duration if args.duration > 0 and not args.forever else None
    print(f"USV mission: {settings.moosdb}, {settings.helm}, warp {settings.warp}, MOOS port {settings.moos_port}, "
          f"simulator port {settings.sim_port}; logs in {settings.log_dir}", flush=True)
    mission = UsvMission(settings)
    previous = {s: signal.signal(s, lambda *_: mission.stop_event.set()) for s in (signal.SIGINT, signal.SIGTERM)}
    failure = None
    started = time.monotonic()
    try:
        mission.start()
        print("waiting for the frontseat interface to reach COMMAND ...", flush=True)
        mission.run(duration, lambda t: print(progress_line(mission.record, t, duration), flush=True))
    except LaunchError as exc:
        failure = str(exc)
        print(f"demo: {exc}", file=sys.stderr, flush=True)
    finally:
        result = mission.stop(failure)
        for s, handler in previous.items():
            signal.signal(s, handler)
        if socket_dir != run_dir:
            shutil.rmtree(socket_dir, ignore_errors=True)
    out.mkdir(parents=True, exist_ok=True)
    track_csv, png = write_outputs(result, settings, out)
    print(summary_text(result, bhv_waypoints(settings.bhv_file)), flush=True)
    print(f"wrote {track_csv}, {out / 'events.csv'} and {png} ({time.monotonic() - started:.0f} s real time)")
    clean = all(o.clean for o in result.outcomes)
    return 0 if failure is None and clean else 1


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    configure_logging(args.verbose, "usv-demo")
    try:
        return run_demo(args)
    except LaunchError as exc:
        print(f"demo: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
