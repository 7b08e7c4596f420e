"""The scope's state: one row per (group, type, scheme) with its latest payload, count, rate and history.

Threads: :meth:`ScopeModel.ingest` runs on the portal thread for every publication and only stores bytes (a dict
lookup, a counter, a deque append under a lock held for microseconds); decoding happens on the web thread in
:meth:`ScopeModel.tick`, once per row per tick whatever the publication rate.  That is the coalescing: a 1 kHz
group costs the page one decoded row per update period.
"""

from __future__ import annotations

import logging
import math
import threading
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from gateway.goby.dccl import Codec as DcclCodec
from gateway.goby.portal.marshalling import scheme_to_string
from launch.liaison.decode import decode_payload

log = logging.getLogger(__name__)

RATE_TIME_CONSTANT_S = 1.0  # the rate shown is an exponential average over about this long
RATE_CHANGE = 0.05  # a row is re-sent for its rate alone when the rate moved by more than this fraction


@dataclass(eq=False)
class _Row:
    id: int
    group: str
    type_name: str
    scheme: int
    history: deque[tuple[float, bytes]]
    count: int = 0
    latest: bytes = b""
    time: float = 0.0
    version: int = 0
    # web-thread state
    sent_version: int = -1
    rate: float = 0.0
    sent_rate: float = 0.0
    rate_count: int = 0
    view: dict[str, Any] = field(default_factory=dict)


class ScopeModel:
    """Rows of everything published on the broker; bounded in rows and in history per row."""

    def __init__(self, max_history: int = 100, max_rows: int = 5000, max_message_size: int = 2048) -> None:
        self.max_history = max(1, max_history)
        self.max_rows = max_rows
        self.max_message_size = max_message_size
        self._lock = threading.Lock()
        self._rows: dict[tuple[str, str, int], _Row] = {}
        self._by_id: dict[int, _Row] = {}
        self._last_tick: float | None = None
        self.refused_rows = 0  # publications on a new (group, type, scheme) beyond max_rows
        self.received = 0
        self._dccl = DcclCodec()  # web thread: decodes DCCL-scheme rows (the intervehicle layer's echoes)

    # ---------------------------------------------------------------------------------- portal thread
    def ingest(self, group: str, scheme: int, type_name: str, payload: bytes, when: float) -> None:
        """Store one publication (``when``: the application clock's time). Runs on the portal thread."""
        key = (group, type_name, scheme)
        with self._lock:
            self.received += 1
            row = self._rows.get(key)
            if row is None:
                if len(self._rows) >= self.max_rows:
                    self.refused_rows += 1
                    if self.refused_rows == 1:
                        log.warning("scope: more than %d rows; new (group, type, scheme) are counted, not shown "
                                    "(max_scope_rows)", self.max_rows)
                    return
                row = _Row(len(self._rows) + 1, group, type_name, scheme, deque(maxlen=self.max_history))
                self._rows[key] = row
                self._by_id[row.id] = row
            row.count += 1
            row.latest = payload
            row.time = when
            row.version += 1
            row.history.append((when, payload))

    # ------------------------------------------------------------------------------------- web thread
    def tick(self, now: float) -> list[dict[str, Any]]:
        """Rows changed since the last tick (value, count or a visible change of rate), as views.

        ``now``: a monotonic time in seconds.  Runs on the web thread only.
        """
        with self._lock:
            rows = list(self._by_id.values())
            state = [(row, row.version, row.count, row.latest, row.time) for row in rows]
        dt = None if self._last_tick is None else max(1e-6, now - self._last_tick)
        self._last_tick = now
        changed = []
        for row, version, count, latest, when in state:
            if dt is not None:
                alpha = 1.0 - math.exp(-dt / RATE_TIME_CONSTANT_S)
                row.rate += alpha * ((count - row.rate_count) / dt - row.rate)
                if row.rate < 0.01:
                    row.rate = 0.0
            row.rate_count = count
            rate_moved = abs(row.rate - row.sent_rate) > RATE_CHANGE * max(row.sent_rate, 0.1)
            if version == row.sent_version and not rate_moved:
                continue
            if version != row.sent_version:
                decoded = decode_payload(latest, row.scheme, row.type_name, self.max_message_size, self._dccl)
                row.view = {
                    "id": row.id, "group": row.group, "type": row.type_name, "scheme": scheme_to_string(row.scheme),
                    "value": decoded.short, "ok": decoded.ok, "time": when,
                }
            row.view["count"] = count
            row.view["rate"] = round(row.rate, 2)
            row.sent_version = version
            row.sent_rate = row.rate
            changed.append(dict(row.view))
        return changed

    def views(self) -> list[dict[str, Any]]:
        """Every row as last computed by :meth:`tick` (for a new or resynchronised browser). Web thread."""
        with self._lock:
            rows = list(self._by_id.values())
        return [dict(row.view) for row in rows if row.view]

    def history(self, row_id: int, limit: int | None = None) -> list[dict[str, Any]] | None:
        """The row's last values, newest first, decoded in full; None for an unknown id. Web thread."""
        with self._lock:
            row = self._by_id.get(row_id)
            if row is None:
                return None
            items = list(row.history)
        items.reverse()
        if limit is not None:
            items = items[:limit]
        return [{"time": when, "value": decode_payload(payload, row.scheme, row.type_name,
                                                         self.max_message_size, self._dccl).full}
                for when, payload in items]

    def row_count(self) -> int:
        with self._lock:
            return len(self._rows)
