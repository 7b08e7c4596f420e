"""Per-vehicle cost: the Python vehicle against the C++ one (Goby3 + MOOS-IvP), CPU and memory per process.

``python -m bench.bench_platform [--warp 1,10] [--seconds 30] [--settle 5] [--runs N]``. Per warp and run it
starts the USV mission's five vehicle processes from ``launch/usv/usv.launch`` with the configs its lines generate
(goby-broker, frontseat-sim, frontseat-interface with its embedded MOOS translation, moos-db, ivp-helm) and, when
the real programs are there, the C++ vehicle beside it on the same generated configs (gobyd,
goby_basic_frontseat_simulator, goby_frontseat_interface with Goby's basic simulator driver and MOOS helm plugin,
MOOSDB, pHelmIvP; ``bench/platform_vehicle.py``). Once each vehicle moves under helm command it waits
``--settle`` seconds, then measures ``--seconds`` real seconds:

- CPU seconds per simulated second, per process (every thread, children included) and in total: utime + stime,
  taken in nanoseconds from each thread's ``schedstat`` when no thread ended in the window (``bench/platform_proc.py``);
- private memory (Private_Clean + Private_Dirty of ``/proc/<pid>/smaps_rollup``) and RSS at the end of the window;
- the Python/C++ ratios;
- that each vehicle runs: NAV_X and DESIRED_SPEED postings per simulated second and metres travelled in the window,
  from a MOOS client on each MOOSDB (the same light client on both).

The C++ programs come from ``$GOBY_BIN_DIR`` (gobyd, goby_basic_frontseat_simulator, goby_frontseat_interface;
its ``../lib`` holds the driver), ``$MOOS_IVP_BIN`` (MOOSDB, pHelmIvP) or PATH. The real MOOSDB listens on every
address, so with them the benchmark re-executes itself inside a private network namespace (``unshare -n``,
loopback up with multicast; ``-r`` when not root) and runs both vehicles there; without them it measures Python only
and says why.

``--python-root DIR`` runs the Python vehicle from another checkout (``git worktree add DIR <commit>``: its
``launch/usv/usv.launch``, config generators and code, on this interpreter); ``--imports`` instead reports the
import cost of each Python process (``bench/platform_import_report.py``). docs/bench.md has the figures.
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

from bench.netns import NETNS_FLAG, cpp_side_here
from bench.platform_import_report import import_report
from bench.platform_proc import ProcSample, cpu_between
from bench.platform_vehicle import (
    CPP,
    PYTHON,
    ROLES,
    Progress,
    Vehicle,
    find_cpp_programs,
    poll_for,
    run_directory,
    vehicle_settings,
)
from bench.progress import progress
from bench.stats import markdown_table
from launch.errors import LaunchError
from launch.usv.mission import LAUNCH_FILE
from util.cli import bounded_number
from util.logsetup import add_verbosity_argument, configure_logging

log = logging.getLogger(__name__)

HERE = Path(__file__).resolve().parent.parent
MIB = 2**20



# ---- one run ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RoleFigures:
    """One process over the window: CPU seconds per simulated second, private and resident bytes at its end."""

    cpu_per_sim_s: float
    private_bytes: int
    rss_bytes: int


@dataclass(frozen=True)
class SideResult:
    """One vehicle over the window: its processes and what it did."""

    roles: dict[str, RoleFigures]
    nav_per_sim_s: float
    desired_per_sim_s: float
    travelled_m: float
    helm_state: str

    @property
    def runs(self) -> bool:
        """NAV fixes and helm setpoints kept coming and the vehicle moved."""
        return self.nav_per_sim_s > 0.5 and self.desired_per_sim_s > 0.5 and self.travelled_m > 1.0

    def figures(self, role_key: str = "") -> RoleFigures:
        """One process's figures, or with no key the vehicle's total."""
        if role_key:
            return self.roles[role_key]
        figures = self.roles.values()
        return RoleFigures(sum(f.cpu_per_sim_s for f in figures), sum(f.private_bytes for f in figures),
                           sum(f.rss_bytes for f in figures))


def role_figures(before: dict[str, list[ProcSample]], after: dict[str, list[ProcSample]], sim_s: float
                 ) -> dict[str, RoleFigures]:
    """Each role's CPU per simulated second between the two samplings, and its memory at the second."""
    return {key: RoleFigures(cpu_between(before.get(key, []), samples) / sim_s,
                             sum(s.private_bytes for s in samples), sum(s.rss_bytes for s in samples))
            for key, samples in after.items()}


