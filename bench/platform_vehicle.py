"""One vehicle of the USV mission, Python or C++, started from ``launch/usv/usv.launch`` and watched over MOOS.

The five processes are the launch file's own lines (frontseat-sim, goby-broker, moos-db, ivp-helm,
frontseat-interface with its embedded translation), with the configs its ``python -m launch.usv.config`` lines
generate from ``UsvSettings``. The C++ vehicle is the same lines with Goby3's and MOOS-IvP's programs:
``goby_basic_frontseat_simulator``, ``gobyd``, ``MOOSDB`` and ``pHelmIvP`` (the launch file's ``USV_MOOSDB`` /
``USV_HELM`` choice) and ``goby_frontseat_interface`` with Goby's basic simulator driver (what Goby's generated
``goby_frontseat_interface_basic_simulator`` wrapper runs), without our driver's ``--frontseat_cfg`` tuning.
The interface's config holds Goby3's fields only, so both sides read the same files.

A MOOS client of the benchmark's own (:class:`MoosWatch`) counts NAV_X and DESIRED_SPEED and keeps the track and
the helm state, so the benchmark can tell that a vehicle really runs (the vehicle's five processes do not include
the missions' loggers, so it cannot read their logs). Programs of the C++ side are looked up in
``$GOBY_BIN_DIR``, ``$MOOS_IVP_BIN`` and then PATH.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import shutil
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from bench.platform_proc import ProcSample, children_by_parent, sample_tree
from gateway.moos import MoosClock, comms
from launch.errors import LaunchError, ProcessDiedError
from launch.launchfile import LaunchEntry, expand_vars, parse_file
from launch.process_group import ProcessGroup, child_environment
from launch.record import MissionRecord
from launch.recorder import SimClock
from launch.usv.settings import UsvSettings
from util.process import free_port

log = logging.getLogger(__name__)

PYTHON, CPP = "python", "cpp"
WATCHED = ("NAV_X", "NAV_Y", "DESIRED_SPEED", "DESIRED_HEADING", "IVPHELM_STATE")
BASIC_SIMULATOR_DRIVER = "libgoby_frontseat_basic_simulator.so"
READY_TIMEOUT_S = 180.0  # launch to moving under helm command, on a loaded machine
GOBY_SOVERSION = "30"  # Goby3 3.x: the soname the generated goby_frontseat_interface_basic_simulator names


class MoosWatch:
    """A MOOS client registered for :data:`WATCHED`; ``poll()`` (the benchmark's thread) counts the mail and files
    the track and the helm state into the record. Its own I/O thread only queues mail (the pymoos contract)."""

    def __init__(self, record: MissionRecord, clock: SimClock, moos_port: int, name: str) -> None:
        self.record, self.clock, self.moos_port, self.name = record, clock, moos_port, name
        self.comms = comms(clock=MoosClock(clock.warp))
        self.comms.set_on_connect_callback(lambda: all(self.comms.register(v, 0) for v in WATCHED))
        self.counts: Counter[str] = Counter()

    def start(self) -> None:
        self.comms.run("127.0.0.1", self.moos_port, self.name)

    def poll(self) -> None:
        now = self.clock.now()
        for msg in self.comms.fetch():
            name = msg.key()
            self.counts[name] += 1
            if name in ("NAV_X", "NAV_Y") and msg.is_double():
                self.record.add_nav(now, name, msg.double())
            elif name == "IVPHELM_STATE":
                self.record.add_event(now, "moos", name, msg.string(), msg.source())

    def close(self) -> None:
        self.comms.close(True)


@dataclass(frozen=True)
class Role:
    """One of the vehicle's five processes: its program in usv.launch and its C++ counterpart."""

    key: str
    python: str
    cpp: str


ROLES = (
    Role("broker", "goby-broker", "gobyd"),
    Role("simulator", "frontseat-sim", "goby_basic_frontseat_simulator"),
    Role("interface", "frontseat-interface", "goby_frontseat_interface"),
    Role("moosdb", "moos-db", "MOOSDB"),
    Role("helm", "ivp-helm", "pHelmIvP"),
)
GOBY_PROGRAMS = ("gobyd", "goby_basic_frontseat_simulator", "goby_frontseat_interface")
MOOS_PROGRAMS = ("MOOSDB", "pHelmIvP")


def find_cpp_programs(environ: Mapping[str, str] | None = None) -> tuple[dict[str, str], str | None]:
    """Program -> path of the C++ vehicle's programs, or ({}, why not): ``$GOBY_BIN_DIR`` for Goby3's,
    ``$MOOS_IVP_BIN`` for MOOS-IvP's, then PATH."""
    environ = os.environ if environ is None else environ
    found: dict[str, str] = {}
    for programs, var in ((GOBY_PROGRAMS, "GOBY_BIN_DIR"), (MOOS_PROGRAMS, "MOOS_IVP_BIN")):
        directory = environ.get(var, "")
        for program in programs:
            candidate = Path(directory) / program if directory else None
            if candidate is not None and os.access(candidate, os.X_OK):
                found[program] = str(candidate)
            elif (on_path := shutil.which(program, path=environ.get("PATH"))) is not None:
                found[program] = on_path
            else:
                return {}, f"{program} is neither in ${var} ({directory or 'unset'}) nor on PATH"
    return found, None


def driver_library(goby_bin: str) -> str:
    """The basic simulator driver for ``FRONTSEAT_DRIVER_LIBRARY``: its path beside Goby's bin directory
    (``../lib``) if it is there, else the soname for the dynamic loader to find."""
    lib_dir = Path(goby_bin).resolve().parent.parent / "lib"
    for candidate in sorted(lib_dir.glob(f"{BASIC_SIMULATOR_DRIVER}.{GOBY_SOVERSION}*")):
        return str(candidate)
    return f"{BASIC_SIMULATOR_DRIVER}.{GOBY_SOVERSION}"


def vehicle_entries(launch_file: Path, env: Mapping[str, str]) -> list[tuple[Role, LaunchEntry]]:
    """The launch file's line for each role (the first line running its Python or C++ program), in launch order.

    ``env`` expands the program names (``${USV_MOOSDB:-moos-db}``); LaunchError names a role without a line.
    """
    chosen: dict[str, tuple[Role, LaunchEntry]] = {}
    order: list[str] = []
    for entry in parse_file(launch_file).entries:
        program = os.path.basename(expand_vars(entry.binary, entry.environment(env)))
        role = next((r for r in ROLES if program in (r.python, r.cpp)), None)
        if role is not None and role.key not in chosen:
            chosen[role.key] = (role, entry)
            order.append(role.key)
    missing = [r.key for r in ROLES if r.key not in chosen]
    if missing:
        raise LaunchError(f"{launch_file} has no line for {', '.join(missing)}")
    return [chosen[key] for key in order]


def cpp_entry(role: Role, entry: LaunchEntry, programs: Mapping[str, str]) -> LaunchEntry:
    """The C++ counterpart of one launch line: the same arguments (the same generated configs) with Goby3's
    program. MOOSDB and pHelmIvP need no change: the launch file takes them from ``USV_MOOSDB``/``USV_HELM``."""
    if role.key in ("moosdb", "helm"):
        return entry
    _, _, args = entry.command.partition(" ")
    env = entry.env
    if role.key == "interface":
        # --frontseat_cfg carries our driver's tuning (an extension Goby's driver does not know)
        args = args.split(" --frontseat_cfg", 1)[0]
        env = (("FRONTSEAT_DRIVER_LIBRARY", driver_library(programs["goby_frontseat_interface"])),)
    return dataclasses.replace(entry, command=f"{programs[role.cpp]} {args}".strip(), env=env)


def profile_imports(role: Role, entry: LaunchEntry) -> LaunchEntry:
    """The line with ``PYTHONPROFILEIMPORTTIME=1`` for its program only (not for the config generators its
    process substitutions run), so the program's log holds one ``-X importtime`` tree."""
    return dataclasses.replace(entry, command=f"env PYTHONPROFILEIMPORTTIME=1 {entry.command}",
                               name=entry.name or role.python)


@dataclass(frozen=True)
class Progress:
    """What a vehicle did up to a moment: MOOS postings counted, sim time, distance along the track."""

    t_sim: float
    nav: int
    desired: int
    travelled_m: float
    helm_state: str


def vehicle_settings(run_dir: Path, warp: int, side: str) -> UsvSettings:
    """The USV settings of one vehicle: its own directory and free ports, the C++ side with MOOSDB and pHelmIvP."""
    settings = UsvSettings(run_dir=run_dir, warp=warp, moos_port=free_port(), sim_port=free_port(),
                           sat_port=free_port(), liaison_port=free_port())
    return settings.replace(moosdb="MOOSDB", helm="pHelmIvP") if side == CPP else settings


class Vehicle:
    """The five processes of one side, started with ``start()`` and always ended with ``stop()`` (or ``with``)."""

    def __init__(self, side: str, settings: UsvSettings, launch_file: Path, *,
                 python_root: Path | None = None, cpp_programs: Mapping[str, str] | None = None,
                 import_profile: bool = False, launch_delay_s: float = 0.2) -> None:
        self.side = side
        self.settings = settings
        self.clock = SimClock(settings.warp)
        self.record = MissionRecord()
        env = child_environment() | settings.to_env()
        if python_root is not None:  # the Python side from another tree (a worktree of an older commit)
            env["PYTHONPATH"] = os.pathsep.join(p for p in (str(python_root), env.get("PYTHONPATH")) if p)
        if side == CPP:
            if not cpp_programs:
                raise LaunchError("the C++ vehicle needs its programs (find_cpp_programs)")
            dirs = dict.fromkeys(str(Path(p).parent) for p in cpp_programs.values())
            # this interpreter first (the config generators' `python`), then the C++ programs
            env["PATH"] = os.pathsep.join([os.path.dirname(sys.executable), *dirs, env["PATH"]])
        selected = vehicle_entries(launch_file, env)
        if side == CPP:
            assert cpp_programs is not None
            selected = [(role, cpp_entry(role, entry, cpp_programs)) for role, entry in selected]
        elif import_profile:
            selected = [(role, profile_imports(role, entry)) for role, entry in selected]
        self.roles = [role for role, _ in selected]
        self.group = ProcessGroup([entry for _, entry in selected], settings.log_dir, platform=side,
                                  launch_delay_s=launch_delay_s, kill_timeout_s=5.0, base_env=env, cwd=settings.run_dir,
                                  report=log.info)
        self.moos = MoosWatch(self.record, self.clock, settings.moos_port, name=f"uBench_{side}")

    def start(self) -> None:
        """Start the processes (the MOOS client connects once the MOOSDB is up)."""
        self.settings.run_dir.mkdir(parents=True, exist_ok=True)
        self.group.start()
        self.moos.start()

    def pids(self) -> dict[str, int]:
        """Role key -> pid of its program."""
        return {role.key: process.pid for role, process in zip(self.roles, self.group.processes, strict=True)}

    def log_paths(self) -> dict[str, Path]:
        return {role.key: process.log_path for role, process in zip(self.roles, self.group.processes, strict=True)}

    def samples(self) -> dict[str, list[ProcSample]]:
        """Role key -> a /proc sample of its program and of each of its descendants."""
        tree = children_by_parent()
        return {key: sample_tree(pid, tree) for key, pid in self.pids().items()}

    def poll(self) -> None:
        """Read MOOS mail; ProcessDiedError if a process ended."""
        self.moos.poll()
        died = self.group.check()
        if died is not None:
            raise ProcessDiedError(died.name, died.returncode, died.log_tail())

    def progress(self) -> Progress:
        """Counts and track so far (call ``poll()`` first)."""
        nav, events = self.record.snapshot()
        travelled = sum(math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(nav, nav[1:], strict=False))
        states = [e.value for e in events if e.name == "IVPHELM_STATE"]
        return Progress(self.clock.now(), self.moos.counts["NAV_X"], self.moos.counts["DESIRED_SPEED"], travelled,
                        states[-1] if states else "-")

    def wait_running(self, others: Sequence[Vehicle] = (), timeout_s: float = READY_TIMEOUT_S,
                     min_travel_m: float = 5.0) -> float:
        """Block until this vehicle moves under helm command (DESIRED_SPEED posted, the track advanced
        ``min_travel_m``); ``others`` are polled meanwhile. Returns the real seconds it took."""
        started = time.monotonic()
        while True:
            for vehicle in (self, *others):
                vehicle.poll()
            now = self.progress()
            if now.desired > 0 and now.travelled_m >= min_travel_m:
                return time.monotonic() - started
            if time.monotonic() - started > timeout_s:
                raise LaunchError(f"the {self.side} vehicle did not move under helm command within {timeout_s:g} s "
                                  f"(NAV_X {now.nav}, DESIRED_SPEED {now.desired}, moved {now.travelled_m:.1f} m, "
                                  f"helm {now.helm_state}; logs in {self.settings.log_dir})")
            time.sleep(0.1)

    def stop(self) -> list[str]:
        """Stop the MOOS client and the processes; returns how each process ended that did not end cleanly."""
        try:
            self.moos.close()
        finally:
            self.group.stop()
        return [f"{p.name}: exit status {p.returncode}" for p in self.group.processes if not p.exited_cleanly]

    def __enter__(self) -> Vehicle:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def poll_for(vehicles: Sequence[Vehicle], seconds: float) -> None:
    """Keep reading every vehicle's MOOS mail (and checking its processes) for ``seconds``."""
    deadline = time.monotonic() + seconds
    while (left := deadline - time.monotonic()) > 0:
        for vehicle in vehicles:
            vehicle.poll()
        time.sleep(min(0.2, left))


@contextmanager
def run_directory(keep: bool) -> Iterator[Path]:
    """A fresh directory under /tmp for one run's vehicles (configs, sockets, logs); removed after, unless ``keep``
    or the run failed (its errors name the logs there), and then its path is logged."""
    path = Path(tempfile.mkdtemp(prefix="platform-", dir="/tmp"))
    try:
        yield path
    except BaseException:
        keep = True
        raise
    finally:
        if keep:
            log.warning("run directory kept: %s", path)
        else:
            shutil.rmtree(path, ignore_errors=True)
