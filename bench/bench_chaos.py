"""Chaos soak of the USV or the trail mission: random SIGKILLs, restarts, recovery times, accounting, memory.

    python -m bench.bench_chaos [--mission usv|trail] [--auvs 2] [--duration 1800] [--warp 20] [--interval 20]
                                [--seed 1] [--out DIR] [--quick]

``--mission usv`` (default) runs ``launch/usv/usv.launch`` (every process, generated configs, the shore's command
schedule) at high warp. Every ``--interval`` seconds on average (exponential) it picks a random process, kills it
with SIGKILL and restarts it (``ProcessGroup.respawn``, what a supervising launcher does). ``--mission trail`` runs
the trail mission as all.launch does (topside, USV, ``--auvs`` AUVs, nested goby-launch per platform, started with
``GOBY_LAUNCH_RESPAWN``) and kills a random process of a random platform: its own launcher starts it again. Two
probes count messages end to end on the USV meanwhile:

- MOOS: a publisher posts ``CHAOS_SEQ`` 0, 1, 2, ... every 50 ms to moos-db, a subscriber reads them; each number
  is delivered, refused (``notify`` False) or reported undelivered (the on-undelivered callback);
- Goby interprocess: the same through goby-broker (group ``chaos_probe``), counted delivered, refused
  (``publish`` False while the portal knows the broker is gone) or reported (``portal.unsent``);

anything else is *lost silently*. A kill counts as recovered when the restarted process has stayed up 1 s, the
vehicle's NAV_X reaches the MOOSDB again (every vehicle's, in the trail mission) and both probes deliver again; the
recovery time is from the kill.
Prints one row per process: kills, recovery median/max, the probes' messages sent while it was down and how they
ended, and RSS at start and end (the latest instance). Exit 0 when nothing was lost silently and every kill
recovered.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import random
import signal
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic, TypeVar

from bench.stats import markdown_table
from gateway.goby.portal.testing import PortalClient
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos import comms
from gateway.moos.clock import MoosClock
from launch.apps.goby_launch import RESPAWN_VAR
from launch.process_group import LAUNCHED_LINE, ProcessGroup
from launch.trail.mission import TrailMission, with_free_ports
from launch.trail.settings import TrailSettings, Vehicle
from launch.usv.mission import UsvMission
from launch.usv.settings import UsvSettings
from util.cli import bounded_number
from util.logsetup import add_verbosity_argument, configure_logging
from util.process import free_port, handle_signals, pid_alive

log = logging.getLogger(__name__)

PROBE_PERIOD_S = 0.05
RECOVERY_TIMEOUT_S = 120.0


def rss_mib(pid: int) -> float | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        return None
    return None


@dataclass
class Ledger:
    """What became of each numbered probe message: sent at, delivered, refused, reported."""

    sent: dict[int, float] = field(default_factory=dict)
    delivered: set[int] = field(default_factory=set)
    refused: set[int] = field(default_factory=set)
    reported: set[int] = field(default_factory=set)
    last_delivery: float = 0.0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def deliver(self, n: int) -> None:
        with self.lock:
            self.delivered.add(n)
            self.last_delivery = time.monotonic()

    def lost(self) -> set[int]:
        with self.lock:
            return set(self.sent) - self.delivered - self.refused - self.reported


class MoosProbe:
    """CHAOS_SEQ through moos-db, and NAV_X freshness (the vehicle's data reaching the MOOSDB)."""

    def __init__(self, port: int, warp: float) -> None:
        self.ledger = Ledger()
        self.last_nav = 0.0
        self._stop = threading.Event()
        self._sub = comms(clock=MoosClock(warp))
        self._sub.set_on_connect_callback(lambda: self._sub.register("CHAOS_SEQ", 0) and self._sub.register("NAV_X", 0))
        self._sub.set_on_mail_callback(self._on_mail)
        self._pub = comms(clock=MoosClock(warp))
        self._pub.set_on_undelivered_callback(self._on_undelivered)
        # After a moos-db restart the queued numbers go once the reader is back (MOOS keeps no mail for a
        # client that has not registered yet, so otherwise they would be confirmed to nobody).
        self._pub.set_on_connect_callback(self._reader_back)
        self._sub.run("127.0.0.1", port, "uChaosSub")
        self._pub.run("127.0.0.1", port, "uChaosPub")
        self._thread = threading.Thread(target=self._publish, name="chaos-moos-probe", daemon=True)

    def _reader_back(self) -> None:
        deadline = time.monotonic() + 30
        while not self._sub.is_connected() and time.monotonic() < deadline and not self._stop.is_set():
            time.sleep(0.05)
        time.sleep(0.3)  # its registration is written right after it connects

    def _on_mail(self) -> None:
        for msg in self._sub.fetch():
            if msg.key() == "CHAOS_SEQ":
                self.ledger.deliver(int(msg.double()))
            elif msg.key() == "NAV_X":
                self.last_nav = time.monotonic()

    def _on_undelivered(self, messages: list) -> None:
        with self.ledger.lock:
            self.ledger.reported.update(int(m.double()) for m in messages if m.key() == "CHAOS_SEQ")

    def start(self) -> None:
        self._sub.wait_until_connected(20_000)
        self._pub.wait_until_connected(20_000)
        time.sleep(0.5)
        self._thread.start()

    def _publish(self) -> None:
        n = 0
        while not self._stop.wait(PROBE_PERIOD_S):
            with self.ledger.lock:
                self.ledger.sent[n] = time.monotonic()
            if not self._pub.notify("CHAOS_SEQ", float(n)):
                with self.ledger.lock:
                    self.ledger.refused.add(n)
            n += 1

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)
        time.sleep(1.0)  # the last numbers arrive
        self._pub.close()
        self._sub.close()


