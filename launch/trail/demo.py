"""``python -m launch.trail.demo`` (``make demo``): run the trail mission headless and show what the fleet did.

Starts all.launch's platforms (topside, USV, N AUVs, each a nested goby-launch with generated configs), sends the
USV commands from the topside over the satellite link (loiter on a hexagon, then the waypoints) and RECOVER from
the USV over the acoustic link (or lets homework 3's helm send it, ``--usv-helm goby``) and counts both links'
datagrams. Every platform logs (goby-logger, moos-logger: ``<out>/run/logs/<platform>``); after the run the
vehicles' tracks and events are read from those logs, ``trail.png``, ``trail_tracks.csv`` and ``trail_events.csv``
are written into the output directory and a summary is printed, with where the logs are and the command that turns
them into MCAP for Foxglove. Exit status 0 only if the mission ran and every process stopped cleanly.

``--acomms-loss 0.2 --acomms-delay 1-3 --satellite-loss 0.05 --satellite-outage 30`` impair the links: every
modem driver of the link applies the channel to what it receives (our ``channel_model`` extension of the driver
block, docs/intervehicle.md "Lossy channels"); the summary prints the channels and, per link, the commands sent,
acked and expired.

``--hosts`` runs every platform on its own host: a Linux network namespace with its own address on a private
bridge (``launch.hosts``; root only), each platform's goby-launch inside it with configs on that address; the links'
multicast groups cross the bridge. ``--split-usv`` also puts the USV on two hosts joined by Goby's interprocess
TCP transport (docs/hosts.md).
"""

from __future__ import annotations

import argparse
import csv
import logging
import math
import sys
import time
from collections import Counter
from pathlib import Path

from gateway.goby.acomms.channel import MAX_DELAY_S, describe
from launch.demo import (
    add_run_arguments,
    demo_main,
    fresh_run_dir,
    plotting,
    run_mission,
    schedule_type,
    whole_number,
)
from launch.errors import LaunchError
from launch.hosts import HostNetwork, unavailable
from launch.mission import choose_program
from launch.record import MissionRecord, shifted
from launch.recorder import logs_lines
from launch.trail.analysis import command_outcomes, recover_outcome, trail_performance
from launch.trail.health_timeline import health_timeline_lines
from launch.trail.links import LinkMonitor
from launch.trail.mission import HostPlan, TrailMission, TrailResult, use_interprocess, with_free_ports
from launch.trail.operator import SCHEDULE_HELP, Operator, PortalWorker, parse_trail_schedule
from launch.trail.settings import CHANNEL_LINKS, TrailSettings, Vehicle, channel_text
from launch.trail.summary import link_accounting, progress_line, summary_text
from util.cli import HelpFormatter, bounded_number
from util.logsetup import add_verbosity_argument

log = logging.getLogger(__name__)
PLOT = "launch.trail.plot"  # matplotlib: the [demo] extra, imported by plotting() when a run draws

DEFAULT_AUVS = 4
DEFAULT_WARP = 10
DEFAULT_DURATION_S = 1500.0
DEFAULT_SCHEDULE = {"ivp": "0:polygon:6:200,500:waypoints,1000:recover", "goby": "none"}
MAX_SOCKET_BASE = 80  # AF_UNIX paths are limited to ~107 bytes


_positive_int = whole_number(1)
_auvs = whole_number(0, 64)
_schedule = schedule_type(parse_trail_schedule)
_probability = bounded_number(float, 0.0, 1.0)
_seconds = bounded_number(float, 0.0, MAX_DELAY_S)
_seed = whole_number(0)
#: Seconds between the starts of two outages when --X-outage gives only their duration.
DEFAULT_OUTAGE_PERIOD_S = 300.0


def _delay(text: str) -> tuple[float, float]:
    """``S`` or ``MIN-MAX`` seconds (each 0..3600, MIN <= MAX)."""
    low, sep, high = text.partition("-")
    if sep and not low:
        raise argparse.ArgumentTypeError(f"{text!r} is not S or MIN-MAX seconds, each >= 0")
    pair = (_seconds(low), _seconds(high)) if sep else (_seconds(text),) * 2
    if pair[0] > pair[1]:
        raise argparse.ArgumentTypeError(f"{text!r}: the shorter delay comes first (MIN-MAX)")
    return pair


def _outage(text: str) -> tuple[float, float]:
    """``DURATION`` or ``DURATION/PERIOD`` seconds (duration <= period)."""
    duration, sep, period = text.partition("/")
    pair = (_seconds(duration), bounded_number(float, 0.0, math.inf, low_inclusive=False)(period) if sep
            else DEFAULT_OUTAGE_PERIOD_S)
    if pair[0] > pair[1]:
        raise argparse.ArgumentTypeError(f"{text!r}: an outage cannot last longer than its period")
    return pair


