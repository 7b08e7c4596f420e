"""Helm benchmark: cost of one decision iteration, and the helm process's CPU per simulated second beside pHelmIvP.

``python -m bench.bench_helm [--warp 10] [--seconds 20] [--settle 5] [--runs N] [--python-root DIR] [--no-live]``

**Core** (no MOOS): the helm core is driven directly at AppTick 4 against a small kinematic vehicle (turn rate
30 deg/s, acceleration 0.5 m/s^2), so the figures are deterministic: wall-clock microseconds per iteration and how
closely the track follows the plan.

**Live** (the helm as a process): each helm gets its own ``moos-db`` and the same scripted NAV_* feed, posted into
every DB at the same moment (one client per DB): a vehicle going round a circle of radius 150 m at 1.5 m/s, the
variables the frontseat translation posts (NAV_X/Y/LAT/LONG/Z/DEPTH/HEADING/YAW/SPEED), once per simulated second
as the course's simulator does. The mission is the USV's: ``behaviors/usv.bhv``, AppTick 1, CommsTick 4,
``course:0:359:360``, ``speed:0:2:41``, at ``--warp`` (default 10). The helms run side by side, so they see the same
machine load: ``ivp-helm`` from this checkout, ``ivp-helm`` from each ``--python-root DIR`` (another checkout, e.g.
``git worktree add /tmp/helm-before c985fb0``; its code on this interpreter, against this checkout's moos-db), and
``pHelmIvP`` when it is found (``$MOOS_IVP_BIN``, then PATH). Once every helm has posted DESIRED_SPEED, ``--settle``
seconds pass, then a window of ``--seconds`` real seconds gives per helm:

- CPU milliseconds per simulated second (utime + stime of every thread, from ``schedstat``: ``bench/platform_proc.py``)
  and the ratio to pHelmIvP;
- iterations (IVPHELM_STATE postings), postings and DESIRED_SPEED postings per simulated second, from a client that
  registers for everything the helm posts (``*`` from the helm's name);
- private memory at the end of the window.

pHelmIvP and the real MOOS programs listen on every address, so with pHelmIvP found the benchmark re-executes itself
inside a private network namespace (``unshare -n``, loopback up) and runs every helm there; without it (or without
``unshare``) the pHelmIvP column is left out and the reason printed.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import statistics
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from tempfile import TemporaryDirectory

from behaviors.helm.helm import Helm
from behaviors.helm.testing import helm_from_text
from behaviors.testing import ORIGIN, write_helm_mission
from bench.netns import NETNS_FLAG, reexec_in_netns
from bench.platform_proc import ProcSample, process_cpu_between, sample
from bench.progress import progress
from bench.stats import markdown_table
from gateway.moos import MoosClock, comms
from gateway.moos.testing import MoosDBProcess, private_netns
from util.geodesy import UTMGeodesy
from util.process import ChildProcess

REPO = Path(__file__).resolve().parents[1]
MIB = 2**20
HELM_NAME = "pHelmIvP"  # both helms connect under pHelmIvP's name and read its block
NAV_VARS = ("NAV_X", "NAV_Y", "NAV_LAT", "NAV_LONG", "NAV_Z", "NAV_DEPTH", "NAV_HEADING", "NAV_YAW", "NAV_SPEED")
CIRCLE_RADIUS_M = 150.0
CIRCLE_SPEED = 1.5
READY_TIMEOUT_S = 60.0

SURVEY = """\
Behavior = BHV_Waypoint
{
  name = survey
  speed = 2.0
  capture_radius = 5
  slip_radius = 0
  points = 40,0:40,50:-20,50:-20,10
}
"""



# ---- core: one iteration, no MOOS -----------------------------------------------------------------------------
class Vehicle:
    def __init__(self, x: float = 0.0, y: float = 0.0, heading: float = 0.0) -> None:
        self.x, self.y, self.heading, self.speed = x, y, heading, 0.0
        self.track: list[tuple[float, float]] = []

    def step(self, dt: float, heading: float, speed: float) -> None:
        err = (heading - self.heading + 180) % 360 - 180
        self.heading = (self.heading + max(-30 * dt, min(30 * dt, err))) % 360
        self.speed += max(-0.5 * dt, min(0.5 * dt, speed - self.speed))
        self.x += self.speed * math.sin(math.radians(self.heading)) * dt
        self.y += self.speed * math.cos(math.radians(self.heading)) * dt
        self.track.append((self.x, self.y))


def make_helm(bhv_text: str, speed_max: str = "4") -> Helm:
    return helm_from_text(bhv_text, ("course:0:359:360", f"speed:0:{speed_max}:41"), ownship="bench",
                          where="bench", start_engaged="true")


def run(helm: Helm, vehicle: Vehicle, seconds: float, pokes: dict[str, str] | None = None) -> float:
    """Simulate; returns the mean wall-clock cost of one helm iteration in microseconds."""
    t, desired, cost, n = 0.0, {"DESIRED_HEADING": 0.0, "DESIRED_SPEED": 0.0}, 0.0, 0
    helm.startup(t)
    for var, poke in (pokes or {}).items():
        helm.handle_mail(var, poke, t, "bench", t)
    while t < seconds:
        for var, value in (("NAV_X", vehicle.x), ("NAV_Y", vehicle.y), ("NAV_HEADING", vehicle.heading),
                           ("NAV_SPEED", vehicle.speed)):
            helm.handle_mail(var, value, t, "sim", t)
        start = time.perf_counter()
        posts = helm.iterate(t)
        cost += time.perf_counter() - start
        n += 1
        for post in posts:
            if post.var in desired and isinstance(post.value, float):
                desired[post.var] = post.value
        for _ in range(5):
            vehicle.step(0.05, desired["DESIRED_HEADING"], desired["DESIRED_SPEED"])
        t += 0.25
    return 1e6 * cost / n


def core_table() -> str:
    rows = []
    helm, vehicle = make_helm(SURVEY), Vehicle()
    us = run(helm, vehicle, 200)
    misses = [min(math.hypot(x - px, y - py) for x, y in vehicle.track)
              for px, py in [(40, 0), (40, 50), (-20, 50), (-20, 10)]]
    rows.append(["waypoint survey, 4 points", f"{us:.0f}", "closest approach (m): " +
                 ", ".join(f"{m:.1f}" for m in misses) + " (capture radius 5)"])
    helm = make_helm((REPO / "behaviors" / "usv.bhv").read_text(), "2")
    vehicle = Vehicle(0, -120, 0)
    helm.handle_mail("POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=60,pts=6", 0, "bench", 0)
    us = run(helm, vehicle, 900)
    radii = [math.hypot(x, y) for x, y in vehicle.track[len(vehicle.track) // 3:]]
    rows.append(["usv.bhv loiter, hexagon r=60", f"{us:.0f}",
                 f"ring radius min/mean/max (m): {min(radii):.1f}/{sum(radii) / len(radii):.1f}/{max(radii):.1f}"
                 " (edge 52.0, vertex 60.0)"])
    return markdown_table(["scenario", "us/iter", "accuracy"], rows)


# ---- live: the helm processes on a scripted feed --------------------------------------------------------------
@dataclass
class HelmSide:
    """One helm under test: its label, how to start it, and (once running) its DB, process and observer."""

    label: str
    command: list[str]
    env: dict[str, str]
    work: Path
    after_mission: list[str] = field(default_factory=list)  # arguments after the mission file
    db: MoosDBProcess | None = None
    proc: ChildProcess | None = None
    watch: Watch | None = None
    feed: comms | None = None


@dataclass
class SideFigures:
    cpu_ms_per_sim_s: float
    iterations_per_sim_s: float
    posts_per_sim_s: float
    desired_per_sim_s: float
    private_mib: float
    last_state: str


class Watch:
    """A client on one DB that counts what the helm posts (``*`` from the helm's name), on its own comms thread."""

    def __init__(self, port: int, clock: MoosClock) -> None:
        self.counts: dict[str, int] = {}
        self.last_state = ""
        self._lock = threading.Lock()
        self.client = comms(clock=clock)
        self.client.set_on_connect_callback(lambda: self.client.register("*", HELM_NAME, 0.0))
        self.client.set_on_mail_callback(self._on_mail)
        self.client.run("127.0.0.1", port, "bench_helm_watch")
        if not self.client.wait_until_connected(10_000):
            self.client.close(False)
            raise TimeoutError(f"the benchmark's watch client could not connect to the DB on port {port}")

    def _on_mail(self) -> bool:
        with self._lock:
            for msg in self.client.fetch():
                if msg.source() != HELM_NAME:
                    continue
                key = msg.key()
                self.counts[key] = self.counts.get(key, 0) + 1
                if key == "IVPHELM_STATE":
                    self.last_state = msg.string()
        return True

    def snapshot(self) -> dict[str, int]:
        with self._lock:
            return dict(self.counts)

    def close(self) -> None:
        self.client.close(False)


def nav_at(t: float, geodesy: UTMGeodesy) -> list[tuple[str, float]]:
    """The scripted vehicle at simulated time ``t``: clockwise round a circle about the origin."""
    angle = CIRCLE_SPEED * t / CIRCLE_RADIUS_M
    x, y = CIRCLE_RADIUS_M * math.sin(angle), CIRCLE_RADIUS_M * math.cos(angle)
    heading = (math.degrees(angle) + 90.0) % 360.0
    lat, lon = geodesy.to_geo(x, y)
    values = {"NAV_X": x, "NAV_Y": y, "NAV_LAT": lat, "NAV_LONG": lon, "NAV_Z": 0.0, "NAV_DEPTH": 0.0,
              "NAV_HEADING": heading, "NAV_YAW": -math.radians(heading), "NAV_SPEED": CIRCLE_SPEED}
    return [(var, values[var]) for var in NAV_VARS]


class Feeder:
    """Posts the scripted NAV_* into every DB once per simulated second (the same values, one client per DB)."""

    def __init__(self, clients: Sequence[comms], warp: float) -> None:
        self.clients = list(clients)
        self.warp = warp
        self.geodesy = UTMGeodesy(*ORIGIN)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="bench-helm-feeder", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def _run(self) -> None:
        period = 1.0 / self.warp
        start = time.monotonic()
        tick = 0
        while not self._stop.wait(max(0.0, start + tick * period - time.monotonic())):
            posts = nav_at(float(tick), self.geodesy)
            for client in self.clients:
                for var, value in posts:
                    client.notify(var, value)
            tick += 1

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)


