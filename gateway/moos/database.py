"""MOOSDB semantics without sockets: variables, type lock, subscriptions, wildcard filters, held mail,
server requests and the DB_* variables (CMOOSDB). The network layer (``server.py``) feeds it decoded messages.

Identity comes from each message's ``src``, as in C++; the caps (variables per DB and per client, name lengths,
stored bytes) are charged to the connection that sent the packet, which the server passes in. Held mail is a
per-client FIFO of *encoded* messages, so a notification fanned out to many subscribers is serialised once.

Work over every variable (server requests, DB_VARSUMMARY, DB_RWSUMMARY, DB_CLEAR) runs as *jobs*
(``db_jobs.py``): generators advanced a slice at a time (``run_jobs``), so one request over 100,000 variables never
holds the server's one thread for more than a few milliseconds; replies that are not ready at once are held as mail
for the requester. The caps and the refusals they cause are counted by ``db_limits.py``.

Not thread-safe: the server calls everything here from its one I/O thread.
"""

from __future__ import annotations

import logging

from . import db_jobs
from . import message as msg_kinds
from .clock import MoosClock
from .codec import encode_message
from .db_jobs import JOB_SLICE_S, MAX_JOBS_PER_CLIENT, JobQueue, Steps, drain
from .db_limits import (
    MAX_NAME_BYTES,
    MAX_STORED_BYTES,
    MAX_VARIABLES,
    MAX_VARIABLES_PER_CLIENT,
    DBLimits,
    preview,
)
from .message import DOUBLE, NOT_SET, NOTIFY, STRING, MoosMessage, to_bytes
from .wildcard import wild_match

log = logging.getLogger(__name__)

SUMMARY_PERIOD_S = 2.0


class HeldMail:
    """Encoded messages held for one client: chunks of wire bytes (each one message, or a run of them forwarded
    as received) and how many messages they hold, so they are framed as one packet without re-encoding."""

    __slots__ = ("chunks", "count")

    def __init__(self) -> None:
        self.chunks: list[bytes] = []
        self.count = 0


class DBVar:
    """One variable (CMOOSDBVar)."""

    __slots__ = (
        "name", "data_type", "dval", "sval", "msg_time", "written_time", "writer", "aux", "community",
        "written", "write_freq", "stats_time", "stats_writes", "subscribers", "writers", "seq", "typed_by",
    )

    def __init__(self, name: bytes, data_type: bytes) -> None:
        self.name = name
        self.data_type = data_type
        self.subscribers: dict[bytes, list[float]] = {}  # client -> [period, last_sent]
        self.reset()

    def reset(self) -> None:
        """Forget value, writers and write count (DB_CLEAR); subscriptions stay."""
        self.dval = -1.0
        self.sval = b""
        self.msg_time = -1.0
        self.written_time = -1.0
        self.writer = b""
        self.aux = b""
        self.community = b""
        self.written = 0
        self.seq = 0  # the DB's write counter at the last write (DB_CLEAR spares later writes)
        self.typed_by = b""  # the client whose first write set the type
        self.write_freq = 0.0
        self.stats_time = 0.0
        self.stats_writes = 0
        self.writers: set[bytes] = set()

    def stored_bytes(self) -> int:
        """What this variable counts against ``max_stored_bytes``."""
        return len(self.name) + len(self.sval) + len(self.aux) + len(self.writer) + len(self.community)

    def as_message(self) -> MoosMessage:
        """``Var2Msg``: the current value as a notification with id -1."""
        msg = MoosMessage(NOTIFY, self.data_type, -1, self.writer, self.aux, self.community, self.name, self.msg_time)
        if self.data_type == DOUBLE:
            msg.dval = self.dval
        else:
            msg.raw_sval = self.sval
        return msg


def parse_filter(sval: bytes) -> tuple[bytes, bytes, float]:
    """``AppPattern=..,VarPattern=..,Interval=..`` → (app, var, interval), as ``MOOSValFromString`` reads it."""
    fields: dict[bytes, bytes] = {}
    for part in sval.split(b","):
        token, sep, value = part.partition(b"=")
        if sep and token.strip() not in fields:
            fields[token.strip()] = value.strip()
    try:
        interval = float(fields.get(b"Interval", b"0") or 0.0)
    except ValueError:
        interval = 0.0
    return fields.get(b"AppPattern", b""), fields.get(b"VarPattern", b""), interval