def add_channel_arguments(parser: argparse.ArgumentParser) -> None:
    """``--{acomms,satellite}-{loss,delay,outage}`` and ``--channel-seed``."""
    group = parser.add_argument_group(
        "lossy links", "a simulated channel per link, applied on receive by every modem driver of the link (each "
        "draws on its own; times in sim seconds; docs/intervehicle.md \"Lossy channels\")")
    for link in CHANNEL_LINKS:
        group.add_argument(f"--{link}-loss", type=_probability, default=0.0, metavar="P",
                           help=f"probability (0..1) that a transmission on the {link} link (data or ack) is lost (default 0)")
        group.add_argument(f"--{link}-delay", type=_delay, default=(0.0, 0.0), metavar="S[-S]",
                           help=f"{link} delay in seconds, fixed or uniform in MIN-MAX, e.g. 1-3 (default 0)")
        group.add_argument(f"--{link}-outage", type=_outage, default=None, metavar="S[/PERIOD]",
                           help=f"the {link} link is dead for S seconds every PERIOD (default "
                           f"{DEFAULT_OUTAGE_PERIOD_S:g}) seconds")
    group.add_argument("--channel-seed", type=_seed, default=None, metavar="N",
                       help="seed of the channels' draws, for a reproducible run (default: random)")


def channel_settings(args: argparse.Namespace) -> dict[str, str]:
    """Per link, its channel_model text from the flags ("" for a lossless link)."""
    return {link: channel_text(getattr(args, f"{link}_loss"), getattr(args, f"{link}_delay"),
                                            getattr(args, f"{link}_outage"), args.channel_seed)
            for link in CHANNEL_LINKS}


def channel_descriptions(settings: TrailSettings) -> dict[str, str]:
    """Per link, its channel in words ("lossless" without one)."""
    out = {}
    for link in CHANNEL_LINKS:
        model = settings.channel_model(link)
        out[link] = "lossless" if model is None else describe(model)
    return out


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="python -m launch.trail.demo", description=__doc__.split("\n\n")[0])
    parser.add_argument("--auvs", type=_auvs, default=DEFAULT_AUVS, help=f"number of AUVs (default {DEFAULT_AUVS})")
    parser.add_argument("--warp", type=_positive_int, default=DEFAULT_WARP, help=f"time warp (default {DEFAULT_WARP})")
    parser.add_argument("--duration", type=float, default=DEFAULT_DURATION_S,
                        help=f"sim seconds after every vehicle is under command (default {DEFAULT_DURATION_S:g}; "
                        "0 = until Ctrl-C)")
    parser.add_argument("--usv-helm", choices=("ivp", "goby"), default="ivp",
                        help="ivp: the MOOS helm with usv.bhv, commanded from the topside; goby: homework 3's helm "
                        "(triangle, then RECOVER)")
    parser.add_argument("--schedule", type=_schedule, default=None,
                        help=f"{SCHEDULE_HELP} (default {DEFAULT_SCHEDULE['ivp']}; none with --usv-helm goby)")
    parser.add_argument("--east-duration", type=_positive_int, default=500, help="homework helm: east leg, s")
    parser.add_argument("--south-duration", type=_positive_int, default=200, help="homework helm: south leg, s")
    add_channel_arguments(parser)
    add_run_arguments(parser)
    parser.add_argument("--listen", default="127.0.0.1", metavar="ADDRESS",
                        help="address the liaison pages listen on (default 127.0.0.1). RISK: another address lets "
                        "anyone who can reach it watch all traffic and command the vehicles: the pages have no login")
    hosts = parser.add_argument_group("hosts", "one platform per host (root only; docs/hosts.md)")
    hosts.add_argument("--hosts", action="store_true",
                       help="run each platform in its own network namespace with its own address on a private "
                       "bridge; links, MOOSDBs, brokers and pages bind that address (--listen is then ignored)")
    hosts.add_argument("--split-usv", action="store_true",
                       help="with --hosts: the USV on two hosts, frontseat simulator and interface on one, broker, "
                       "MOOS and helm on the other, joined by Goby's interprocess TCP transport")
    parser.add_argument("--keep-going", action="store_true",
                        help="when a platform's process dies (its goby-launch then stops that platform), keep the "
                        "other platforms running; the summary says what died when (default: stop everything)")
    add_verbosity_argument(parser)
    return parser


