"""The import cost of the Python vehicle's five processes (``python -m bench.bench_platform --imports``).

Each program runs once with ``PYTHONPROFILEIMPORTTIME=1`` (``-X importtime``), started 2 s apart so that their
imports do not overlap on a small machine; its log's import tree gives the modules with the most import time of
their own and the imports that pulled them in. Then a bare interpreter's private memory, and what each library the
vehicle imports (``zmq``, ``asyncio``, ``google.protobuf``, ...) adds to it when its modules are imported alone:
the candidates for lazy imports.
"""

from __future__ import annotations

import subprocess
import sys
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from bench.platform_imports import (
    ImportRecord,
    describe,
    parse_importtime,
    self_time_by_package,
    top_by_self,
    total_us,
)
from bench.platform_proc import ProcSample, sample
from bench.platform_vehicle import PYTHON, ROLES, Vehicle, poll_for, run_directory, vehicle_settings

REPO = Path(__file__).resolve().parent.parent
MIB = 2**20


@dataclass(frozen=True)
class Interpreter:
    """A fresh interpreter's memory once it imported some modules, and every module it then held."""

    memory: ProcSample
    modules: frozenset[str]


def interpreter_memory(modules: Sequence[str] = ()) -> Interpreter | None:
    """A fresh interpreter (this one, site and .pth files loaded) once it imported ``modules`` (each that imports:
    a module whose import fails in the program, such as ``nt``, fails here too); None if it could not be read."""
    code = ("import importlib, sys\n"
            "for name in sys.argv[1:]:\n"
            "    try: importlib.import_module(name)\n"
            "    except Exception: pass\n"
            "print(*sys.modules, flush=True); sys.stdin.read()")
    child = subprocess.Popen([sys.executable, "-c", code, *modules], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             text=True)
    try:
        assert child.stdout is not None
        loaded = frozenset(child.stdout.readline().split())
        memory = sample(child.pid)
        return Interpreter(memory, loaded) if memory is not None else None
    finally:
        child.communicate()


def profile_imports(python_root: Path | None, warp: int, keep: bool, progress: Callable[[str], None]
                    ) -> tuple[dict[str, list[ImportRecord]], dict[str, int]]:
    """Run the Python vehicle once with PYTHONPROFILEIMPORTTIME for its programs, started 2 s apart so that their
    imports do not overlap; returns each role's import records and private bytes once it runs."""
    root = python_root or REPO
    with run_directory(keep) as base:
        with Vehicle(PYTHON, vehicle_settings(base / "py", warp, PYTHON), root / "launch" / "usv" / "usv.launch",
                     python_root=python_root, import_profile=True, launch_delay_s=2.0) as vehicle:
            vehicle.start()
            took = vehicle.wait_running()
            progress(f"  python vehicle under helm command ({took:.1f} s); settling 3 s")
            poll_for([vehicle], 3.0)
            private = {key: sum(s.private_bytes for s in samples) for key, samples in vehicle.samples().items()}
        logs = vehicle.log_paths()
        records = {role.key: parse_importtime(logs[role.key].read_text(errors="replace").splitlines())
                   for role in ROLES}
    return records, private


@dataclass(frozen=True)
class LibraryCost:
    """A library the vehicle imports: the private bytes a bare interpreter gains importing the library's modules
    that the vehicle imports, how many modules, the other libraries that import loads with it, and where the
    vehicle's imports enter the library."""

    name: str
    private_bytes: int
    modules: int
    brings: list[str]
    entries: list[str]


def library_memory(records: dict[str, list[ImportRecord]], root: Path, floor: Interpreter) -> list[LibraryCost]:
    """The cost of every top-level package the five import that is not the checkout's (counting only modules a bare
    interpreter has not loaded already); largest first."""
    modules: dict[str, set[str]] = {}
    # where the vehicle's imports enter each library: (module, its importer) -> the processes, the longest import
    entries: dict[str, dict[tuple[str, str], tuple[list[str], int]]] = {}
    for role in ROLES:
        for record in records[role.key]:
            if record.name in floor.modules:
                continue
            package = _package(record.name)
            modules.setdefault(package, set()).add(record.name)
            importer = record.parent.name if record.parent is not None else "(run time)"
            if record.parent is None or _package(importer) != package:
                users, longest = entries.setdefault(package, {}).get((record.name, importer), ([], 0))
                if role.python not in users:
                    users.append(role.python)
                entries[package][(record.name, importer)] = (users, max(longest, record.cumulative_us))
    floor_packages = {_package(m) for m in floor.modules}
    out = []
    for package, names in modules.items():
        if (root / package / "__init__.py").is_file():
            continue
        loaded = interpreter_memory(sorted(names))
        if loaded is None:
            continue
        others = {_package(m) for m in loaded.modules} - floor_packages - {package}
        brings = sorted(p for p in others if p in modules)  # other libraries of the vehicle's that come with it
        ranked = sorted(entries.get(package, {}).items(), key=lambda item: -item[1][1])
        where = [f"{module} <- {importer} ({', '.join(users)})" for (module, importer), (users, _) in ranked]
        out.append(LibraryCost(package, loaded.memory.private_bytes - floor.memory.private_bytes, len(names), brings,
                               where))
    return sorted(out, key=lambda row: -row.private_bytes)


def _package(module: str) -> str:
    return module.split(".", 1)[0]


def import_report(python_root: Path | None, warp: int, top: int, keep: bool, progress: Callable[[str], None]) -> int:
    """Each Python process's import cost: modules, import time, the modules with the most time of their own and
    what imported them; then a bare interpreter's memory and what the libraries the five import add to it."""
    records, private = profile_imports(python_root, warp, keep, progress)
    by_package: Counter[str] = Counter()
    for role in ROLES:
        mine = records[role.key]
        packages = self_time_by_package(mine)
        by_package.update(packages)
        print(f"\n## {role.python}: {len(mine)} modules, {total_us(mine) / 1000:.0f} ms of imports, "
              f"private {private[role.key] / MIB:.1f} MiB")
        print("own import time by top-level package: " + ", ".join(
            f"{name} {us / 1000:.0f} ms" for name, us in packages.most_common(8)))
        for record in top_by_self(mine, top):
            print(f"  {describe(record)}")
    print("\nall five, own import time by top-level package: " + ", ".join(
        f"{name} {us / 1000:.0f} ms" for name, us in by_package.most_common(12)))
    floor = interpreter_memory()
    if floor is None:
        progress("(cannot read a bare interpreter's memory)")
        return 1
    print(f"\nbare interpreter ({sys.executable}; site and .pth files): private "
          f"{floor.memory.private_bytes / MIB:.1f} MiB, RSS {floor.memory.rss_bytes / MIB:.1f} MiB")
    print("private memory a bare interpreter gains importing each library's modules that the vehicle imports "
          "(with the libraries of 1 MiB or more each loads: rows overlap):")
    costs = library_memory(records, python_root or REPO, floor)
    heavy = {c.name for c in costs if c.private_bytes >= MIB and not c.name.startswith("_")}  # worth naming
    for library in costs[:top]:
        more = f"; and {len(library.entries) - 3} more" if len(library.entries) > 3 else ""
        brings = [name for name in library.brings if name in heavy]
        brings_text = f", loads {', '.join(brings)}" if brings else ""
        print(f"  {library.name}: +{library.private_bytes / MIB:.1f} MiB ({library.modules} modules{brings_text}); "
              f"entered as {'; '.join(library.entries[:3])}{more}")
    return 0