def find_phelmivp() -> tuple[str | None, str]:
    """The path of pHelmIvP (``$MOOS_IVP_BIN``, then PATH), or None and why not."""
    directory = os.environ.get("MOOS_IVP_BIN", "")
    if directory and os.access(Path(directory) / "pHelmIvP", os.X_OK):
        return str(Path(directory) / "pHelmIvP"), ""
    on_path = shutil.which("pHelmIvP")
    if on_path:
        return on_path, ""
    return None, f"pHelmIvP is neither in $MOOS_IVP_BIN ({directory or 'unset'}) nor on PATH"


def python_helm(root: Path, label: str, work: Path) -> HelmSide:
    """``ivp-helm`` from checkout ``root`` on this interpreter."""
    env = dict(os.environ, PYTHONPATH=str(root))
    return HelmSide(label, [sys.executable, "-m", "behaviors.apps.ivp_helm"], env, work)


@contextmanager
def running_sides(sides: Sequence[HelmSide], warp: float) -> Iterator[Feeder]:
    """Start a moos-db, a feed client and a watch per side, the feeder, then the helms; stop everything on exit."""
    clock = MoosClock(warp)
    bhv = REPO / "behaviors" / "usv.bhv"
    with ExitStack() as stack:
        for side in sides:
            side.work.mkdir(parents=True, exist_ok=True)
            side.db = stack.enter_context(MoosDBProcess(side.work, community="usv", warp=warp))
            feed = comms(clock=clock)
            feed.run("127.0.0.1", side.db.port, "bench_helm_feed")
            stack.callback(feed.close, True)
            if not feed.wait_until_connected(10_000):
                raise TimeoutError(f"the feed client could not connect to {side.label}'s DB")
            side.feed = feed
            side.watch = Watch(side.db.port, clock)
            stack.callback(side.watch.close)
        feeder = Feeder([side.feed for side in sides if side.feed is not None], warp)
        feeder.start()
        stack.callback(feeder.stop)
        for side in sides:
            assert side.db is not None
            mission = write_helm_mission(side.work, side.db.port, bhv, warp=warp, community="usv", max_speed="2",
                                         app_tick=1, name="usv.moos")
            side.proc = stack.enter_context(ChildProcess([*side.command, str(mission), *side.after_mission], side.work / "helm.log",
                                                         name=side.label, cwd=side.work, env=side.env))
        yield feeder