class MoosDatabase:
    """The DB proper. Not thread-safe: the server calls it from its one I/O thread."""

    def __init__(self, community: str = "#1", clock: MoosClock | None = None, *,
                 max_variables: int = MAX_VARIABLES, max_variables_per_client: int = MAX_VARIABLES_PER_CLIENT,
                 max_name_bytes: int = MAX_NAME_BYTES, max_stored_bytes: int = MAX_STORED_BYTES) -> None:
        self.community = to_bytes(community)
        self.name = b"MOOSDB_" + self.community
        self.clock = clock or MoosClock()
        self.start_time = self.clock.time()
        self._summary_time = self.start_time
        self.limits = DBLimits(max_variables, max_variables_per_client, max_name_bytes, max_stored_bytes)
        self.vars: dict[bytes, DBVar] = {}
        self.clients: dict[bytes, bool] = {}  # name -> asynchronous, in connection order
        self.held: dict[bytes, HeldMail] = {}
        self.mail_waiting: set[bytes] = set()
        self.filters: dict[bytes, dict[tuple[bytes, bytes], float]] = {}
        self.qos: dict[bytes, list[float]] = {}  # name -> [recent, max, min, sum, count] in ms
        self.rejected_writes = 0  # writes refused by the type lock
        self._write_seq = 0
        self.rw_version = 0  # bumped when who subscribes to or has written what changes (PROC_SUMMARY's cache)
        self.rw_cache: tuple[int, dict[bytes, list[bytes]], dict[bytes, list[bytes]]] | None = None
        self._jobs = JobQueue(self._hold_wire)
        self._summaries_running = False
        now = self.clock.time()
        for var_name, data_type in (
            (b"DB_TIME", DOUBLE), (b"DB_UPTIME", DOUBLE), (b"DB_CLIENTS", DOUBLE), (b"DB_EVENT", STRING),
            (b"DB_VARSUMMARY", STRING), (b"DB_QOS", STRING), (b"DB_RWSUMMARY", STRING), (b"DB_REFUSED", STRING),
        ):
            var = DBVar(var_name, data_type)
            var.writer, var.community, var.written_time = self.name, self.community, now
            self.vars[var_name] = var
            self.limits.stored_bytes += var.stored_bytes()

    # ---- caps (self.limits counts and refuses) -----------------------------------------------------
    @property
    def max_variables(self) -> int:
        return self.limits.max_variables

    @property
    def max_variables_per_client(self) -> int:
        return self.limits.max_variables_per_client

    @property
    def refusals(self) -> dict[tuple[bytes, str], int]:
        """(client, cause) -> messages refused, as published in DB_REFUSED."""
        return self.limits.refusals

    def flush_warnings(self) -> None:
        """Log the counts of refusals held back by the rate limit (the server calls this periodically)."""
        self.limits.flush_warnings()

    # ---- clients -----------------------------------------------------------------------------------
    def connect(self, name: bytes, asynchronous: bool) -> None:
        self.clients[name] = asynchronous
        self.held[name] = HeldMail()
        self._internal_notify(b"DB_EVENT", b"connected=" + name)

    def disconnect(self, name: bytes) -> None:
        """Drop the client's subscriptions, filters and held mail; its written values stay."""
        if self.clients.pop(name, None) is None:
            return
        for var in self.vars.values():
            var.subscribers.pop(name, None)
        self.rw_version += 1
        self.filters.pop(name, None)
        self.held.pop(name, None)
        self.mail_waiting.discard(name)
        self.qos.pop(name, None)
        self._internal_notify(b"DB_EVENT", b"disconnected=" + name)

    def take_mail(self, name: bytes) -> tuple[list[bytes], int]:
        """Remove and return the mail held for ``name`` in the order it was queued: (wire chunks, message count);
        ``frame_packet(chunks, count)`` makes it a packet."""
        self.mail_waiting.discard(name)
        box = self.held.get(name)
        if box is None or not box.count:
            return [], 0
        chunks, count = box.chunks, box.count
        box.chunks, box.count = [], 0
        return chunks, count

    def record_timing(self, name: bytes, latency_ms: float) -> None:
        stats = self.qos.get(name)
        if stats is None:
            self.qos[name] = [latency_ms, latency_ms, latency_ms, latency_ms, 1.0]
        else:
            stats[0] = latency_ms
            stats[1] = max(stats[1], latency_ms)
            stats[2] = min(stats[2], latency_ms)
            stats[3] += latency_ms
            stats[4] += 1.0

    # ---- packets -----------------------------------------------------------------------------------
    def process(self, messages: list[MoosMessage], client: bytes | None = None
                ) -> tuple[list[MoosMessage], bool]:
        """Apply a packet's messages (a leading T already removed); return (server-request replies, had N).

        ``client`` is the connection that sent them: caps are charged to it (default: each message's ``src``).
        Server requests that need more than ``JOB_SLICE_S`` finish later; their replies are then held as mail.
        """
        now = self.clock.time()
        had_notify = False
        for msg in messages:
            had_notify |= msg.msg_type == NOTIFY
            self.process_one(msg, now, client)
        return self.end_of_packet(now), had_notify

    def process_one(self, msg: MoosMessage, now: float, client: bytes | None = None) -> None:
        """Apply one message of a packet (``db_wire.process_wire`` calls this for all but runs of notifications)."""
        kind = msg.msg_type
        if kind == NOTIFY:  # the common case first; the rest are rare (registrations, server requests)
            self.notify(msg, now, client)
        elif kind == msg_kinds.REGISTER:
            self.register(msg.raw_src, msg.raw_key, msg.dval, client)
        elif kind == msg_kinds.UNREGISTER:
            self.unregister(msg.raw_src, msg.raw_key)
        elif kind == msg_kinds.WILDCARD_REGISTER:
            self.wildcard_register(msg.raw_src, *parse_filter(msg.raw_sval))
        elif kind == msg_kinds.WILDCARD_UNREGISTER:
            app, var, _ = parse_filter(msg.raw_sval)
            self.wildcard_unregister(msg.raw_src, app, var)
        elif kind == msg_kinds.SERVER_REQUEST:
            self._start_request(msg, client if client is not None else msg.raw_src)

    def end_of_packet(self, now: float) -> list[MoosMessage]:
        """After a packet: the DB_* summaries when due, and the replies of requests that fit one slice."""
        self.maybe_publish_summaries(now)
        return self._jobs.run_new() if self._jobs.has_new else []

    def notify(self, msg: MoosMessage, now: float | None = None, client: bytes | None = None) -> bool:
        """``OnNotify``: store, type-lock, fan out to due subscribers. False when refused (type lock, caps)."""
        if now is None:
            now = self.clock.time()
        key = msg.raw_key
        writer = msg.raw_src if client is None else client
        internal = writer == self.name
        limits = self.limits
        if not internal and not limits.names_fit(msg, writer):
            return False
        var = self.vars.get(key)
        if var is None:
            if not internal and not (limits.may_store(msg, None, writer)
                                     and limits.may_create(writer, key, "write", len(self.vars))):
                return False
            var = self.vars[key] = DBVar(key, msg.data_type)
            limits.stored_bytes += len(key)
        elif var.written and var.data_type != msg.data_type:
            # MOOSDB refuses too, on the wire without a word (a MOOSTrace on its console): so do we, but it is
            # counted (DB_REFUSED) and logged naming both sides, so a writer shut out by another is found.
            self.rejected_writes += 1
            limits.refuse(writer, "type_mismatch", "refused write to %s by %s: the variable is type %s since %s "
                          "wrote it first, the message is type %s (MOOS locks a variable's type on its first write)",
                          preview(key), preview(writer), var.data_type.decode("latin-1"), preview(var.typed_by),
                          msg.data_type.decode("latin-1"))
            return False
        elif not internal and not limits.may_store(msg, var, writer):
            return False
        if var.written == 0:
            var.data_type = msg.data_type
            var.typed_by = writer
            for filter_owner, filters in self.filters.items():
                for (app, pattern), period in filters.items():
                    if wild_match(app, msg.raw_src) and wild_match(pattern, key):
                        var.subscribers[filter_owner] = [period, 0.0]
                        self.rw_version += 1
        limits.stored_bytes -= len(var.aux) + len(var.writer) + len(var.community) + len(var.sval)
        var.written_time = now
        var.msg_time = msg.msg_time
        var.writer = msg.raw_src
        var.aux = msg.raw_aux
        if not msg.raw_community:
            msg.raw_community = self.community
        var.community = msg.raw_community
        if var.data_type == DOUBLE:
            var.dval = msg.dval
        else:
            var.sval = msg.raw_sval
        limits.stored_bytes += len(var.aux) + len(var.writer) + len(var.community) + len(var.sval)
        if msg.raw_src not in var.writers:
            var.writers.add(msg.raw_src)
            self.rw_version += 1
        self.count_writes(var, 1, now)
        if var.subscribers:
            msg.msg_type = NOTIFY
            wire = encode_message(msg)
            self.fan_out(var, wire, 1, wire, now)
        return True

    def count_writes(self, var: DBVar, n: int, now: float) -> None:
        """``n`` writes to ``var`` at ``now``: write count, the DB's write sequence, the write frequency."""
        var.written += 1
        dt = now - var.stats_time
        if dt > 0.5:
            if dt > 10.0:
                var.write_freq = 0.0
            else:
                var.write_freq = 0.5 * var.write_freq + 0.5 / (dt / (var.written - var.stats_writes))
            var.stats_writes, var.stats_time = var.written, now
        var.written += n - 1  # the rest came at the same ``now``: the estimate would not change again
        self._write_seq += n
        var.seq = self._write_seq

    def fan_out(self, var: DBVar, wire: bytes, n: int, first: bytes, now: float) -> None:
        """Hold ``n`` notifications of ``var`` (``wire``, the first alone ``first``) for its due subscribers: all
        for those registered with interval 0, else the first if the interval has passed (``now`` is one time for
        all ``n``, so at most one is due)."""
        held = self.held
        waiting = self.mail_waiting
        for subscriber, info in var.subscribers.items():
            period = info[0]
            if period == 0.0:
                box = held.get(subscriber)
                if box is not None:
                    box.chunks.append(wire)
                    box.count += n
                    waiting.add(subscriber)
                    info[1] = now
            elif now - info[1] >= period:
                box = held.get(subscriber)
                if box is not None:
                    box.chunks.append(first)
                    box.count += 1
                    waiting.add(subscriber)
                    info[1] = now

    def register(self, client: bytes, key: bytes, period: float, sender: bytes | None = None) -> None:
        """``OnRegister``: (re)subscribe with ``period``; queue the current value if the variable was written."""
        if client not in self.clients:
            log.warning("ignored registration for %s from %s: no connected client has that name",
                        preview(key), preview(client))
            return
        var = self.vars.get(key)
        if var is None:
            if not self.limits.may_create(client if sender is None else sender, key, "registration", len(self.vars)):
                return
            var = self.vars[key] = DBVar(key, NOT_SET)
            self.limits.stored_bytes += len(key)
        if client not in var.subscribers:
            self.rw_version += 1
        var.subscribers[client] = [max(0.0, period), 0.0]
        if var.written:
            self._hold(client, var.as_message())
            var.subscribers[client][1] = self.clock.time()

    def unregister(self, client: bytes, key: bytes) -> None:
        var = self.vars.get(key)
        if var is not None and var.subscribers.pop(client, None) is not None:
            self.rw_version += 1

    def wildcard_register(self, client: bytes, app: bytes, pattern: bytes, period: float) -> None:
        """Store the filter (first period wins, as C++'s set does) and register every matching variable."""
        if client not in self.clients:
            log.warning("ignored wildcard registration from %s: no connected client has that name", preview(client))
            return
        self.filters.setdefault(client, {}).setdefault((app, pattern), period)
        for var in list(self.vars.values()):
            if wild_match(app, var.writer) and wild_match(pattern, var.name):
                self.register(client, var.name, period)

    def wildcard_unregister(self, client: bytes, app: bytes, pattern: bytes) -> None:
        """Unsubscribe matching variables. As in C++ the stored filter stays (new variables still match)."""
        for var in self.vars.values():
            if wild_match(app, var.writer) and wild_match(pattern, var.name):
                if var.subscribers.pop(client, None) is not None:
                    self.rw_version += 1

    def _hold(self, client: bytes, msg: MoosMessage) -> None:
        box = self.held.get(client)
        if box is not None:
            box.chunks.append(encode_message(msg))
            box.count += 1
            self.mail_waiting.add(client)

    def _internal_notify(self, key: bytes, value: bytes | float) -> None:
        now = self.clock.time()
        if isinstance(value, bytes):
            msg = MoosMessage(NOTIFY, STRING, src=self.name, community=self.community, key=key, msg_time=now, sval=value)
        else:
            msg = MoosMessage(NOTIFY, DOUBLE, src=self.name, community=self.community, key=key, msg_time=now, dval=value)
        self.notify(msg)

    def _hold_wire(self, client: bytes, wire: list[bytes]) -> None:
        """Hold encoded messages for ``client`` all at once (one request's replies go in one packet)."""
        box = self.held.get(client)
        if box is not None:
            box.chunks.extend(wire)
            box.count += len(wire)
            self.mail_waiting.add(client)

    def _forget(self, var: DBVar) -> None:
        """DB_CLEAR of one variable: its value, writers and write count go; subscriptions stay."""
        self.limits.stored_bytes -= len(var.aux) + len(var.writer) + len(var.community) + len(var.sval)
        var.reset()
        self.rw_version += 1

    # ---- jobs (db_jobs.py) -------------------------------------------------------------------------
    @property
    def jobs_pending(self) -> bool:
        """True while work is left for ``run_jobs`` (the server then polls instead of sleeping)."""
        return self._jobs.pending

    def run_jobs(self, budget_s: float = JOB_SLICE_S) -> None:
        """Advance pending jobs in turn for about ``budget_s`` (at least one step); finished replies are held."""
        self._jobs.run(budget_s)

    # ---- server requests ---------------------------------------------------------------------------
    def server_request(self, msg: MoosMessage) -> list[MoosMessage]:
        """Replies to a ``Q`` message, in the order C++ sends them (it pushes each to the front), at once."""
        steps = self._request_steps(msg)
        return (drain(steps) if steps is not None else None) or []

    def _start_request(self, msg: MoosMessage, client: bytes) -> None:
        steps = self._request_steps(msg)
        if steps is None:
            return
        busy = self._jobs.in_progress(client)
        if busy >= MAX_JOBS_PER_CLIENT:
            steps.close()
            self.limits.refuse(client, "requests_in_progress", "refused server request %s from %s: %d of its "
                               "requests are still in progress", preview(msg.raw_key), preview(client), busy)
            return
        self._jobs.add(client, steps)

    def _request_steps(self, msg: MoosMessage) -> Steps | None:
        what = msg.raw_key
        if what == b"ALL":
            return db_jobs.all_steps(self, msg)
        if b"PROC_SUMMARY" in what:
            return db_jobs.proc_summary_steps(self, msg)
        if b"VAR_SUMMARY" in what:
            return db_jobs.var_names_steps(self, msg)
        if b"DB_CLEAR" in what:
            log.warning("DB_CLEAR requested by %s: resetting %d variables and all held mail",
                        preview(msg.raw_src), len(self.vars))
            for client in self.held:
                self.held[client] = HeldMail()
            self.mail_waiting.clear()
            self.start_time = self.clock.time()
            return db_jobs.clear_steps(self.vars, self._write_seq, self._forget)
        log.info("ignored unknown server request %s from %s", preview(what), preview(msg.raw_src))
        return None

    # ---- DB_* variables ----------------------------------------------------------------------------
    def maybe_publish_summaries(self, now: float | None = None) -> None:
        """Every 2 s of DB MOOS time (checked when packets arrive): DB_TIME, DB_UPTIME, DB_CLIENTS, ...

        DB_VARSUMMARY and DB_RWSUMMARY cover every variable: they are built as a job, a slice at a time.
        """
        if now is None:
            now = self.clock.time()
        if now - self._summary_time <= SUMMARY_PERIOD_S:
            return
        self._summary_time = now
        self._internal_notify(b"DB_TIME", now)
        self._internal_notify(b"DB_UPTIME", now - self.start_time)
        self._internal_notify(b"DB_CLIENTS", b"".join(c + b"," for c in self.clients))
        if self.qos:
            self._internal_notify(b"DB_QOS", b"".join(
                c + b"=" + f"{s[0]:.2f}:{s[1]:.2f}:{s[2]:.2f}:{s[3] / s[4]:.2f}".encode() + b","
                for c, s in self.qos.items()
            ))
        refused = self.limits.refused_report()
        if refused is not None:
            self._internal_notify(b"DB_REFUSED", refused)
        if not self._summaries_running:
            self._summaries_running = True
            self._jobs.add(None, self._summary_steps())

    def _summary_steps(self) -> Steps:
        try:
            text = yield from db_jobs.var_summary_steps(self.vars)
            self._internal_notify(b"DB_VARSUMMARY", text)
            text = yield from db_jobs.rw_summary_steps(self)
            self._internal_notify(b"DB_RWSUMMARY", text)
        finally:
            self._summaries_running = False
        return None

    def rw_summary(self) -> bytes:
        """``client=sub1:sub2&pub1:pub2,...`` for every connected client."""
        return drain(db_jobs.rw_summary_steps(self))

    def var_summary(self) -> bytes:
        """The DB_VARSUMMARY table: one padded line per variable, as CMOOSDB::UpdateSummaryVar prints it."""
        return drain(db_jobs.var_summary_steps(self.vars))