def side_result(roles: dict[str, RoleFigures], p0: Progress, p1: Progress) -> SideResult:
    sim_s = max(1e-9, p1.t_sim - p0.t_sim)
    return SideResult(roles, (p1.nav - p0.nav) / sim_s, (p1.desired - p0.desired) / sim_s,
                      p1.travelled_m - p0.travelled_m, p1.helm_state)


def measure_run(warp: int, seconds: float, settle: float, python_root: Path | None,
                cpp_programs: dict[str, str] | None, keep: bool) -> dict[str, SideResult]:
    """Start the vehicles, wait until each moves under helm command, settle, measure; stop them."""
    with run_directory(keep) as base, ExitStack() as stack:
        launch_file = (python_root / "launch" / "usv" / "usv.launch") if python_root else LAUNCH_FILE
        vehicles = [Vehicle(PYTHON, vehicle_settings(base / "py", warp, PYTHON), launch_file,
                            python_root=python_root)]
        if cpp_programs:
            vehicles.append(Vehicle(CPP, vehicle_settings(base / "cpp", warp, CPP), LAUNCH_FILE,
                                    cpp_programs=cpp_programs))
        launched = time.monotonic()
        for vehicle in vehicles:
            stack.callback(_stop_reporting, vehicle)
            vehicle.start()
        for vehicle in vehicles:
            vehicle.wait_running([v for v in vehicles if v is not vehicle])
            progress(f"  {vehicle.side} vehicle under helm command {time.monotonic() - launched:.1f} s after launch")
        poll_for(vehicles, settle)
        before = {v.side: v.samples() for v in vehicles}
        p0 = {v.side: v.progress() for v in vehicles}
        started = time.monotonic()
        progress(f"  measuring {seconds:g} s ({seconds * warp:g} sim s)")
        poll_for(vehicles, seconds)
        after = {v.side: v.samples() for v in vehicles}
        sim_s = (time.monotonic() - started) * warp
        p1 = {v.side: v.progress() for v in vehicles}
        return {v.side: side_result(role_figures(before[v.side], after[v.side], sim_s), p0[v.side], p1[v.side])
                for v in vehicles}


def _stop_reporting(vehicle: Vehicle) -> None:
    unclean = vehicle.stop()
    if unclean:
        progress(f"  ({vehicle.side} vehicle: {'; '.join(unclean)})")


# ---- the table --------------------------------------------------------------------------------------------------
def spread(values: Sequence[float], fmt: Callable[[float], str]) -> str:
    """The median, and with several runs its range: ``12.3 (11.0-14.2)``."""
    if not values:
        return "-"
    text = fmt(statistics.median(values))
    return text if len(values) == 1 else f"{text} ({fmt(min(values))}-{fmt(max(values))})"


def ratio_cell(py: Sequence[float], cpp: Sequence[float]) -> str:
    """Python/C++ per run, as ``spread`` shows it; "-" if a C++ figure is zero."""
    if len(py) != len(cpp) or not all(b > 0 for b in cpp):
        return "-"
    return spread([a / b for a, b in zip(py, cpp, strict=True)], "{:.2f}".format)


def table(runs: list[dict[str, SideResult]]) -> str:
    """Per process and in total: CPU ms per sim s, private MiB, RSS MiB; with the C++ vehicle its figures and the
    Python/C++ ratios beside them."""
    with_cpp = all(CPP in run for run in runs)
    header = ["process (Python / C++)" if with_cpp else "process"]
    for what in ("CPU ms/sim s", "private MiB", "RSS MiB"):
        header += [f"{what} Py", "C++", "ratio"] if with_cpp else [what]
    rows = []
    for label, key in [*((f"{r.python} / {r.cpp}" if with_cpp else r.python, r.key) for r in ROLES), ("total", "")]:
        cells = [label]
        py = [run[PYTHON].figures(key) for run in runs]
        cpp = [run[CPP].figures(key) for run in runs] if with_cpp else []
        for attr, scale in (("cpu_per_sim_s", 1000.0), ("private_bytes", 1 / MIB), ("rss_bytes", 1 / MIB)):
            a = [getattr(f, attr) * scale for f in py]
            cells.append(spread(a, "{:.1f}".format))
            if with_cpp:
                b = [getattr(f, attr) * scale for f in cpp]
                cells += [spread(b, "{:.1f}".format), ratio_cell(a, b)]
        rows.append(cells)
    return markdown_table(header, rows)


