"""One trail AUV, Python against C++, process by process, in the same mission run (issue 24).

``python -m bench.bench_trail_auv [--warp 10] [--seconds 20] [--auvs 2] [--runs 1] [--settle 10]``. Per run it
starts the whole trail mission (``launch.trail.mission.TrailMission``: topside, USV and ``--auvs`` AUVs, every
process of every platform, as ``all.launch`` runs it) with auv0 all ours and auv1 built from the C++ originals:
``launch/trail/auv.launch``'s program variables set on auv1's launch line only (:func:`cpp_environment`):

=====================  ==================================================================================
ours                   C++ on auv1
=====================  ==================================================================================
frontseat-sim          goby_basic_frontseat_simulator
goby-broker            gobyd (its acomms link on ``TRAIL_LINK_ADDRESS=0.0.0.0``, as the real driver needs)
goby-logger            goby_logger
frontseat-interface    goby_frontseat_interface with Goby's basic simulator driver, without our tuning
moos-db                MOOSDB
ivp-helm               pHelmIvP
node-reporter          pNodeReporter
moos-share             pShare
moos-logger            pLogger
goby-liaison, auv-manager, moos-gateway (the goby3_course plugin), launch.trail.moos_gen: ours on both AUVs
=====================  ==================================================================================

(the course's C++ liaison, AUV manager and gateway plugin are not built here). Once both AUVs are under helm
command (their frontseat interfaces report COMMAND in their goby logs) it waits ``--settle`` real seconds, then
measures ``--seconds`` real seconds and prints per process, both AUVs side by side, with the Python/C++ ratio:

- CPU ms per simulated second: utime + stime of the process and its descendants (``bench/platform_proc.py``:
  nanoseconds from each thread's ``schedstat`` when no thread ended in the window);
- wake-ups per simulated second: voluntary context switches, summed over the process's threads;
- private memory (Private_Clean + Private_Dirty) at the end of the window;

then the totals (the AUV's launcher, goby-launch, is ours on both and shown apart, outside the totals), whether
each AUV kept up (at least 0.9 NAV_X rows in its alog per simulated second: the simulator sends one fix a sim
second, Goby's interface posts each twice, docs/bench.md; DESIRED_SPEED rows are shown too) and what 16 AUVs at the
measured cost would need at this warp.

The C++ programs come from ``$GOBY_BIN_DIR`` / ``$MOOS_IVP_BIN`` / PATH (``bench.platform_vehicle``), goby_logger
beside gobyd and the MOOS apps beside MOOSDB. The real MOOSDB and gobyd listen on every address, so the benchmark
re-executes itself inside a private network namespace (``bench/netns.py``); without the programs (or with
``--python-only``) every AUV is ours and only auv0 is reported, with the reason.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import shutil
import statistics
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from bench.bench_platform import ratio_cell, spread
from bench.netns import NETNS_FLAG, cpp_side_here
from bench.platform_proc import (
    ProcSample,
    children_by_parent,
    cpu_between,
    machine_ticks,
    program_name,
    sample,
    wakeups,
)
from bench.platform_vehicle import driver_library, find_cpp_programs, run_directory
from bench.progress import progress
from bench.stats import markdown_table
from launch.errors import LaunchError
from launch.launchfile import LaunchEntry
from launch.trail.mission import TrailMission, all_launch_entries, with_free_ports
from launch.trail.settings import TrailSettings, Vehicle
from util.cli import bounded_number
from util.logsetup import add_verbosity_argument, configure_logging

log = logging.getLogger(__name__)

PYTHON, CPP = "python", "cpp"
SIDE_AUV = {PYTHON: "auv0", CPP: "auv1"}
MIB = 2**20
LAUNCHER = "goby-launch"
COMMAND_TIMEOUT_S = 300.0  # launch to both AUVs under command: ~45 processes start on a loaded 2-core machine
FLEET = 16  # issue 24: topside + USV + 16 AUVs at warp 10 within 80 % of the machine's cores
FLEET_SHARE = 0.8


@dataclass(frozen=True)
class Role:
    """One AUV process: our program, its C++ counterpart (None: ours on both AUVs) and the launch file's variable."""

    python: str
    cpp: str | None = None
    variable: str = ""
    aliases: tuple[str, ...] = ()  # what else its process may show in /proc as its program

    def label(self, with_cpp: bool) -> str:
        if not with_cpp:
            return self.python
        return f"{self.python} / {self.cpp}" if self.cpp else f"{self.python} (ours on both)"