def make_settings(args: argparse.Namespace, run_dir: Path, socket_dir: Path, console: str = "") -> TrailSettings:
    """The run's settings; with hosts, ``console`` (the bridge's address here) is where the demo joins the links'
    groups (each launcher's own variables put its configs on its host, ``HostPlan.environment``)."""
    channels = channel_settings(args)
    settings = TrailSettings(
        run_dir=run_dir,
        warp=args.warp,
        moosdb=choose_program(args.moosdb, "MOOSDB", "moos-db"),
        helm=choose_program(args.helm, "pHelmIvP", "ivp-helm"),
        usv_helm=args.usv_helm,
        liaison_address=args.listen,
        socket_dir=socket_dir,
        east_duration=args.east_duration,
        south_duration=args.south_duration,
        acomms_channel=channels["acomms"],
        satellite_channel=channels["satellite"],
        link_address=console or TrailSettings.link_address,
    )
    return with_free_ports(settings, args.auvs, prefer_course=True)


def write_csvs(records: dict[str, MissionRecord], operator: MissionRecord, out: Path) -> tuple[Path, Path]:
    """trail_tracks.csv (vehicle,t,x,y,depth,heading,speed) and trail_events.csv (vehicle,t,source,name,value,origin)."""
    tracks, events = out / "trail_tracks.csv", out / "trail_events.csv"
    with open(tracks, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["vehicle", "t", "x", "y", "depth", "heading", "speed"])
        for name, record in records.items():
            for s in record.snapshot()[0]:
                writer.writerow([name, f"{s.t:.2f}", f"{s.x:.2f}", f"{s.y:.2f}", _fmt(s.depth), _fmt(s.heading),
                                 _fmt(s.speed)])
    with open(events, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["vehicle", "t", "source", "name", "value", "origin"])
        for name, record in [*records.items(), ("operator", operator)]:
            for e in record.snapshot()[1]:
                writer.writerow([name, f"{e.t:.2f}", e.source, e.name, e.value, e.origin])
    return tracks, events


def _fmt(value: float | None) -> str:
    return "" if value is None else f"{value:.2f}"


def report(result: TrailResult, operator: MissionRecord, n_auvs: int, links: LinkMonitor | None, sim_seconds: float,
           out: Path, title: str, channels: dict[str, str] | None = None) -> str:
    """Analyse, write the CSVs and the picture, and return the summary text."""
    records = result.records
    operator = shifted(operator, result.t0)
    auvs = [Vehicle("auv", n_auvs, i) for i in range(n_auvs)]
    trails = [trail_performance(v, records[v.name], records["usv"]) for v in auvs
              if v.name in records and "usv" in records]
    commands = command_outcomes(operator, records)
    recovers = [recover_outcome(v.name, records[v.name]) for v in auvs if v.name in records]
    if not any(c.what == "recover" for c in commands) and all(r.commanded_at is None for r in recovers):
        recovers = []  # no RECOVER in this run (homework helm not at its end, none scheduled)
    out.mkdir(parents=True, exist_ok=True)
    write_csvs(records, operator, out)
    plotting(PLOT, "trail.png").write_trail_png(out / "trail.png", records, commands, recovers, trails, title)
    topside = records.get("topside")
    view = Counter(e.value for e in topside.events_named("node_status", "topside")) if topside is not None else None
    return summary_text(result, trails, commands, recovers, None if links is None else links.stats, sim_seconds,
                        None if links is None else links.error, None if view is None else dict(view),
                        link_accounting(operator, n_auvs),
                        channels)


def liaison_urls_line(settings: TrailSettings, n_auvs: int, hosts: HostPlan | None = None) -> str:
    """Where the platforms' goby-liaison pages are: the topside's commander (USVCommand over the satellite link)
    and every vehicle's scope, at port 50000 + platform id as in the course (on each host's address with hosts)."""
    default = "127.0.0.1" if settings.liaison_address in ("", "0.0.0.0", "::") else settings.liaison_address
    vehicles = [Vehicle("topside", n_auvs), Vehicle("usv", n_auvs), *(Vehicle("auv", n_auvs, i) for i in range(n_auvs))]
    where = {v.name: default if hosts is None else hosts.address(v) for v in vehicles}
    pages = [f"{v.name} http://{where[v.name]}:{v.liaison_port(settings)}/" for v in vehicles]
    return (f"web pages (goby-liaison): {', '.join(pages)}; command the USV from "
            f"http://{where['topside']}:{vehicles[0].liaison_port(settings)}/?_=/commander")


def _report(line: str) -> None:
    """The launcher's lines: deaths always, the rest with -v."""
    if "died" in line:
        print(line, flush=True)
    else:
        log.info("%s", line)