def checks(runs: list[dict[str, SideResult]]) -> str:
    """Does each vehicle run? NAV_X and DESIRED_SPEED per sim s, metres travelled in the window, helm state."""
    header = ["vehicle", "runs", "NAV_X/sim s", "DESIRED_SPEED/sim s", "travelled m", "IVPHELM_STATE"]
    rows = []
    for side in (PYTHON, CPP):
        results = [run[side] for run in runs if side in run]
        if not results:
            continue
        rows.append([side, "yes" if all(r.runs for r in results) else "NO",
                     spread([r.nav_per_sim_s for r in results], "{:.2f}".format),
                     spread([r.desired_per_sim_s for r in results], "{:.2f}".format),
                     spread([r.travelled_m for r in results], "{:.0f}".format),
                     ",".join(sorted({r.helm_state for r in results}))])
    return markdown_table(header, rows)


# ---- the private network namespace ------------------------------------------------------------------------------
# ---- main -------------------------------------------------------------------------------------------------------
def warps(text: str) -> list[int]:
    try:
        values = [int(w) for w in text.split(",") if w.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--warp takes whole numbers separated by commas, not {text!r}") from None
    if not values or any(w < 1 or w > 100 for w in values):
        raise argparse.ArgumentTypeError(f"each warp must be 1..100, not {text!r}")
    return values


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="python -m bench.bench_platform", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--warp", type=warps, default=[1, 10], help="time warps, comma-separated (default 1,10)")
    parser.add_argument("--seconds", type=bounded_number(float, 0, 3600, low_inclusive=False), default=30.0,
                        help="real seconds measured per run (default 30)")
    parser.add_argument("--settle", type=bounded_number(float, 0, 600, low_inclusive=False), default=5.0,
                        help="real seconds between moving under helm command and the measurement (default 5)")
    parser.add_argument("--runs", type=bounded_number(int, 1, 100), default=1,
                        help="runs per warp, to show the spread (default 1)")
    parser.add_argument("--python-only", action="store_true", help="skip the C++ vehicle")
    parser.add_argument("--python-root", type=Path, help="run the Python vehicle from this checkout")
    parser.add_argument("--imports", action="store_true", help="report each Python process's import cost instead")
    parser.add_argument("--top", type=bounded_number(int, 1, 100), default=12,
                        help="modules and libraries listed (--imports; default 12)")
    parser.add_argument("--keep", action="store_true", help="keep the run directories (configs, logs)")
    parser.add_argument(NETNS_FLAG, action="store_true", help=argparse.SUPPRESS)
    add_verbosity_argument(parser)
    args = parser.parse_args(argv)
    configure_logging(args.verbose, "bench_platform")
    root: Path | None = args.python_root.resolve() if args.python_root else None
    if root is not None and not (root / "launch" / "usv" / "usv.launch").is_file():
        parser.error(f"--python-root {root} holds no launch/usv/usv.launch")
    if args.imports:
        try:
            return import_report(root, max(args.warp), args.top, args.keep, progress)
        except LaunchError as exc:
            progress(f"failed: {exc}")
            return 1

    programs: dict[str, str] | None = None
    if args.python_only:
        progress("(C++ vehicle skipped: --python-only)")
    else:
        found, why = find_cpp_programs()
        here, status = cpp_side_here(why, args.in_netns, "bench.bench_platform", argv, "C++ vehicle",
                                     "the real MOOSDB listens on all addresses")
        if status is not None:
            return status
        if here:
            programs = found
    print(f"one USV vehicle, Python{' vs C++' if programs else ''}: {args.seconds:g} s measured per run after "
          f"{args.settle:g} s settling, {args.runs} run(s) per warp, {os.cpu_count()} cores"
          f"{f', Python from {root}' if root else ''}")
    status = 0
    for warp in args.warp:
        runs: list[dict[str, SideResult]] = []
        for index in range(args.runs):
            progress(f"warp {warp}, run {index + 1}/{args.runs}: starting")
            try:
                runs.append(measure_run(warp, args.seconds, args.settle, root, programs, args.keep))
            except LaunchError as exc:
                progress(f"  failed: {exc}")
                status = 1
        if not runs:
            continue
        load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
        print(f"\nwarp {warp} ({len(runs)} run(s); median (min-max); load average now {load})")
        print(table(runs))
        print(checks(runs))
    return status


if __name__ == "__main__":
    sys.exit(main())