ROLES = (
    Role("frontseat-sim", "goby_basic_frontseat_simulator", "TRAIL_FRONTSEAT_SIM"),
    Role("goby-broker", "gobyd", "TRAIL_GOBY_BROKER"),
    Role("goby-logger", "goby_logger", "TRAIL_GOBY_LOGGER"),
    Role("frontseat-interface", "goby_frontseat_interface", "TRAIL_FRONTSEAT_INTERFACE"),
    Role("goby-liaison"),
    Role("auv-manager"),
    Role("moos-gateway"),
    Role("launch.trail.moos_gen", aliases=("sh",)),  # execs a shell that holds the .moos/.bhv files until stopped
    Role("moos-db", "MOOSDB", "TRAIL_MOOSDB"),
    Role("ivp-helm", "pHelmIvP", "TRAIL_HELM"),
    Role("node-reporter", "pNodeReporter", "TRAIL_NODE_REPORTER"),
    Role("moos-share", "pShare", "TRAIL_MOOS_SHARE"),
    Role("moos-logger", "pLogger", "TRAIL_MOOS_LOGGER"),
)
GOBY_EXTRA = ("goby_logger",)  # found beside gobyd
MOOS_EXTRA = ("pNodeReporter", "pShare", "pLogger")  # found beside MOOSDB


# ---- the C++ programs -------------------------------------------------------------------------------------------
def find_programs(environ: Mapping[str, str] | None = None) -> tuple[dict[str, str], str | None]:
    """Program -> path of every C++ program of the AUV, or ({}, why not): bench_platform's five as
    ``find_cpp_programs`` finds them, goby_logger beside gobyd and the MOOS apps beside MOOSDB (else on PATH)."""
    environ = os.environ if environ is None else environ
    found, why = find_cpp_programs(environ)
    if why is not None:
        return {}, why
    for programs, sibling in ((GOBY_EXTRA, "gobyd"), (MOOS_EXTRA, "MOOSDB")):
        directory = Path(found[sibling]).parent
        for program in programs:
            beside = directory / program
            path = str(beside) if os.access(beside, os.X_OK) else shutil.which(program, path=environ.get("PATH"))
            if path is None:
                return {}, f"{program} is neither beside {sibling} ({directory}) nor on PATH"
            found[program] = path
    return found, None


def cpp_environment(programs: Mapping[str, str]) -> dict[str, str]:
    """auv1's variables: each C++ program by name (``auv.launch`` runs ``${TRAIL_GOBY_BROKER:-goby-broker}`` ...)
    with their directories on PATH after this interpreter's (a MOOS app takes its name, and so its ProcessConfig
    block, from argv[0]: ``/path/pHelmIvP`` would read no config), Goby's basic simulator driver without our
    tuning, and the acomms link where the real gobyd can use it."""
    env = {role.variable: role.cpp for role in ROLES if role.cpp}
    dirs = dict.fromkeys(str(Path(p).parent) for p in programs.values())
    env["PATH"] = os.pathsep.join([os.path.dirname(sys.executable), *dirs, "${PATH}"])
    env["TRAIL_FRONTSEAT_DRIVER"] = driver_library(programs["goby_frontseat_interface"])
    env["TRAIL_FRONTSEAT_TUNING"] = ""  # set and empty: no --frontseat_cfg
    # a UDP socket bound to 127.0.0.1 hears no multicast: the real driver needs 0.0.0.0 (docs/intervehicle.md)
    env["TRAIL_LINK_ADDRESS"] = "0.0.0.0"
    return env


