"""The MOOSDB's work over every variable, done a slice at a time: server requests (``ALL``, ``PROC_SUMMARY``,
``VAR_SUMMARY``, ``DB_CLEAR``) and the ``DB_VARSUMMARY`` and ``DB_RWSUMMARY`` tables.

Each piece of work is a *job*: a generator that yields after each step of ``JOB_STEP`` or so variables and returns
its replies (or None). Names are sorted ``SORT_RUN`` at a time and the sorted runs merged lazily, so no step sorts
100,000 names at once. :class:`JobQueue` advances jobs in turn for about ``JOB_SLICE_S`` per call, so one request
never holds the server's one I/O thread for more than a few milliseconds; a request's replies that are not ready
within the packet that asked are encoded as a job too, then handed to ``deliver`` (the DB holds them as mail).

Everything here runs on the caller's thread, the server's one I/O thread; nothing is thread-safe.
"""

from __future__ import annotations

import heapq
import time as _time
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator, Mapping
from typing import TYPE_CHECKING, TypeVar

from .codec import encode_message
from .db_limits import MAX_SUMMARY_BYTES, cut
from .message import BINARY, DOUBLE, NOTIFY, STRING, MoosMessage, to_bytes, to_str

if TYPE_CHECKING:  # the DB imports this module: its types are only named here
    from .database import DBVar, MoosDatabase

MAX_JOBS_PER_CLIENT = 4  # server requests one client may have in progress
JOB_SLICE_S = 0.002  # how long jobs may hold the caller at a time
JOB_STEP = 256  # variables per job step (~0.5 ms of formatting)
SORT_RUN = 4096  # names sorted per step; the runs are merged lazily

Steps = Generator[None, None, list[MoosMessage] | None]
T = TypeVar("T")


class Job:
    """One piece of work over many variables, advanced a step at a time by :class:`JobQueue`."""

    __slots__ = ("owner", "steps", "inline")

    def __init__(self, owner: bytes | None, steps: Steps) -> None:
        self.owner = owner  # the requesting client (its replies are held for it), None for the DB's own work
        self.steps = steps
        self.inline = True  # still inside the process() call that made it: replies go back with the packet


class JobQueue:
    """Jobs in progress, advanced in turn; ``deliver(owner, encoded replies)`` takes late replies."""

    def __init__(self, deliver: Callable[[bytes, list[bytes]], None]) -> None:
        self._deliver = deliver
        self._jobs: deque[Job] = deque()
        self._new: list[Job] = []  # added since the last run: the packet that asked may still carry the replies

    @property
    def pending(self) -> bool:
        """True while work is left."""
        return bool(self._jobs or self._new)

    @property
    def has_new(self) -> bool:
        return bool(self._new)

    def add(self, owner: bytes | None, steps: Steps) -> None:
        self._new.append(Job(owner, steps))

    def in_progress(self, owner: bytes) -> int:
        """How many of ``owner``'s jobs are not finished."""
        return sum(1 for job in self._jobs if job.owner == owner) + sum(1 for job in self._new if job.owner == owner)

    def run(self, budget_s: float = JOB_SLICE_S) -> None:
        """Advance every job in turn for about ``budget_s`` (at least one step); finished replies are delivered."""
        for job in self._new:
            job.inline = False
        self._jobs.extend(self._new)
        self._new = []
        self._advance(self._jobs, _time.monotonic() + budget_s)

    def run_new(self) -> list[MoosMessage]:
        """Give the new jobs one slice: small ones finish and their replies are returned, to go with the packet."""
        new, self._new = deque(self._new), []
        replies: list[MoosMessage] = []
        self._advance(new, _time.monotonic() + JOB_SLICE_S, replies)
        for job in new:
            job.inline = False
        self._jobs.extend(new)
        return replies

    def _advance(self, jobs: deque[Job], deadline: float, inline: list[MoosMessage] | None = None) -> None:
        while jobs:
            job = jobs[0]
            try:
                next(job.steps)
            except StopIteration as done:
                jobs.popleft()
                result = done.value
                if result and job.owner is not None:
                    if job.inline and inline is not None:
                        inline[:0] = result  # C++ pushes each request's replies to the front
                    else:  # encoding 100,000 replies is a job too
                        jobs.append(Job(None, self._deliver_steps(job.owner, result)))
            else:
                jobs.rotate(-1)
            if _time.monotonic() >= deadline:
                return

    def _deliver_steps(self, owner: bytes, replies: list[MoosMessage]) -> Steps:
        """Encode a late request's replies a slice at a time, then deliver them all at once (one packet)."""
        wire: list[bytes] = []
        for start in range(0, len(replies), 4 * JOB_STEP):
            wire.extend(encode_message(m) for m in replies[start:start + 4 * JOB_STEP])
            yield
        self._deliver(owner, wire)
        return None