def run_demo(args: argparse.Namespace) -> int:
    plotting(PLOT, "trail.png")  # before any process starts
    if args.split_usv and not args.hosts:
        raise LaunchError("--split-usv needs --hosts")
    if not args.hosts:
        return _run_demo(args, None)
    reason = unavailable()
    if reason is not None:
        raise LaunchError(f"--hosts: {reason}")
    with HostNetwork(HostPlan.names(args.auvs, args.split_usv)) as network:
        plan = HostPlan.from_network(network, args.split_usv)
        print("hosts: " + ", ".join(f"{h.name} {h.address} ({h.netns})" for h in network.hosts.values())
              + f"; console {network.console} on bridge {network.bridge}"
              + ("; the USV on two hosts over Goby's interprocess TCP transport "
                 f"({plan.hosts['usv'].address}:{plan.broker_port})" if args.split_usv else ""), flush=True)
        return _run_demo(args, plan)


def _run_demo(args: argparse.Namespace, hosts: HostPlan | None) -> int:
    out: Path = args.out.resolve()
    run_dir, socket_dir = fresh_run_dir(out, "trail-", MAX_SOCKET_BASE)
    settings = make_settings(args, run_dir, socket_dir, "" if hosts is None else hosts.console)
    schedule = args.schedule if args.schedule is not None else DEFAULT_SCHEDULE[args.usv_helm]
    plan = parse_trail_schedule(schedule)
    duration = args.duration if args.duration > 0 else None
    n = args.auvs
    print(f"trail mission: topside, USV ({args.usv_helm} helm) and {n} AUVs; {settings.moosdb}, {settings.helm}, "
          f"warp {settings.warp}; MOOS ports {settings.moos_port_base}+id; logs in {run_dir / 'logs'}", flush=True)
    print(f"schedule: {schedule}", flush=True)
    channels = channel_descriptions(settings)
    print("channels: " + "; ".join(f"{link} {text}" for link, text in channels.items()), flush=True)
    mission = TrailMission(settings, n, report=_report, keep_going=args.keep_going, hosts=hosts)
    links = LinkMonitor(settings, n)
    mission.add_hook(links.poll)
    operator_record = MissionRecord()
    workers: list[PortalWorker] = []
    started = time.monotonic()
    sim_seconds = 0.0

    def body() -> None:
        nonlocal sim_seconds
        print(f"starting {len(mission.entries)} platforms ...", flush=True)
        mission.start()
        print(liaison_urls_line(settings, n, hosts), flush=True)
        topside = PortalWorker("topside", Vehicle("topside", n).ipc_base(settings), settings.warp)
        usv = PortalWorker("usv", Vehicle("usv", n).ipc_base(settings), settings.warp) if args.usv_helm == "ivp" else None
        workers.extend(w for w in (topside, usv) if w is not None)
        if hosts is not None:
            for worker, vehicle in ((topside, Vehicle("topside", n)), (usv, Vehicle("usv", n))):
                if worker is not None:
                    use_interprocess(worker, hosts.interprocess(vehicle, settings))
        for worker in workers:
            worker.start()
        operator = Operator(plan, operator_record, mission.clock, topside, usv)
        mission.add_hook(operator.poll)
        print(f"all platforms up after {time.monotonic() - started:.0f} s; waiting for every vehicle to reach "
              "COMMAND ...", flush=True)
        t0 = mission.wait_for_command(progress=lambda: print(progress_line(
            {k: r.record for k, r in mission.runs.items()}, 0, None), flush=True))
        if t0 is not None:
            print(f"every vehicle under helm command ({time.monotonic() - started:.0f} s real)", flush=True)
            operator.start(t0)
            mission.run(duration, lambda t: print(progress_line({k: r.record for k, r in mission.runs.items()}, t,
                                                                duration), flush=True))
            sim_seconds = mission.now() - t0

    def close_workers_and_links() -> None:
        for worker in workers:
            worker.close()
        links.poll()
        links.close()

    result, failure = run_mission(mission, body, run_dir, socket_dir, before_stop=close_workers_and_links)
    title = (f"Trail mission: USV ({args.usv_helm} helm) + {n} AUVs, {settings.helm} + {settings.moosdb}, "
             f"warp {settings.warp}, {sim_seconds:.0f} sim s")
    print(report(result, operator_record, n, links, sim_seconds, out, title, channels), flush=True)
    print("\n".join(health_timeline_lines(result.logs, settings.warp, result.origin + result.t0)), flush=True)
    real = time.monotonic() - started
    print(f"wrote {out / 'trail.png'}, {out / 'trail_tracks.csv'} and {out / 'trail_events.csv'} "
          f"({real:.0f} s real time)")
    print("\n".join(logs_lines(run_dir / "logs", [p for paths in result.logs.values() for p in paths])), flush=True)
    clean = all(o.clean for o in result.outcomes)
    return 0 if failure is None and clean and not result.deaths else 1


def main(argv: list[str] | None = None) -> int:
    return demo_main(build_parser(), run_demo, "trail-demo", argv)


if __name__ == "__main__":
    sys.exit(main())