def mission_entries(n_auvs: int, platform_env: Mapping[str, Mapping[str, str]]) -> list[LaunchEntry]:
    """all.launch's lines for ``n_auvs`` with ``platform_env[name]`` added to platform ``name``'s line (its nested
    goby-launch and so every process of that platform)."""
    return [dataclasses.replace(e, env=e.env + tuple(platform_env[e.name].items()))
            if e.name is not None and e.name in platform_env else e for e in all_launch_entries(n_auvs)]


# ---- /proc ------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Reading:
    """One /proc reading of a process: CPU and memory, wake-ups."""

    proc: ProcSample
    wakeups: int


def read_platform(launcher_pid: int) -> dict[str, tuple[set[str], list[Reading]]]:
    """Role (our program's name, or ``goby-launch``) -> (the programs seen, readings of each of its processes and
    their descendants) for the platform launched by ``launcher_pid`` (its nested goby-launch)."""
    tree = children_by_parent()
    by_program = {program: role.python for role in ROLES for program in (role.python, role.cpp, *role.aliases)
                  if program}
    out: dict[str, tuple[set[str], list[Reading]]] = {}

    def add(role: str, program: str, root: int) -> None:
        programs, readings = out.setdefault(role, (set(), []))
        programs.add(program)
        todo = [root]
        while todo:
            pid = todo.pop()
            todo.extend(tree.get(pid, []))
            proc = sample(pid)
            if proc is not None:
                readings.append(Reading(proc, wakeups(pid)))

    launcher = sample(launcher_pid)
    if launcher is not None:
        out[LAUNCHER] = ({program_name(launcher_pid)}, [Reading(launcher, wakeups(launcher_pid))])
    for child in tree.get(launcher_pid, []):
        program = program_name(child)
        if program != "?":  # ended between the two reads
            add(by_program.get(program, program), program, child)
    return out


@dataclass(frozen=True)
class Figures:
    """One process (or a total) over the window."""

    cpu_per_sim_s: float
    wakeups_per_sim_s: float
    private_bytes: int

    def __add__(self, other: Figures) -> Figures:
        return Figures(self.cpu_per_sim_s + other.cpu_per_sim_s, self.wakeups_per_sim_s + other.wakeups_per_sim_s,
                       self.private_bytes + other.private_bytes)


ZERO = Figures(0.0, 0.0, 0)


def figures(before: Sequence[Reading], after: Sequence[Reading], sim_s: float) -> Figures:
    """CPU and wake-ups between two readings per simulated second (a process seen only after counts whole), and
    the private memory of the second."""
    first = {(r.proc.pid, r.proc.start_ticks): r.wakeups for r in before}
    woke = sum(r.wakeups - first.get((r.proc.pid, r.proc.start_ticks), 0) for r in after)
    cpu = cpu_between([r.proc for r in before], [r.proc for r in after])
    return Figures(cpu / sim_s, woke / sim_s, sum(r.proc.private_bytes for r in after))


# ---- one run ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SideResult:
    """One AUV over the window: its processes by role, the programs they ran, and whether it kept up."""

    roles: dict[str, Figures]
    programs: dict[str, set[str]]
    nav_per_sim_s: float
    desired_per_sim_s: float

    @property
    def runs(self) -> bool:
        """Every NAV fix of the simulator (one a sim second) reached the MOOSDB: the frontseat chain kept pace.
        (The helm posts DESIRED_* only once its trail behaviour has the USV's first report, over acomms.)"""
        return self.nav_per_sim_s > 0.9

    def total(self) -> Figures:
        """Every AUV process, the launcher left out."""
        return sum((f for role, f in self.roles.items() if role != LAUNCHER), ZERO)

    def swapped(self) -> Figures:
        """The processes that have a C++ counterpart."""
        return sum((self.roles.get(r.python, ZERO) for r in ROLES if r.cpp), ZERO)