def drain(steps: Generator[None, None, T]) -> T:
    """Run a job's steps to the end at once (for callers that want the result now)."""
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value


# ---- walking the variables in name order ----------------------------------------------------------------
def sorted_names(names: Iterable[bytes]) -> Generator[None, None, Iterator[bytes]]:
    """``names`` in order (C++'s std::map order), sorted a run at a time and merged lazily."""
    names = list(names)
    if len(names) <= SORT_RUN:
        return iter(sorted(names))
    runs = []
    for start in range(0, len(names), SORT_RUN):
        runs.append(sorted(names[start:start + SORT_RUN]))
        yield
    return heapq.merge(*runs)


def sorted_vars(variables: Mapping[bytes, DBVar]) -> Generator[None, None, Iterator[DBVar]]:
    """The variables in name order; one removed (or cleared away) before the walk reaches it is skipped."""
    names = yield from sorted_names(variables)
    found = (variables.get(name) for name in names)
    return (var for var in found if var is not None)


def rw_lists(variables: Mapping[bytes, DBVar]
             ) -> Generator[None, None, tuple[dict[bytes, list[bytes]], dict[bytes, list[bytes]]]]:
    """(client -> variables it subscribes to, client -> variables it wrote), in name order: one pass."""
    subs: dict[bytes, list[bytes]] = {}
    pubs: dict[bytes, list[bytes]] = {}
    ordered = yield from sorted_vars(variables)
    for i, var in enumerate(ordered, 1):
        for client in var.subscribers:
            subs.setdefault(client, []).append(var.name)
        for client in var.writers:
            pubs.setdefault(client, []).append(var.name)
        if i % JOB_STEP == 0:
            yield
    return subs, pubs


def cached_rw_lists(db: MoosDatabase
                    ) -> Generator[None, None, tuple[dict[bytes, list[bytes]], dict[bytes, list[bytes]]]]:
    """:func:`rw_lists` of the DB's variables, reused while no subscription or writer changed (``rw_version``):
    a publishing client asks for PROC_SUMMARY every second, and the answer rarely changes."""
    cache = db.rw_cache
    if cache is not None and cache[0] == db.rw_version:
        return cache[1], cache[2]
    version = db.rw_version
    subs, pubs = yield from rw_lists(db.vars)
    if db.rw_version == version:
        db.rw_cache = (version, subs, pubs)
    return subs, pubs


# ---- server requests ------------------------------------------------------------------------------------
def all_steps(db: MoosDatabase, msg: MoosMessage) -> Steps:
    """``ALL``: every variable as a notification, times relative to the DB's start."""
    replies: list[MoosMessage] = []
    variables = yield from sorted_vars(db.vars)
    for i, var in enumerate(variables, 1):
        rel = var.written_time - db.start_time
        replies.append(MoosMessage(
            NOTIFY, var.data_type, msg.msg_id, var.writer, var.aux, var.community, var.name,
            rel if rel >= 0 else -1.0, var.dval, var.write_freq, var.sval,
        ))
        if i % JOB_STEP == 0:
            yield
    replies.reverse()  # C++ pushes each to the front
    return replies