def wait_driving(sides: Sequence[HelmSide]) -> None:
    deadline = time.monotonic() + READY_TIMEOUT_S
    for side in sides:
        assert side.watch is not None and side.proc is not None
        while not side.watch.snapshot().get("DESIRED_SPEED"):
            if not side.proc.running:
                raise RuntimeError(f"{side.label} exited:\n{side.proc.output()[-2000:]}")
            if time.monotonic() > deadline:
                raise TimeoutError(f"{side.label} posted no DESIRED_SPEED within {READY_TIMEOUT_S:.0f} s:\n"
                                   f"{side.proc.output()[-2000:]}")
            time.sleep(0.2)


def measure_live(sides: Sequence[HelmSide], warp: float, seconds: float, settle: float) -> dict[str, SideFigures]:
    with running_sides(sides, warp):
        wait_driving(sides)
        time.sleep(settle)
        before: dict[str, tuple[ProcSample | None, dict[str, int]]] = {}
        for side in sides:
            assert side.proc is not None and side.watch is not None
            before[side.label] = (sample(side.proc.pid), side.watch.snapshot())
        start = time.monotonic()
        time.sleep(seconds)
        after = {side.label: (sample(side.proc.pid), side.watch.snapshot())
                 for side in sides if side.proc is not None and side.watch is not None}
        sim_s = (time.monotonic() - start) * warp
        time.sleep(0.5)  # postings of the window's last iteration reach the watch
        out = {}
        for side in sides:
            assert side.watch is not None
            (first, counts0), (last, _) = before[side.label], after[side.label]
            if last is None:
                raise RuntimeError(f"{side.label} ended during the window")
            counts1 = after[side.label][1]
            posts = sum(counts1.values()) - sum(counts0.values())

            def rate(var: str, c0: dict[str, int] = counts0, c1: dict[str, int] = counts1) -> float:
                return (c1.get(var, 0) - c0.get(var, 0)) / sim_s

            out[side.label] = SideFigures(1000.0 * process_cpu_between(first, last) / sim_s,
                                          rate("IVPHELM_STATE"), posts / sim_s, rate("DESIRED_SPEED"),
                                          last.private_bytes / MIB, side.watch.last_state)
    return out