def missing_roles(result: SideResult) -> list[str]:
    """The AUV processes not measured (an empty list when every process was)."""
    return [r.python for r in ROLES if r.python not in result.roles] + ([] if LAUNCHER in result.roles else [LAUNCHER])


def wrong_programs(side: str, result: SideResult) -> list[str]:
    """Roles that ran another program than the side's (``goby-broker ran gobyd``), and processes of no role."""
    out = []
    for role in ROLES:
        expected = {role.cpp if side == CPP and role.cpp else role.python, *role.aliases}
        seen = result.programs.get(role.python, set())
        if seen - expected:
            out.append(f"{role.python} ran {', '.join(sorted(seen))}, not {' or '.join(sorted(expected))}")
    known = {r.python for r in ROLES} | {LAUNCHER}
    out += [f"a process of no role: {role}" for role in result.roles if role not in known]
    return out


def _auv(name: str, n_auvs: int) -> Vehicle:
    return Vehicle("auv", n_auvs, int(name.removeprefix("auv")))


def measure_run(warp: int, seconds: float, settle: float, n_auvs: int, cpp_env: Mapping[str, str] | None,
                keep: bool) -> dict[str, SideResult]:
    """Start the mission, wait until the AUVs compared are under helm command, settle, measure; stop it."""
    sides = {PYTHON: SIDE_AUV[PYTHON], **({CPP: SIDE_AUV[CPP]} if cpp_env is not None else {})}
    with run_directory(keep) as base:
        settings = with_free_ports(TrailSettings(run_dir=base, warp=warp, socket_dir=base), n_auvs,
                                   prefer_course=False)
        entries = mission_entries(n_auvs, {SIDE_AUV[CPP]: cpp_env} if cpp_env is not None else {})
        mission = TrailMission(settings, n_auvs, entries=entries, vehicles=[_auv(a, n_auvs) for a in sides.values()],
                               report=log.debug, launch_delay_s=1.0, moos_variables=("NAV_X",))
        launched = time.monotonic()
        try:
            mission.start()
            progress(f"  launched; waiting for {' and '.join(sides.values())} to be under helm command")

            def waiting() -> None:
                states = {name: "/".join(dict.fromkeys(run.interface_states())) or "no status yet"
                          for name, run in mission.runs.items()}
                progress(f"  {time.monotonic() - launched:.0f} s: "
                         + "; ".join(f"{name} {state}" for name, state in states.items()))

            mission.wait_for_command(COMMAND_TIMEOUT_S, progress=waiting)
            progress(f"  under helm command {time.monotonic() - launched:.0f} s after launch; settling {settle:g} s")
            settled = time.monotonic()
            mission.run(None, until=lambda: time.monotonic() - settled >= settle)
            assert mission.group is not None
            launchers = {p.name: p.pid for p in mission.group.processes}
            before = {side: read_platform(launchers[auv]) for side, auv in sides.items()}
            counts0 = {side: dict(mission.runs[auv].logs.counts) for side, auv in sides.items()}
            sim0, real0, machine0 = mission.now(), time.monotonic(), machine_ticks()
            progress(f"  measuring {seconds:g} s ({seconds * warp:g} sim s)")
            mission.run(None, until=lambda: time.monotonic() - real0 >= seconds)
            after = {side: read_platform(launchers[auv]) for side, auv in sides.items()}
            sim_s = mission.now() - sim0
            machine1 = machine_ticks()
            progress(f"  the machine was {(machine1[0] - machine0[0]) / (machine1[1] - machine0[1]):.0%} busy over the "
                     "window (everything on it, this benchmark included; near 100 % the figures over-count)")
            results = {}
            for side, auv in sides.items():
                counts = mission.runs[auv].logs.counts
                rate = {var: (counts.get(var, 0) - counts0[side].get(var, 0)) / sim_s
                        for var in ("NAV_X", "DESIRED_SPEED")}
                results[side] = SideResult(
                    {role: figures(before[side].get(role, (set(), []))[1], readings, sim_s)
                     for role, (_, readings) in after[side].items()},
                    {role: programs for role, (programs, _) in after[side].items()},
                    rate["NAV_X"], rate["DESIRED_SPEED"])
        finally:
            ended = mission.stop()
            for line in [e for e in ended.log_errors if any(auv in e for auv in sides.values())][:8]:
                progress(f"  log: {line[:200]}")
            for outcome in ended.outcomes:
                if not outcome.clean:
                    progress(f"  ({outcome.name}: exit status {outcome.returncode}; log {outcome.log_path})")
        return results