class PortalProbe:
    """The same count through goby-broker: one publishing and one subscribing portal, each on its own thread."""

    def __init__(self, platform: str, ipc_base: str) -> None:
        self.ledger = Ledger()
        self.cfg = InterProcessPortalConfig(platform=platform, socket_name=ipc_base)
        self._stop = threading.Event()
        self._ready = threading.Event()
        self.error: BaseException | None = None
        self._threads = [threading.Thread(target=self._guard, args=(self._subscribe,), name="chaos-portal-sub",
                                          daemon=True),
                         threading.Thread(target=self._guard, args=(self._publish,), name="chaos-portal-pub",
                                          daemon=True)]

    def _guard(self, body: Callable[[], None]) -> None:
        try:
            body()
        except BaseException as exc:  # noqa: BLE001 - reported in the summary
            self.error = exc
            log.exception("portal probe failed")

    def _subscribe(self) -> None:
        with PortalClient(self.cfg, "chaos_probe_sub") as client:
            client.subscribe("chaos_probe", str, lambda text: self.ledger.deliver(int(text)))
            client.wait_subscribed(30)
            self._ready.set()
            while not self._stop.is_set():
                client.poll(0.05)
            client.poll_until(lambda: False, 1.0)

    def _on_undelivered(self, lost: list[tuple[str, bytes]]) -> None:
        with self.ledger.lock:
            self.ledger.reported.update(int(payload.rstrip(b"\0")) for group, payload in lost if group == "chaos_probe")

    def _publish(self) -> None:
        self._ready.wait(30)
        with PortalClient(self.cfg, "chaos_probe_pub") as client:
            client.portal.on_undelivered = self._on_undelivered
            client.wait_ready(30)
            n = 0
            next_at = time.monotonic()
            while not self._stop.is_set():
                client.poll(max(0.0, next_at - time.monotonic()))
                if time.monotonic() < next_at:
                    continue
                next_at += PROBE_PERIOD_S
                with self.ledger.lock:
                    self.ledger.sent[n] = time.monotonic()
                if not client.publish("chaos_probe", str(n)):
                    with self.ledger.lock:
                        self.ledger.refused.add(n)
                n += 1

    def start(self) -> None:
        for thread in self._threads:
            thread.start()
        self._ready.wait(40)

    def stop(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(10)


@dataclass
class Kill:
    name: str
    at: float
    recovered_at: float | None = None


_Mission = TypeVar("_Mission", bound=UsvMission | TrailMission)


class _MissionTarget(Generic[_Mission]):
    """What the soak needs of a mission: start it until every vehicle is under command, stop it."""

    mission: _Mission
    command_timeout_s: float = 180.0

    def start(self) -> None:
        self.mission.start()
        self.mission.wait_for_command(self.command_timeout_s)

    def stop(self) -> None:
        self.mission.stop()


class UsvTarget(_MissionTarget[UsvMission]):
    """The USV mission as one flat process group: the soak kills a process and restarts it itself."""

    def __init__(self, args: argparse.Namespace, out: Path, socket_dir: Path) -> None:
        self.settings = UsvSettings(run_dir=out, warp=args.warp, moos_port=free_port(), sim_port=free_port(),
                                    liaison_port=free_port(), socket_name=str(socket_dir / "goby_usv"))
        self.mission = UsvMission(self.settings, report=log.info)
        self.log_dir = self.settings.log_dir
        self.probe_moos_port, self.probe_platform = self.settings.moos_port, self.settings.platform
        self.probe_ipc_base = self.settings.ipc_base

    def poll(self) -> None:
        self.mission.poll_logs()

    def _group(self) -> ProcessGroup:
        assert self.mission.group is not None
        return self.mission.group

    def processes(self) -> dict[str, int]:
        return {p.name: p.pid for p in self._group().processes if p.running}

    def kill(self, name: str) -> None:
        process = next(p for p in self._group().processes if p.name == name)
        process.child.send_signal(signal.SIGKILL)
        process.child.wait(10)
        self._group().respawn(process)

    def nav_since(self, kill: Kill, last_nav: float) -> bool:
        return last_nav > kill.at

    def back(self, name: str, kill: Kill) -> bool:
        process = next(p for p in self._group().processes if p.name == name)
        if not process.running:  # died again on its own (e.g. its peer was not back yet): restart it
            self._group().respawn(process)
            return False
        return time.monotonic() - process.started_at >= 1.0


class TrailTarget(_MissionTarget[TrailMission]):
    """The trail mission as all.launch runs it; every platform's goby-launch restarts what the soak kills."""

    command_timeout_s = 300.0

    def __init__(self, args: argparse.Namespace, out: Path, socket_dir: Path) -> None:
        base = TrailSettings(run_dir=out, warp=args.warp, socket_dir=socket_dir, schedule="none")
        self.settings = with_free_ports(base, args.auvs, prefer_course=False)
        self.mission = TrailMission(self.settings, args.auvs, report=log.info, extra_env={RESPAWN_VAR: "1000000"})
        self.log_dir = self.mission.log_dir
        usv = Vehicle("usv", args.auvs)
        self.probe_moos_port, self.probe_platform = usv.moos_port(self.settings), usv.name
        self.probe_ipc_base = usv.ipc_base(self.settings)
        self._killed_pid, self._killed_sim_t = 0, 0.0  # the last kill's victim and the sim time it died
        self._seen: dict[int, float] = {}  # when each new pid was first seen

    def poll(self) -> None:
        self.mission.poll()

    def processes(self) -> dict[str, int]:
        """The live programs under every platform's launcher, by name (``auv0.moos-db``), from its log."""
        assert self.mission.group is not None
        found: dict[str, int] = {}
        for launcher in self.mission.group.processes:
            for pid, name in LAUNCHED_LINE.findall(launcher.child.output()):
                found[name] = int(pid)  # the newest launch of each name wins
        return {name: pid for name, pid in found.items() if pid_alive(pid)}

    def kill(self, name: str) -> None:
        self._killed_pid, self._killed_sim_t = self.processes()[name], self.mission.clock.now()
        self._seen.clear()
        with contextlib.suppress(ProcessLookupError):
            os.kill(self._killed_pid, signal.SIGKILL)

    def nav_since(self, kill: Kill, last_nav: float) -> bool:
        """Every vehicle with a MOOSDB has had a NAV fix since the kill (the USV's is also the probe's)."""
        for run in self.mission.runs.values():
            nav, _ = run.record.snapshot()
            if run.logs.moos and (not nav or nav[-1].t <= self._killed_sim_t):
                return False
        return last_nav > kill.at

    def back(self, name: str, kill: Kill) -> bool:
        """Its launcher has started it again (a new pid under the same name) and it has been up 1 s."""
        pid = self.processes().get(name)
        if pid is None or pid == self._killed_pid:
            return False
        first_seen = self._seen.setdefault(pid, time.monotonic())
        return time.monotonic() - first_seen >= 1.0


def _wait_recovered(target: UsvTarget | TrailTarget, probes: tuple[MoosProbe, PortalProbe], kill: Kill) -> None:
    moos, portal = probes
    deadline = kill.at + RECOVERY_TIMEOUT_S
    while time.monotonic() < deadline:
        target.poll()
        fresh = target.nav_since(kill, moos.last_nav) and min(moos.ledger.last_delivery,
                                                                portal.ledger.last_delivery) > kill.at
        if target.back(kill.name, kill) and fresh:
            kill.recovered_at = time.monotonic()
            return
        time.sleep(0.05)


def run(args: argparse.Namespace) -> int:
    rng = random.Random(args.seed)
    out = Path(args.out or tempfile.mkdtemp(prefix="chaos_"))
    socket_dir = Path(tempfile.mkdtemp(prefix="cs", dir="/tmp"))
    target = (TrailTarget if args.mission == "trail" else UsvTarget)(args, out, socket_dir)
    kills: list[Kill] = []
    signals = contextlib.ExitStack()  # SIGINT/SIGTERM end the soak early; the previous handlers come back at the end
    stop = signals.enter_context(handle_signals())
    try:
        target.start()
        rss_start = {name: rss_mib(pid) for name, pid in target.processes().items()}
        probes = (MoosProbe(target.probe_moos_port, args.warp), PortalProbe(target.probe_platform,
                                                                            target.probe_ipc_base))
        for probe in probes:
            probe.start()
        print(f"chaos soak of the {args.mission} mission: {args.duration:g} s, warp {args.warp}, a kill every "
              f"~{args.interval:g} s; logs in {target.log_dir}", flush=True)
        end = time.monotonic() + args.duration
        while time.monotonic() < end and not stop.is_set():
            pause = min(rng.expovariate(1.0 / args.interval), max(0.0, end - time.monotonic()))
            wake = time.monotonic() + pause
            while time.monotonic() < wake and not stop.is_set():
                target.poll()
                time.sleep(0.05)
            if time.monotonic() >= end or stop.is_set():
                break
            names = sorted(n for n in target.processes()
                           if not args.victims or any(v in n for v in args.victims.split(",")))
            kill = Kill(rng.choice(names), time.monotonic())
            kills.append(kill)
            target.kill(kill.name)
            _wait_recovered(target, probes, kill)
            took = f"{kill.recovered_at - kill.at:.1f} s" if kill.recovered_at else "NOT recovered"
            print(f"{time.strftime('%H:%M:%S')} kill -9 {kill.name}: recovered in {took}", flush=True)
        rss_end = {name: rss_mib(pid) for name, pid in target.processes().items()}
        for probe in probes:
            probe.stop()
    finally:
        target.stop()
        signals.close()
    print(report(kills, probes, rss_start, rss_end, args))
    lost = sum(len(p.ledger.lost()) for p in probes)
    return 0 if lost == 0 and all(k.recovered_at for k in kills) else 1


def _window(kills: list[Kill], t: float) -> Kill | None:
    """The kill whose outage (kill to recovery) covers time ``t``, if any."""
    for kill in kills:
        if kill.at <= t <= (kill.recovered_at or kill.at + RECOVERY_TIMEOUT_S):
            return kill
    return None


def report(kills: list[Kill], probes: tuple[MoosProbe, PortalProbe], rss_start: dict[str, float | None],
           rss_end: dict[str, float | None], args: argparse.Namespace) -> str:
    rows = []
    for name in rss_start:
        mine = [k for k in kills if k.name == name]
        times = [k.recovered_at - k.at for k in mine if k.recovered_at]
        cells = [name, str(len(mine)), f"{statistics.median(times):.1f}" if times else "-",
                 f"{max(times):.1f}" if times else "-"]
        for probe in probes:
            ledger = probe.ledger
            with ledger.lock:
                during = [n for n, t in ledger.sent.items() if (k := _window(kills, t)) is not None and k.name == name]
                delivered = sum(n in ledger.delivered for n in during)
                refused = sum(n in ledger.refused for n in during)
                reported = sum(n in ledger.reported and n not in ledger.delivered for n in during)
            lost = len(during) - delivered - refused - reported
            cells.append(f"{len(during)}/{delivered}/{refused + reported}/{lost}")
        start, end = rss_start.get(name), rss_end.get(name)
        cells.append(f"{start:.0f} → {end:.0f}" if start and end else "-")
        rows.append(cells)
    totals = []
    for label, ledger in (("MOOS", probes[0].ledger), ("interprocess", probes[1].ledger)):
        with ledger.lock:
            sent, delivered = len(ledger.sent), len(ledger.delivered)
            refused, reported = len(ledger.refused), len(ledger.reported - ledger.delivered)
        totals.append(f"{label} probe: sent {sent}, delivered {delivered}, refused {refused}, reported {reported}, "
                      f"lost silently {len(ledger.lost())}")
    header = ["process", "kills", "recovery median s", "recovery max s", "MOOS probe sent/delivered/reported/lost",
              "interprocess probe sent/delivered/reported/lost", "RSS MiB start → end"]
    return "\n".join([f"Chaos soak of the {args.mission} mission: {args.duration:g} s real time at warp {args.warp}, "
                      f"{len(kills)} kills "
                      f"(seed {args.seed}); probe counts are messages sent while that process was down",
                      markdown_table(header, rows), *totals])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.bench_chaos", description=__doc__.split("\n\n")[0])
    parser.add_argument("--mission", choices=("usv", "trail"), default="usv", help="which mission (default usv)")
    parser.add_argument("--auvs", type=bounded_number(int, 0, 16), default=2, help="AUVs of the trail mission (2)")
    parser.add_argument("--duration", type=float, default=1800.0, help="real seconds of chaos (default 1800)")
    parser.add_argument("--warp", type=int, default=20, help="time warp of the mission (default 20)")
    parser.add_argument("--interval", type=float, default=20.0, help="mean real seconds between kills (default 20)")
    parser.add_argument("--seed", type=int, default=1, help="random seed (which process, when)")
    parser.add_argument("--out", help="run directory (default a new temporary one)")
    parser.add_argument("--victims", default="", help="comma-separated parts of process names to kill "
                        "(default: any process of the mission)")
    parser.add_argument("--quick", action="store_true", help="a smoke run: 90 s, a kill every ~10 s")
    add_verbosity_argument(parser)
    args = parser.parse_args(argv)
    if args.quick:
        args.duration, args.interval = 90.0, 10.0
    configure_logging(args.verbose, "bench_chaos")
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