def var_names_steps(db: MoosDatabase, msg: MoosMessage) -> Steps:
    """``VAR_SUMMARY``: every variable name, comma-separated."""
    names = yield from sorted_names(db.vars)
    parts: list[bytes] = []
    for i, name in enumerate(names, 1):
        parts.append(name)
        if i % (8 * JOB_STEP) == 0:
            yield
    return [MoosMessage(NOTIFY, STRING, msg.msg_id, db.name, key=b"VAR_SUMMARY", msg_time=db.clock.time(),
                        sval=b",".join(parts))]


def proc_summary_steps(db: MoosDatabase, msg: MoosMessage) -> Steps:
    """``PROC_SUMMARY``: one ``client:SUBSCRIBED=,A,B,PUBLISHED=,X`` line per connected client."""
    subs, pubs = yield from cached_rw_lists(db)
    now = db.clock.time()
    replies = []
    for client in db.clients:
        sub, pub = subs.get(client), pubs.get(client)
        text = (client + b":SUBSCRIBED=" + (b"," + b",".join(sub) if sub else b"") + b",PUBLISHED="
                + (b"," + b",".join(pub) if pub else b""))
        yield
        replies.append(MoosMessage(NOTIFY, STRING, msg.msg_id, db.name, key=b"PROC_SUMMARY",
                                   msg_time=now - db.start_time, sval=cut(text)))
    replies.reverse()
    return replies


def clear_steps(variables: Mapping[bytes, DBVar], up_to: int, forget: Callable[[DBVar], None]) -> Steps:
    """``DB_CLEAR`` a slice at a time: ``forget`` each variable last written at or before write ``up_to`` (a
    variable written after the request keeps that write)."""
    for i, var in enumerate(list(variables.values()), 1):
        if var.seq <= up_to:
            forget(var)
        if i % (4 * JOB_STEP) == 0:
            yield
    return None


# ---- DB_* summaries -------------------------------------------------------------------------------------
def rw_summary_steps(db: MoosDatabase) -> Generator[None, None, bytes]:
    """``DB_RWSUMMARY``: ``client=sub1:sub2&pub1:pub2,...`` for every connected client."""
    subs, pubs = yield from cached_rw_lists(db)
    return cut(b",".join(client + b"=" + b":".join(subs.get(client, ())) + b"&" + b":".join(pubs.get(client, ()))
                         for client in db.clients))


def var_summary_steps(variables: Mapping[bytes, DBVar]) -> Generator[None, None, bytes]:
    """``DB_VARSUMMARY``: one padded line per variable, cut at ``MAX_SUMMARY_BYTES``."""
    lines: list[str] = []
    size = 0
    count = len(variables)
    ordered = yield from sorted_vars(variables)
    for i, var in enumerate(ordered, 1):
        line = summary_line(var)
        size += len(line)
        if size > MAX_SUMMARY_BYTES:
            lines.append(f"... and {count - i + 1} more variables (summary cut at {MAX_SUMMARY_BYTES} bytes)\n")
            break
        lines.append(line)
        if i % JOB_STEP == 0:
            yield
    return to_bytes("".join(lines))


def summary_line(var: DBVar) -> str:
    """One variable's line of ``DB_VARSUMMARY``, as CMOOSDB::UpdateSummaryVar prints it."""
    stamp = _time.localtime(var.written_time)
    when = _time.strftime("%H:%M:%S", stamp) + f".{int((var.written_time % 1) * 1000):03d}"
    who = to_str(var.writer) if var.writer else "(write pending)"
    if var.data_type == DOUBLE:
        value = f"{var.dval:.1f}"
    elif var.data_type == BINARY:
        n = len(var.sval)
        value = (f"*binary* {n:<4d} B  " if n < 1024 else f"*binary* {n / 1024:.3f} KB " if n < 1024 * 1024
                 else f"*binary* {n / 1048576:.3f} MB ")
    elif var.data_type == STRING:
        text = to_str(var.sval[:25])
        value = text[:22] + "..." if len(var.sval) > 25 else text
    else:
        value = ""
    return (f"{to_str(var.name):<20} {when:<20} {who:<20} {var.write_freq:<4.1f}Hz "
            f"{var.data_type.decode('latin-1'):<2} {value:<20}\n")