# ---- the tables -------------------------------------------------------------------------------------------------
def table(runs: list[dict[str, SideResult]]) -> str:
    """Per process, the totals and the launcher: CPU ms/sim s, wake-ups/sim s, private MiB; with the C++ AUV its
    figures and the Python/C++ ratios beside them."""
    with_cpp = all(CPP in run for run in runs)
    header = ["process (auv0 ours / auv1 C++)" if with_cpp else "process (auv0)"]
    for what in ("CPU ms/sim s", "wake-ups/sim s", "private MiB"):
        header += [f"{what} Py", "C++", "ratio"] if with_cpp else [what]
    lines: list[tuple[str, str]] = [(r.label(with_cpp), r.python) for r in ROLES]
    lines.append(("**total** (launcher left out)", "total"))
    if with_cpp:
        lines.append(("those with a C++ counterpart", "swapped"))
    lines.append((f"{LAUNCHER} (the AUV's launcher{', ours on both' if with_cpp else ''})", LAUNCHER))
    rows = []
    for label, key in lines:
        cells = [label]
        per_side = {side: [_pick(run[side], key) for run in runs] for side in (PYTHON, CPP) if with_cpp or side == PYTHON}
        for attr, scale, fmt in (("cpu_per_sim_s", 1000.0, "{:.2f}"), ("wakeups_per_sim_s", 1.0, "{:.0f}"),
                                 ("private_bytes", 1 / MIB, "{:.1f}")):
            a = [getattr(f, attr) * scale for f in per_side[PYTHON]]
            cells.append(spread(a, fmt.format))
            if with_cpp:
                b = [getattr(f, attr) * scale for f in per_side[CPP]]
                cells += [spread(b, fmt.format), ratio_cell(a, b)]
        rows.append(cells)
    return markdown_table(header, rows)


def _pick(result: SideResult, key: str) -> Figures:
    if key == "total":
        return result.total()
    if key == "swapped":
        return result.swapped()
    return result.roles.get(key, ZERO)


def checks(runs: list[dict[str, SideResult]]) -> str:
    """Did each AUV keep up (``SideResult.runs``)? NAV_X and DESIRED_SPEED rows of its alog per simulated second."""
    header = ["AUV", "kept up", "NAV_X/sim s", "DESIRED_SPEED/sim s"]
    rows = []
    for side in (PYTHON, CPP):
        results = [run[side] for run in runs if side in run]
        if results:
            rows.append([f"{SIDE_AUV[side]} ({'C++' if side == CPP else 'ours'})",
                         "yes" if all(r.runs for r in results) else "NO",
                         spread([r.nav_per_sim_s for r in results], "{:.2f}".format),
                         spread([r.desired_per_sim_s for r in results], "{:.2f}".format)])
    return markdown_table(header, rows)


