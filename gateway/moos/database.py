"""MOOSDB semantics without sockets: variables, type lock, subscriptions, wildcard filters, held mail,
server requests and the DB_* variables (CMOOSDB). The network layer (``server.py``) feeds it decoded messages.

Identity comes from each message's ``src``, as in C++. Held mail is a per-client FIFO of *encoded* messages,
so a notification fanned out to many subscribers is serialised once.
"""

from __future__ import annotations

import logging
import time as _time

from . import message as msg_kinds
from .clock import MoosClock
from .codec import encode_message
from .message import BINARY, DOUBLE, NOT_SET, NOTIFY, STRING, MoosMessage, to_bytes, to_str
from .wildcard import wild_match

log = logging.getLogger(__name__)

SUMMARY_PERIOD_S = 2.0


class DBVar:
    """One variable (CMOOSDBVar)."""

    __slots__ = (
        "name", "data_type", "dval", "sval", "msg_time", "written_time", "writer", "aux", "community",
        "written", "write_freq", "stats_time", "stats_writes", "subscribers", "writers",
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
        self.write_freq = 0.0
        self.stats_time = 0.0
        self.stats_writes = 0
        self.writers: set[bytes] = set()

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

    def __init__(self, community: str = "#1", clock: MoosClock | None = None) -> None:
        self.community = to_bytes(community)
        self.name = b"MOOSDB_" + self.community
        self.clock = clock or MoosClock()
        self.start_time = self.clock.time()
        self._summary_time = self.start_time
        self.vars: dict[bytes, DBVar] = {}
        self.clients: dict[bytes, bool] = {}  # name -> asynchronous, in connection order
        self.held: dict[bytes, list[bytes]] = {}
        self.mail_waiting: set[bytes] = set()
        self.filters: dict[bytes, dict[tuple[bytes, bytes], float]] = {}
        self.qos: dict[bytes, list[float]] = {}  # name -> [recent, max, min, sum, count] in ms
        self.rejected_writes = 0
        now = self.clock.time()
        for var_name, data_type in (
            (b"DB_TIME", DOUBLE), (b"DB_UPTIME", DOUBLE), (b"DB_CLIENTS", DOUBLE), (b"DB_EVENT", STRING),
            (b"DB_VARSUMMARY", STRING), (b"DB_QOS", STRING), (b"DB_RWSUMMARY", STRING),
        ):
            var = DBVar(var_name, data_type)
            var.writer, var.community, var.written_time = self.name, self.community, now
            self.vars[var_name] = var

    # ---- clients -----------------------------------------------------------------------------------
    def connect(self, name: bytes, asynchronous: bool) -> None:
        self.clients[name] = asynchronous
        self.held[name] = []
        self._internal_notify(b"DB_EVENT", b"connected=" + name)

    def disconnect(self, name: bytes) -> None:
        """Drop the client's subscriptions, filters and held mail; its written values stay."""
        if self.clients.pop(name, None) is None:
            return
        for var in self.vars.values():
            var.subscribers.pop(name, None)
        self.filters.pop(name, None)
        self.held.pop(name, None)
        self.mail_waiting.discard(name)
        self.qos.pop(name, None)
        self._internal_notify(b"DB_EVENT", b"disconnected=" + name)

    def take_mail(self, name: bytes) -> list[bytes]:
        """Remove and return the encoded messages held for ``name``, in the order they were queued."""
        self.mail_waiting.discard(name)
        box = self.held.get(name)
        if not box:
            return []
        self.held[name] = []
        return box

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
    def process(self, messages: list[MoosMessage]) -> tuple[list[MoosMessage], bool]:
        """Apply a packet's messages (a leading T already removed); return (server-request replies, had N)."""
        replies: list[MoosMessage] = []
        had_notify = False
        now = self.clock.time()
        for msg in messages:
            kind = msg.msg_type
            if kind == NOTIFY:  # the common case first; the rest are rare (registrations, server requests)
                self.notify(msg, now)
                had_notify = True
            elif kind == msg_kinds.REGISTER:
                self.register(msg.raw_src, msg.raw_key, msg.dval)
            elif kind == msg_kinds.UNREGISTER:
                self.unregister(msg.raw_src, msg.raw_key)
            elif kind == msg_kinds.WILDCARD_REGISTER:
                self.wildcard_register(msg.raw_src, *parse_filter(msg.raw_sval))
            elif kind == msg_kinds.WILDCARD_UNREGISTER:
                app, var, _ = parse_filter(msg.raw_sval)
                self.wildcard_unregister(msg.raw_src, app, var)
            elif kind == msg_kinds.SERVER_REQUEST:
                replies[:0] = self.server_request(msg)
        self.maybe_publish_summaries(now)
        return replies, had_notify

    def notify(self, msg: MoosMessage, now: float | None = None) -> bool:
        """``OnNotify``: store, type-lock, fan out to due subscribers. False when the type lock rejects it."""
        if now is None:
            now = self.clock.time()
        key = msg.raw_key
        var = self.vars.get(key)
        if var is None:
            var = self.vars[key] = DBVar(key, msg.data_type)
        if var.written == 0:
            var.data_type = msg.data_type
            for client, filters in self.filters.items():
                for (app, pattern), period in filters.items():
                    if wild_match(app, msg.raw_src) and wild_match(pattern, key):
                        var.subscribers[client] = [period, 0.0]
        if var.data_type != msg.data_type:
            self.rejected_writes += 1
            log.warning(
                "rejected write to %r by %r: the variable is type %s, the message is type %s (type is locked by "
                "the first write)", to_str(key), to_str(msg.raw_src), var.data_type.decode(), msg.data_type.decode(),
            )
            return False
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
        var.writers.add(msg.raw_src)
        var.written += 1
        dt = now - var.stats_time
        if dt > 0.5:
            if dt > 10.0:
                var.write_freq = 0.0
            else:
                var.write_freq = 0.5 * var.write_freq + 0.5 / (dt / (var.written - var.stats_writes))
            var.stats_writes, var.stats_time = var.written, now
        subscribers = var.subscribers
        if subscribers:
            msg.msg_type = NOTIFY
            wire = encode_message(msg)
            held = self.held
            waiting = self.mail_waiting
            for client, info in subscribers.items():
                if info[0] == 0.0 or now - info[1] >= info[0]:
                    box = held.get(client)
                    if box is not None:
                        box.append(wire)
                        waiting.add(client)
                        info[1] = now
        return True

    def register(self, client: bytes, key: bytes, period: float) -> None:
        """``OnRegister``: (re)subscribe with ``period``; queue the current value if the variable was written."""
        if client not in self.clients:
            log.warning("ignored registration for %r from %r: no connected client has that name",
                        to_str(key), to_str(client))
            return
        var = self.vars.get(key)
        if var is None:
            var = self.vars[key] = DBVar(key, NOT_SET)
        var.subscribers[client] = [max(0.0, period), 0.0]
        if var.written:
            self._hold(client, var.as_message())
            var.subscribers[client][1] = self.clock.time()

    def unregister(self, client: bytes, key: bytes) -> None:
        var = self.vars.get(key)
        if var is not None:
            var.subscribers.pop(client, None)

    def wildcard_register(self, client: bytes, app: bytes, pattern: bytes, period: float) -> None:
        """Store the filter (first period wins, as C++'s set does) and register every matching variable."""
        if client not in self.clients:
            log.warning("ignored wildcard registration from %r: no connected client has that name", to_str(client))
            return
        self.filters.setdefault(client, {}).setdefault((app, pattern), period)
        for var in list(self.vars.values()):
            if wild_match(app, var.writer) and wild_match(pattern, var.name):
                self.register(client, var.name, period)

    def wildcard_unregister(self, client: bytes, app: bytes, pattern: bytes) -> None:
        """Unsubscribe matching variables. As in C++ the stored filter stays (new variables still match)."""
        for var in self.vars.values():
            if wild_match(app, var.writer) and wild_match(pattern, var.name):
                var.subscribers.pop(client, None)

    def _hold(self, client: bytes, msg: MoosMessage) -> None:
        box = self.held.get(client)
        if box is not None:
            box.append(encode_message(msg))
            self.mail_waiting.add(client)

    def _internal_notify(self, key: bytes, value: bytes | float) -> None:
        now = self.clock.time()
        if isinstance(value, bytes):
            msg = MoosMessage(NOTIFY, STRING, src=self.name, community=self.community, key=key, msg_time=now, sval=value)
        else:
            msg = MoosMessage(NOTIFY, DOUBLE, src=self.name, community=self.community, key=key, msg_time=now, dval=value)
        self.notify(msg)

    # ---- server requests ---------------------------------------------------------------------------
    def server_request(self, msg: MoosMessage) -> list[MoosMessage]:
        """Replies to a ``Q`` message, in the order C++ sends them (it pushes each to the front)."""
        what = msg.raw_key
        now = self.clock.time()
        replies: list[MoosMessage] = []
        if what == b"ALL":
            for var in sorted(self.vars.values(), key=lambda v: v.name):
                rel = var.written_time - self.start_time
                replies.insert(0, MoosMessage(
                    NOTIFY, var.data_type, msg.msg_id, var.writer, var.aux, var.community, var.name,
                    rel if rel >= 0 else -1.0, var.dval, var.write_freq, var.sval,
                ))
        elif b"PROC_SUMMARY" in what:
            for client in self.clients:
                subscribed = b"SUBSCRIBED="
                published = b"PUBLISHED="
                for var in sorted(self.vars.values(), key=lambda v: v.name):
                    if client in var.writers:
                        published += b"," + var.name
                    if client in var.subscribers:
                        subscribed += b"," + var.name
                replies.insert(0, MoosMessage(
                    NOTIFY, STRING, msg.msg_id, self.name, key=b"PROC_SUMMARY", msg_time=now - self.start_time,
                    sval=client + b":" + subscribed + b"," + published,
                ))
        elif b"VAR_SUMMARY" in what:
            replies.append(MoosMessage(
                NOTIFY, STRING, msg.msg_id, self.name, key=b"VAR_SUMMARY", msg_time=now,
                sval=b",".join(sorted(self.vars)),
            ))
        elif b"DB_CLEAR" in what:
            log.warning("DB_CLEAR requested by %r: resetting %d variables and all held mail",
                        to_str(msg.raw_src), len(self.vars))
            for var in self.vars.values():
                var.reset()
            for client in self.held:
                self.held[client] = []
            self.mail_waiting.clear()
            self.start_time = now
        else:
            log.info("ignored unknown server request %r from %r", to_str(what), to_str(msg.raw_src))
        return replies

    # ---- DB_* variables ----------------------------------------------------------------------------
    def maybe_publish_summaries(self, now: float | None = None) -> None:
        """Every 2 s of DB MOOS time (checked when packets arrive): DB_TIME, DB_UPTIME, DB_CLIENTS, ..."""
        if now is None:
            now = self.clock.time()
        if now - self._summary_time <= SUMMARY_PERIOD_S:
            return
        self._summary_time = now
        self._internal_notify(b"DB_TIME", now)
        self._internal_notify(b"DB_UPTIME", now - self.start_time)
        self._internal_notify(b"DB_CLIENTS", b"".join(c + b"," for c in self.clients))
        self._internal_notify(b"DB_VARSUMMARY", self.var_summary())
        if self.qos:
            self._internal_notify(b"DB_QOS", b"".join(
                c + b"=" + f"{s[0]:.2f}:{s[1]:.2f}:{s[2]:.2f}:{s[3] / s[4]:.2f}".encode() + b","
                for c, s in self.qos.items()
            ))
        self._internal_notify(b"DB_RWSUMMARY", self.rw_summary())

    def rw_summary(self) -> bytes:
        """``client=sub1:sub2&pub1:pub2,...`` for every connected client."""
        entries = []
        ordered = sorted(self.vars.values(), key=lambda v: v.name)
        for client in self.clients:
            subs = b":".join(v.name for v in ordered if client in v.subscribers)
            pubs = b":".join(v.name for v in ordered if client in v.writers)
            entries.append(client + b"=" + subs + b"&" + pubs)
        return b",".join(entries)

    def var_summary(self) -> bytes:
        """The DB_VARSUMMARY table: one padded line per variable, as CMOOSDB::UpdateSummaryVar prints it."""
        lines = []
        for var in sorted(self.vars.values(), key=lambda v: v.name):
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
                text = to_str(var.sval)
                value = text[:22] + "..." if len(var.sval) > 25 else text
            else:
                value = ""
            lines.append(
                f"{to_str(var.name):<20} {when:<20} {who:<20} {var.write_freq:<4.1f}Hz "
                f"{var.data_type.decode('latin-1'):<2} {value:<20}\n"
            )
        return to_bytes("".join(lines))
