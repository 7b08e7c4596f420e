"""What ``/proc`` says about a running process and its descendants: CPU seconds and memory.

CPU is ``utime + stime`` from ``/proc/<pid>/stat`` (every thread of the process, ended ones included, in clock
ticks: 10 ms here), and in nanoseconds the run time of each thread from ``/proc/<pid>/task/<tid>/schedstat``, which
``cpu_between`` uses when no thread ended in between (an ended thread's time is only in ``stat``); memory is
``/proc/<pid>/smaps_rollup``: private (``Private_Clean + Private_Dirty``, what the process alone costs the
machine) and RSS (which also counts shared pages: the interpreter, shared libraries). Pure readers: a process that
has gone is simply left out.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

CLK_TCK = os.sysconf("SC_CLK_TCK")


@dataclass(frozen=True)
class ProcSample:
    """One reading of a process: CPU seconds used so far, private and resident memory in bytes."""

    pid: int
    cpu_s: float
    private_bytes: int
    rss_bytes: int
    start_ticks: int  # start time in clock ticks since boot: tells a reused pid apart
    thread_ns: dict[int, int] = field(default_factory=dict)  # thread id -> CPU nanoseconds (schedstat)


def parse_stat(text: str) -> tuple[int, float, int]:
    """(parent pid, CPU seconds, start time in ticks) from the text of ``/proc/<pid>/stat``.

    The command name (field 2) may hold spaces and parentheses, so fields are counted after its last ``)``.
    """
    fields = text.rsplit(")", 1)[1].split()
    # after the name: state ppid pgrp session tty tpgid flags minflt cminflt majflt cmajflt utime stime ... starttime
    return int(fields[1]), (int(fields[11]) + int(fields[12])) / CLK_TCK, int(fields[19])


def parse_smaps_rollup(text: str) -> tuple[int, int]:
    """(private bytes, RSS bytes) from the text of ``/proc/<pid>/smaps_rollup``."""
    values: dict[str, int] = {}
    for line in text.splitlines():
        key, sep, rest = line.partition(":")
        parts = rest.split()
        if sep and len(parts) == 2 and parts[1] == "kB":
            values[key] = int(parts[0]) * 1024
    return values.get("Private_Clean", 0) + values.get("Private_Dirty", 0), values.get("Rss", 0)


def thread_run_times(pid: int) -> dict[int, int]:
    """Thread id -> CPU nanoseconds so far (first field of ``schedstat``), for the threads that could be read."""
    out: dict[int, int] = {}
    try:
        tids = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return out
    for tid in tids:
        try:
            out[int(tid)] = int(Path(f"/proc/{pid}/task/{tid}/schedstat").read_text().split()[0])
        except (OSError, IndexError, ValueError):
            continue
    return out


def sample(pid: int) -> ProcSample | None:
    """The process's CPU and memory now, or None if it has gone (or cannot be read)."""
    try:
        threads = thread_run_times(pid)
        _, cpu, start = parse_stat(Path(f"/proc/{pid}/stat").read_text())
        private, rss = parse_smaps_rollup(Path(f"/proc/{pid}/smaps_rollup").read_text())
    except (OSError, IndexError, ValueError):
        return None
    return ProcSample(pid, cpu, private, rss, start, threads)


def children_by_parent() -> dict[int, list[int]]:
    """Every process's children, from one pass over ``/proc``."""
    tree: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            ppid, _, _ = parse_stat(Path(f"/proc/{entry}/stat").read_text())
        except (OSError, IndexError, ValueError):
            continue
        tree.setdefault(ppid, []).append(int(entry))
    return tree


def subtree(root: int, tree: dict[int, list[int]]) -> list[int]:
    """``root`` and all its descendants in ``tree``."""
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo.extend(tree.get(pid, []))
    return out


def sample_tree(root: int, tree: dict[int, list[int]] | None = None) -> list[ProcSample]:
    """A sample of ``root`` and of each of its descendants that could be read."""
    pids = subtree(root, children_by_parent() if tree is None else tree)
    return [s for s in (sample(pid) for pid in pids) if s is not None]


def process_cpu_between(before: ProcSample | None, after: ProcSample) -> float:
    """CPU seconds one process used between two samples (``before`` None: since it started). In nanoseconds from
    its threads when each thread of ``before`` is still there (a thread started meanwhile counts whole), else in
    ticks from ``stat``."""
    if before is None:
        return after.cpu_s
    if before.thread_ns and before.thread_ns.keys() <= after.thread_ns.keys():
        return sum(ns - before.thread_ns.get(tid, 0) for tid, ns in after.thread_ns.items()) / 1e9
    return after.cpu_s - before.cpu_s


def cpu_between(before: Iterable[ProcSample], after: Iterable[ProcSample]) -> float:
    """CPU seconds used between two samplings of the same processes. A process seen only in ``after`` (a child
    started meanwhile) counts whole; one seen only in ``before`` (ended meanwhile) is lost, as its counters are."""
    first = {(s.pid, s.start_ticks): s for s in before}
    return sum(process_cpu_between(first.get((s.pid, s.start_ticks)), s) for s in after)


def program_name(pid: int) -> str:
    """What a process runs: the console script or ``-m`` module (``moos-db``, ``launch.trail.moos_gen``) of a
    Python process, else its executable's name (``MOOSDB``); "?" if it has gone."""
    try:
        args = [a.decode(errors="replace") for a in Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0") if a]
    except OSError:
        return "?"
    if not args:
        return "?"
    if "python" in Path(args[0]).name and len(args) > 1:
        return args[2] if args[1] == "-m" and len(args) > 2 else Path(args[1]).name
    return Path(args[0]).name


def wakeups(pid: int) -> int:
    """Voluntary context switches of every thread of ``pid`` so far (a thread that ended is not counted)."""
    total = 0
    try:
        tids = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return 0
    for tid in tids:
        try:
            text = Path(f"/proc/{pid}/task/{tid}/status").read_text()
        except OSError:
            continue
        for line in text.splitlines():
            if line.startswith("voluntary_ctxt_switches:"):
                total += int(line.split()[1])
    return total


def machine_ticks() -> tuple[int, int]:
    """(busy, all) clock ticks of the whole machine since boot, from ``/proc/stat`` (idle and iowait are not busy)."""
    values = [int(v) for v in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    return sum(values) - values[3] - values[4], sum(values)
