"""The MOOSDB's caps and what they refused: variables per DB and per client, name lengths, stored bytes.

Pure bookkeeping for :class:`~gateway.moos.database.MoosDatabase`, which owns one :class:`DBLimits` and calls it
from the server's one I/O thread (not thread-safe). Each refusal is counted per client and cause (published as
``DB_REFUSED``) and logged, rate-limited per client and cause; ``flush_warnings`` reports what the limit held back.
"""

from __future__ import annotations

import logging
from typing import Protocol

from util.ratelimit import RateLimitedLog

from .message import DOUBLE, MoosMessage, to_str

log = logging.getLogger("gateway.moos.database")  # the refusals are the DB's: one logger for operators to filter

MAX_VARIABLES = 100_000  # per DB: a community of even a hundred apps uses a few thousand
MAX_VARIABLES_PER_CLIENT = 20_000  # variables one client name may create (by writing or registering)
MAX_NAME_BYTES = 256  # client, variable, source, aux and community names
MAX_STORED_BYTES = 256 * 1024 * 1024  # names, values and aux of every variable together
MAX_SUMMARY_BYTES = 1024 * 1024  # DB_VARSUMMARY, DB_RWSUMMARY, DB_REFUSED and each PROC_SUMMARY line are cut here
MAX_REFUSAL_KEYS = 1000  # (client, cause) counters kept; past it a stream of new names shares one per cause
LOG_PREFIX_BYTES = 40
WARN_PERIOD_S = 10.0  # one WARNING per client and cause this often; the next says how many were held back


def preview(data: bytes, limit: int = LOG_PREFIX_BYTES) -> str:
    """Client-supplied bytes fit for a log line: at most ``limit`` of them, and the full length when cut."""
    if len(data) <= limit:
        return repr(to_str(data))
    return f"{to_str(data[:limit])!r}... ({len(data)} bytes)"


def cut(text: bytes, limit: int = MAX_SUMMARY_BYTES) -> bytes:
    """A summary bounded in size: one client must not make every subscriber's copy huge."""
    return text if len(text) <= limit else text[:limit] + b"...(cut)"


class StoredValue(Protocol):
    """What a stored variable tells the caps (``DBVar``)."""

    aux: bytes
    writer: bytes
    sval: bytes


class DBLimits:
    """The caps of one DB, the bytes and variables charged against them, and the refusals they caused."""

    def __init__(self, max_variables: int = MAX_VARIABLES, max_variables_per_client: int = MAX_VARIABLES_PER_CLIENT,
                 max_name_bytes: int = MAX_NAME_BYTES, max_stored_bytes: int = MAX_STORED_BYTES) -> None:
        self.max_variables = int(max_variables)
        self.max_variables_per_client = int(max_variables_per_client)
        self.max_name_bytes = int(max_name_bytes)
        self.max_stored_bytes = int(max_stored_bytes)
        self.stored_bytes = 0  # names, values and aux of every variable (the DB adds and subtracts)
        self.created_by: dict[bytes, int] = {}  # client -> variables it created
        self.refusals: dict[tuple[bytes, str], int] = {}  # (client, cause) -> count, published as DB_REFUSED
        self._refusals_published = 0
        self._warn = RateLimitedLog(log, WARN_PERIOD_S)

    def refuse(self, client: bytes, cause: str, text: str, *args: object) -> None:
        """Count a refused message of ``client`` and log it (rate-limited per client and cause)."""
        key = (client, cause)
        if key not in self.refusals and len(self.refusals) >= MAX_REFUSAL_KEYS:
            key = (b"*", cause)  # bounded: a stream of new names shares one counter
        self.refusals[key] = self.refusals.get(key, 0) + 1
        self._warn.warning(key, text, *args)

    def flush_warnings(self) -> None:
        """Log the counts of refusals held back by the rate limit."""
        self._warn.flush()

    def refused_report(self) -> bytes | None:
        """``client:cause=count,...`` for ``DB_REFUSED`` when a refusal was counted since the last report, else None."""
        total = sum(self.refusals.values())
        if total == self._refusals_published:
            return None
        self._refusals_published = total
        return cut(b",".join(client + b":" + cause.encode() + b"=" + str(n).encode()
                             for (client, cause), n in self.refusals.items()))

    def names_fit(self, msg: MoosMessage, writer: bytes) -> bool:
        """Whether the write's source, aux and community are within ``max_name_bytes``; logs a refusal."""
        limit = self.max_name_bytes
        if len(msg.raw_src) <= limit and len(msg.raw_aux) <= limit and len(msg.raw_community) <= limit:
            return True
        self.refuse(writer, "max_name_bytes", "refused write to %s by %s: source, aux or community longer than "
                    "max_name_bytes (%d)", preview(msg.raw_key), preview(writer), limit)
        return False

    def may_store(self, msg: MoosMessage, var: StoredValue | None, writer: bytes) -> bool:
        """Whether this write keeps the stored names, values and aux within ``max_stored_bytes``; logs a refusal."""
        grow = len(msg.raw_aux) + len(msg.raw_src) + (len(msg.raw_sval) if msg.data_type != DOUBLE else 0)
        grow -= len(var.aux) + len(var.writer) + len(var.sval) if var is not None else -len(msg.raw_key)
        if grow <= 0 or self.stored_bytes + grow <= self.max_stored_bytes:
            return True
        self.refuse(writer, "max_stored_bytes", "refused write to %s by %s: it would take the DB's stored names "
                    "and values past max_stored_bytes (%d)", preview(msg.raw_key), preview(writer),
                    self.max_stored_bytes)
        return False

    def may_create(self, client: bytes, key: bytes, how: str, variables: int) -> bool:
        """Whether ``client`` may create variable ``key`` in a DB holding ``variables`` (name length, DB and
        per-client caps); charges it to ``client`` if so, else logs a refusal."""
        if len(key) > self.max_name_bytes:
            self.refuse(client, "max_name_bytes", "refused %s of a variable by %s: its name %s is longer than "
                        "max_name_bytes (%d)", how, preview(client), preview(key), self.max_name_bytes)
            return False
        if variables >= self.max_variables:
            self.refuse(client, "max_variables", "refused %s of new variable %s by %s: the DB holds "
                        "max_variables (%d)", how, preview(key), preview(client), self.max_variables)
            return False
        created = self.created_by.get(client, 0)
        if created >= self.max_variables_per_client:
            self.refuse(client, "max_variables_per_client", "refused %s of new variable %s by %s: it created "
                        "max_variables_per_client (%d) already", how, preview(key), preview(client),
                        self.max_variables_per_client)
            return False
        if created == 0 and len(self.created_by) >= 10 * self.max_variables:
            self.created_by.clear()  # bounded: only reached under a stream of new names; the DB cap still holds
        self.created_by[client] = created + 1
        return True