def fleet_estimate(runs: list[dict[str, SideResult]], warp: int) -> str:
    """What ``FLEET`` AUVs at each side's median cost need at ``warp``, against ``FLEET_SHARE`` of the cores."""
    cores = os.cpu_count() or 1
    budget = FLEET_SHARE * cores
    parts = []
    for side, name in ((PYTHON, "ours"), (CPP, "C++")):
        totals = [run[side].total().cpu_per_sim_s for run in runs if side in run]
        if totals:
            need = FLEET * statistics.median(totals) * warp
            parts.append(f"{name} {need:.2f} cores ({'fits' if need <= budget else 'does not fit'})")
    return (f"{FLEET} AUVs at warp {warp} by these totals (CPU s per sim s x warp x {FLEET}; the topside and the USV "
            f"not included): " + ", ".join(parts) + f"; {FLEET_SHARE:.0%} of {cores} cores is {budget:.1f}")


# ---- main -------------------------------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="python -m bench.bench_trail_auv", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--warp", type=bounded_number(int, 1, 100), default=10, help="time warp (default 10)")
    parser.add_argument("--seconds", type=bounded_number(float, 0, 3600, low_inclusive=False), default=20.0,
                        help="real seconds measured per run (default 20)")
    parser.add_argument("--settle", type=bounded_number(float, 0, 600), default=10.0,
                        help="real seconds between both AUVs under command and the measurement (default 10: "
                             "at warp 10 the helms have the USV's first acomms report by then)")
    parser.add_argument("--auvs", type=bounded_number(int, 1, 16), default=2,
                        help="AUVs in the mission (default 2: auv0 ours, auv1 C++, the others ours)")
    parser.add_argument("--runs", type=bounded_number(int, 1, 20), default=1, help="runs, to show the spread")
    parser.add_argument("--python-only", action="store_true", help="no C++ AUV: measure auv0 alone")
    parser.add_argument("--keep", action="store_true", help="keep the run directories (configs, logs)")
    parser.add_argument(NETNS_FLAG, action="store_true", help=argparse.SUPPRESS)
    add_verbosity_argument(parser)
    args = parser.parse_args(argv)
    configure_logging(args.verbose, "bench_trail_auv")

    cpp_env: dict[str, str] | None = None
    if args.python_only:
        progress("(C++ AUV skipped: --python-only)")
    elif args.auvs < 2:
        progress("(C++ AUV skipped: --auvs 1 leaves no auv1 for it)")
    else:
        programs, why = find_programs()
        here, status = cpp_side_here(why, args.in_netns, "bench.bench_trail_auv", argv, "C++ AUV",
                                     "the real MOOSDB and gobyd listen on all addresses")
        if status is not None:
            return status
        if here:
            cpp_env = cpp_environment(programs)
    print(f"one trail AUV, {'ours (auv0) vs C++ (auv1)' if cpp_env else 'ours (auv0) alone'}: mission of "
          f"{args.auvs} AUV(s) + USV + topside at warp {args.warp}, {args.seconds:g} s measured per run after "
          f"{args.settle:g} s settling, {args.runs} run(s), {os.cpu_count()} cores")
    runs: list[dict[str, SideResult]] = []
    status = 0
    for index in range(args.runs):
        progress(f"run {index + 1}/{args.runs}: starting")
        try:
            run = measure_run(args.warp, args.seconds, args.settle, args.auvs, cpp_env, args.keep)
        except LaunchError as exc:
            progress(f"  failed: {exc}")
            status = 1
            continue
        for side, result in run.items():
            problems = [f"not measured: {', '.join(m)}" for m in [missing_roles(result)] if m]
            problems += wrong_programs(side, result)
            if problems:
                progress(f"  {SIDE_AUV[side]}: {'; '.join(problems)}")
                status = 1
        runs.append(run)
    if not runs:
        return 1
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"\n{len(runs)} run(s); median (min-max); load average now {load}")
    print(table(runs))
    print(checks(runs))
    print(fleet_estimate(runs, args.warp))
    return status


if __name__ == "__main__":
    sys.exit(main())