def live_table(runs: list[dict[str, SideFigures]], reference: str | None) -> str:
    def cell(values: Sequence[float], fmt: str) -> str:
        mid = statistics.median(values)
        text = format(mid, fmt)
        return text if len(values) == 1 else f"{text} ({format(min(values), fmt)}-{format(max(values), fmt)})"

    header = ["helm", "CPU ms/sim s", "vs pHelmIvP", "iterations/sim s", "postings/sim s", "DESIRED_SPEED/sim s",
              "private MiB", "state"]
    rows = []
    for label in runs[0]:
        figs = [run[label] for run in runs]
        cpu = [f.cpu_ms_per_sim_s for f in figs]
        ratio = "-"
        if reference is not None and label != reference:
            ratio = cell([f.cpu_ms_per_sim_s / run[reference].cpu_ms_per_sim_s for f, run in zip(figs, runs,
                                                                                                  strict=True)], ".2f")
        rows.append([label, cell(cpu, ".2f"), ratio, cell([f.iterations_per_sim_s for f in figs], ".2f"),
                     cell([f.posts_per_sim_s for f in figs], ".1f"), cell([f.desired_per_sim_s for f in figs], ".2f"),
                     cell([f.private_mib for f in figs], ".1f"), ",".join(sorted({f.last_state for f in figs}))])
    return markdown_table(header, rows)


