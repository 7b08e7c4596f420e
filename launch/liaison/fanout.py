"""One browser connection on the server side: what it watches, and a bounded queue of updates to it.

Why a queue per browser: the web thread must never wait for one page.  Each connection has its own sender task
that writes from its queue; :meth:`Browser.offer` never blocks.  When a page does not read (a stalled tab, a
slow link) its queue fills; then its queued updates are dropped (counted) and the page is marked for a full
resynchronisation, which it gets as soon as it has room again.  A send that stays blocked longer than
``send_timeout_s`` closes the connection.  Everything here runs on the web thread's event loop.
"""

from __future__ import annotations

import asyncio
import logging
import re
from dataclasses import dataclass, field

from aiohttp import web

log = logging.getLogger(__name__)

VIEWS = frozenset({"scope", "commander", "map"})


def compile_filter(expression: str, what: str) -> re.Pattern[str]:
    """A scope filter (matched against the whole group or type, like Goby's ``regex_match``); ValueError names
    the expression and the regex error."""
    try:
        return re.compile(expression or ".*")
    except re.error as exc:
        raise ValueError(f"{what} filter {expression!r} is not a valid regular expression: {exc}") from None


@dataclass(eq=False)
class Browser:
    """One WebSocket client."""

    ws: web.WebSocketResponse
    address: str
    queue_size: int
    send_timeout_s: float = 10.0
    views: set[str] = field(default_factory=set)
    group_filter: re.Pattern[str] = field(default_factory=lambda: re.compile(".*"))
    type_filter: re.Pattern[str] = field(default_factory=lambda: re.compile(".*"))
    paused: bool = False
    expanded: set[int] = field(default_factory=set)
    needs_resync: set[str] = field(default_factory=set)  # views to send in full at the next chance
    dropped: int = 0
    _queue: asyncio.Queue[str] = field(init=False)
    _matches: dict[int, bool] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._queue = asyncio.Queue(maxsize=max(1, self.queue_size))

    def set_filters(self, group: str, type_: str) -> None:
        """Raises ValueError (naming the expression) for a bad regex; the old filters then stay."""
        group_re = compile_filter(group, "group")
        type_re = compile_filter(type_, "type")
        self.group_filter, self.type_filter = group_re, type_re
        self._matches.clear()

    def shows(self, row: dict[str, object]) -> bool:
        """Whether a scope row passes this page's filters (cached per row)."""
        row_id = int(row["id"])  # type: ignore[arg-type]
        hit = self._matches.get(row_id)
        if hit is None:
            hit = bool(self.group_filter.fullmatch(str(row["group"]))) and bool(
                self.type_filter.fullmatch(str(row["type"])))
            self._matches[row_id] = hit
        return hit

    @property
    def filter_key(self) -> tuple[str, str]:
        return self.group_filter.pattern, self.type_filter.pattern

    def offer(self, text: str, view: str) -> bool:
        """Queue one update; on a full queue drop everything queued and ask for a resync of ``view``."""
        try:
            self._queue.put_nowait(text)
            return True
        except asyncio.QueueFull:
            dropped = 0
            while not self._queue.empty():
                self._queue.get_nowait()
                dropped += 1
            self.dropped += dropped
            self.needs_resync.update(self.views | {view})
            log.info("browser %s is not reading: dropped %d queued update(s) (%d in all); it will be resynchronised",
                     self.address, dropped, self.dropped)
            return False

    def has_room(self) -> bool:
        return self._queue.qsize() < self._queue.maxsize // 2 + 1

    async def send_loop(self) -> None:
        """Write queued updates until the connection closes; closes a connection stuck on one send."""
        while not self.ws.closed:
            text = await self._queue.get()
            try:
                await asyncio.wait_for(self.ws.send_str(text), self.send_timeout_s)
            except TimeoutError:
                log.warning("browser %s did not take an update for %.0f s: closing its connection", self.address,
                            self.send_timeout_s)
                await self.ws.close(code=1008, message=b"not reading updates")
                return
            except (ConnectionError, RuntimeError):
                return
