"""One browser connection on the server side: what it watches, its replies, and a bounded queue of updates to it.

Why a queue per browser: the web thread must never wait for one page.  Each connection has its own sender task
that writes from its queues; :meth:`Browser.offer` and :meth:`Browser.reply` never block.  Two queues, because
they are bounded differently:

- **updates** (scope rows, map, the sent log): when a page does not read (a stalled tab, a slow link) this queue
  fills; then its queued updates are dropped (counted) and the page is marked for a full resynchronisation,
  which it gets as soon as it has room again.  Nothing is lost that a resync does not restore.
- **replies** (one per page message: accepted, refused, error, ...): never dropped, sent before updates.  They
  are bounded by the page itself: once :data:`MAX_PENDING_REPLIES` wait, the server stops reading that page's
  messages (:meth:`Browser.replies_drained`) until they are sent, so TCP pushes back on the sender.

A send that stays blocked longer than ``send_timeout_s`` closes the connection.  Scope filters are matched once
per row and cached, within a time budget per call (:meth:`Browser.visible`).  Everything here runs on the web
thread's event loop.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from aiohttp import web

from launch.liaison.name_filter import NameFilter, compile_filter

log = logging.getLogger(__name__)

VIEWS = frozenset({"scope", "commander", "map"})
MAX_PENDING_REPLIES = 64  # replies waiting to be sent before the page's messages are no longer read
MATCH_BUDGET_S = 0.005  # wall time one call may spend matching filters against rows not matched before

__all__ = ["VIEWS", "Browser", "compile_filter"]


@dataclass(eq=False)
class Browser:
    """One WebSocket client."""

    ws: web.WebSocketResponse
    address: str
    queue_size: int
    send_timeout_s: float = 10.0
    views: set[str] = field(default_factory=set)
    group_filter: NameFilter = field(default_factory=lambda: NameFilter(".*", "group"))
    type_filter: NameFilter = field(default_factory=lambda: NameFilter(".*", "type"))
    paused: bool = False
    expanded: set[int] = field(default_factory=set)
    needs_resync: set[str] = field(default_factory=set)  # views to send in full at the next chance
    dropped: int = 0
    _updates: deque[str] = field(default_factory=deque)
    _replies: deque[str] = field(default_factory=deque)
    _wake: asyncio.Event = field(default_factory=asyncio.Event)
    _drained: asyncio.Event = field(default_factory=asyncio.Event)
    _matches: dict[int, bool] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.queue_size = max(1, self.queue_size)
        self._drained.set()

    def set_filters(self, group: str, type_: str) -> None:
        """Raises ValueError (naming the expression) for a refused regex; the old filters then stay."""
        group_re = compile_filter(group, "group")
        type_re = compile_filter(type_, "type")
        self.group_filter, self.type_filter = group_re, type_re
        self._matches.clear()

    def shows(self, row: dict[str, Any]) -> bool:
        """Whether a scope row passes this page's filters (cached per row)."""
        hit = self._matches.get(row["id"])
        if hit is None:
            hit = self._matches[row["id"]] = self._match(row)
        return hit

    def _match(self, row: dict[str, Any]) -> bool:
        return self.group_filter.fullmatch(str(row["group"])) and self.type_filter.fullmatch(str(row["type"]))

    def visible(self, rows: list[dict[str, Any]], deadline: float | None = None) -> list[dict[str, Any]] | None:
        """The rows this page shows, or None when matching the rows not seen before ran past ``deadline``
        (``time.perf_counter()``; default: :data:`MATCH_BUDGET_S` from now); what was matched is kept, so the
        next call goes on from there. Bounds how long the loop is held, whatever the filter and the row count."""
        if deadline is None:
            deadline = time.perf_counter() + MATCH_BUDGET_S
        matches = self._matches
        shown = []
        for row in rows:
            hit = matches.get(row["id"])
            if hit is None:
                if time.perf_counter() > deadline:
                    return None
                hit = matches[row["id"]] = self._match(row)
            if hit:
                shown.append(row)
        return shown

    @property
    def filter_key(self) -> tuple[str, str]:
        return self.group_filter.pattern, self.type_filter.pattern

    def offer(self, text: str, view: str) -> bool:
        """Queue one update; on a full queue drop everything queued and ask for a resync of ``view``."""
        if len(self._updates) < self.queue_size:
            self._updates.append(text)
            self._wake.set()
            return True
        dropped = len(self._updates)
        self._updates.clear()
        self.dropped += dropped
        self.needs_resync.update(self.views | {view})
        log.info("browser %s is not reading: dropped %d queued update(s) (%d in all); it will be resynchronised",
                 self.address, dropped, self.dropped)
        return False

    def reply(self, text: str) -> None:
        """Queue the answer to one of the page's messages: never dropped (see :meth:`replies_drained`)."""
        self._replies.append(text)
        if len(self._replies) >= MAX_PENDING_REPLIES:
            self._drained.clear()
        self._wake.set()

    async def replies_drained(self) -> None:
        """Wait while too many replies are pending: the caller then stops reading this page's messages."""
        await self._drained.wait()

    def has_room(self) -> bool:
        return len(self._updates) < self.queue_size // 2 + 1

    async def send_loop(self) -> None:
        """Write queued replies, then updates, until the connection closes; closes a connection stuck on a send."""
        while not self.ws.closed:
            if not self._replies and not self._updates:
                self._wake.clear()
                await self._wake.wait()
                continue
            text = self._replies.popleft() if self._replies else self._updates.popleft()
            if len(self._replies) < MAX_PENDING_REPLIES // 2:
                self._drained.set()
            try:
                await asyncio.wait_for(self.ws.send_str(text), self.send_timeout_s)
            except TimeoutError:
                log.warning("browser %s did not take an update for %.0f s: closing its connection", self.address,
                            self.send_timeout_s)
                self._drained.set()
                await self.ws.close(code=1008, message=b"not reading updates")
                return
            except (ConnectionError, RuntimeError):
                self._drained.set()
                return
