"""Active queues: per-variable callbacks (``CMOOSCommClient::AddActiveQueue``), run on the client's reactor thread.

libMOOS gives each queue a thread; here a routed message is handed to its queue's callback on the client's I/O
thread (its reactor) as the packet is delivered, in arrival order, before the on-mail callback. A callback that
needs its own thread posts the message to one. Routes may be changed from any thread: the tables are replaced,
never changed in place, so the reactor reads them without a lock.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from .message import MoosMessage
from .wildcard import wild_match

log = logging.getLogger(__name__)

MessageCallback = Callable[[MoosMessage], object]
Routes = dict[bytes, frozenset[str]]


class ActiveQueueRouter:
    """Maps variable names (and wildcard patterns) to named callbacks; ``dispatch`` runs on the reactor thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()  # serialises writers; readers use whatever table is current
        self._queues: dict[str, MessageCallback] = {}
        self._routes: Routes = {}
        self._wild_routes: Routes = {}

    def __bool__(self) -> bool:
        return bool(self._routes or self._wild_routes)

    def add_queue(self, name: str, callback: MessageCallback) -> bool:
        """Create queue ``name``; False if it exists."""
        with self._lock:
            if name in self._queues:
                return False
            self._queues = {**self._queues, name: callback}
            return True

    def has_queue(self, name: str) -> bool:
        return name in self._queues

    def add_route(self, name: str, key: bytes, wildcard: bool = False) -> bool:
        """Route messages named ``key`` (or matching it, if ``wildcard``) to queue ``name``."""
        with self._lock:
            if name not in self._queues:
                return False
            table = dict(self._wild_routes if wildcard else self._routes)
            table[key] = table.get(key, frozenset()) | {name}
            if wildcard:
                self._wild_routes = table
            else:
                self._routes = table
            return True

    def remove_route(self, name: str, key: bytes) -> bool:
        with self._lock:
            routes, found_plain = _without(self._routes, name, key)
            wild, found_wild = _without(self._wild_routes, name, key)
            self._routes, self._wild_routes = routes, wild
            return found_plain or found_wild

    def remove_queue(self, name: str) -> bool:
        with self._lock:
            if name not in self._queues:
                return False
            self._queues = {k: v for k, v in self._queues.items() if k != name}
            self._routes = _drop_queue(self._routes, name)
            self._wild_routes = _drop_queue(self._wild_routes, name)
            return True

    def describe(self) -> str:
        lines = [f"{key.decode(errors='replace')} -> {sorted(names)}" for key, names in self._routes.items()]
        lines += [f"{key.decode(errors='replace')} (wildcard) -> {sorted(names)}"
                  for key, names in self._wild_routes.items()]
        return "\n".join(lines)

    def dispatch(self, msg: MoosMessage) -> bool:
        """Call every queue ``msg`` is routed to (on this thread); True if it went to at least one."""
        targets = self._routes.get(msg.raw_key)
        wild_routes = self._wild_routes
        if wild_routes:
            wild = {n for pattern, names in wild_routes.items() if wild_match(pattern, msg.raw_key) for n in names}
            targets = (targets or frozenset()) | wild
        if not targets:
            return False
        queues = self._queues
        delivered = False
        for name in sorted(targets) if len(targets) > 1 else targets:
            callback = queues.get(name)
            if callback is None:
                continue
            delivered = True
            try:
                callback(msg)
            except Exception:
                log.exception("active queue %r: callback raised; carrying on", name)
        return delivered

    def clear(self) -> None:
        with self._lock:
            self._queues, self._routes, self._wild_routes = {}, {}, {}


def _without(table: Routes, name: str, key: bytes) -> tuple[Routes, bool]:
    names = table.get(key)
    if not names or name not in names:
        return table, False
    copy = dict(table)
    rest = names - {name}
    if rest:
        copy[key] = rest
    else:
        del copy[key]
    return copy, True


def _drop_queue(table: Routes, name: str) -> Routes:
    return {key: names - {name} for key, names in table.items() if names - {name}}