# ---- the private network namespace ----------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="python -m bench.bench_helm", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--warp", type=float, default=10.0, help="MOOSTimeWarp of the live part (default 10)")
    parser.add_argument("--seconds", type=float, default=20.0, help="real seconds measured per run (default 20)")
    parser.add_argument("--settle", type=float, default=5.0, help="real seconds after the first DESIRED_SPEED")
    parser.add_argument("--runs", type=int, default=1, help="live runs; the table gives the median and range")
    parser.add_argument("--python-root", type=Path, action="append", default=[],
                        help="also run ivp-helm from this checkout (repeatable)")
    parser.add_argument("--no-live", action="store_true", help="only the core (no MOOS) table")
    parser.add_argument("--no-core", action="store_true", help="only the live table")
    parser.add_argument(NETNS_FLAG, action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not (0 < args.warp <= 100 and args.seconds > 0 and args.settle >= 0 and args.runs >= 1):
        parser.error("need 0 < --warp <= 100, --seconds > 0, --settle >= 0 and --runs >= 1")
    for root in args.python_root:
        if not (root / "behaviors" / "apps" / "ivp_helm.py").is_file():
            parser.error(f"--python-root {root}: no behaviors/apps/ivp_helm.py there")
    phelmivp, why_not = (None, "--no-live") if args.no_live else find_phelmivp()
    if phelmivp is not None and not args.in_netns and not private_netns():
        code = reexec_in_netns("bench.bench_helm", argv, "pHelmIvP", "pHelmIvP listens on all addresses")
        if code is not None:
            return code
        phelmivp, why_not = None, "no private network namespace"
    if not args.no_core:
        print(core_table(), flush=True)
    if args.no_live:
        return 0
    if phelmivp is None:
        progress(f"(pHelmIvP column left out: {why_not})")
    runs: list[dict[str, SideFigures]] = []
    with TemporaryDirectory(prefix="bench_helm_") as tmp:
        for index in range(args.runs):
            work = Path(tmp) / f"run{index}"
            sides = [python_helm(REPO, "ivp-helm", work / "ivp-helm")]
            for n, root in enumerate(args.python_root):
                sides.append(python_helm(root.resolve(), f"ivp-helm @ {root}", work / f"python-root-{n}"))
            if phelmivp is not None:
                # a MOOS app takes its name from argv[0] unless aliased: the full path would not find its block
                sides.append(HelmSide("pHelmIvP", [phelmivp], dict(os.environ), work / "pHelmIvP",
                                      [f"--alias={HELM_NAME}"]))
            progress(f"live run {index + 1}/{args.runs}: {', '.join(s.label for s in sides)} at warp {args.warp:g}, "
                     f"{args.seconds:g} s window")
            runs.append(measure_live(sides, args.warp, args.seconds, args.settle))
    print(f"\nUSV mission (behaviors/usv.bhv, AppTick 1) on a scripted NAV_* feed at warp {args.warp:g}, "
          f"{args.seconds:g} s windows, {args.runs} run(s):")
    print(live_table(runs, "pHelmIvP" if phelmivp is not None else None))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
