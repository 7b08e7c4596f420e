"""Active queues: per-variable callbacks that run on their own thread (``CMOOSCommClient::AddActiveQueue``)."""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable

from .message import MoosMessage
from .wildcard import wild_match

log = logging.getLogger(__name__)

MessageCallback = Callable[[MoosMessage], object]

_STOP = object()


class ActiveQueue:
    """One queue and the thread that calls ``callback(msg)`` for each message pushed to it, in order."""

    def __init__(self, name: str, callback: MessageCallback, owner: str = "") -> None:
        self.name = name
        self._callback = callback
        self._queue: queue.SimpleQueue[object] = queue.SimpleQueue()
        self._thread = threading.Thread(
            target=self._run, name=f"moos-active-queue-{owner}-{name}", daemon=True
        )
        self._thread.start()

    def push(self, msg: MoosMessage) -> None:
        self._queue.put(msg)

    def stop(self, timeout: float = 5.0) -> None:
        """Let the queue finish what it holds, then end its thread; idempotent."""
        if self._thread.is_alive():
            self._queue.put(_STOP)
            if threading.current_thread() is not self._thread:
                self._thread.join(timeout)

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            if item is _STOP:
                return
            try:
                self._callback(item)  # type: ignore[arg-type]
            except Exception:
                log.exception("active queue %r: callback raised; carrying on", self.name)


class ActiveQueueRouter:
    """Maps variable names (and wildcard patterns) to active queues; used by the client's reader thread."""

    def __init__(self, owner: str = "") -> None:
        self._owner = owner
        self._lock = threading.Lock()
        self._queues: dict[str, ActiveQueue] = {}
        self._routes: dict[bytes, set[str]] = {}
        self._wild_routes: dict[bytes, set[str]] = {}

    def __bool__(self) -> bool:
        return bool(self._routes or self._wild_routes)

    def add_queue(self, name: str, callback: MessageCallback) -> bool:
        """Create queue ``name`` (its callback runs on the queue's own thread); False if it exists."""
        with self._lock:
            if name in self._queues:
                return False
            self._queues[name] = ActiveQueue(name, callback, self._owner)
            return True

    def has_queue(self, name: str) -> bool:
        return name in self._queues

    def add_route(self, name: str, key: bytes, wildcard: bool = False) -> bool:
        """Route messages named ``key`` (or matching it, if ``wildcard``) to queue ``name``."""
        with self._lock:
            if name not in self._queues:
                return False
            table = self._wild_routes if wildcard else self._routes
            table.setdefault(key, set()).add(name)
            return True

    def remove_route(self, name: str, key: bytes) -> bool:
        with self._lock:
            found = False
            for table in (self._routes, self._wild_routes):
                names = table.get(key)
                if names and name in names:
                    names.discard(name)
                    if not names:
                        del table[key]
                    found = True
            return found

    def remove_queue(self, name: str) -> bool:
        with self._lock:
            q = self._queues.pop(name, None)
            for table in (self._routes, self._wild_routes):
                for key in [k for k, names in table.items() if name in names]:
                    table[key].discard(name)
                    if not table[key]:
                        del table[key]
        if q is None:
            return False
        q.stop()
        return True

    def describe(self) -> str:
        with self._lock:
            lines = [f"{key.decode(errors='replace')} -> {sorted(names)}" for key, names in self._routes.items()]
            lines += [f"{key.decode(errors='replace')} (wildcard) -> {sorted(names)}" for key, names in self._wild_routes.items()]
        return "\n".join(lines)

    def dispatch(self, msg: MoosMessage) -> bool:
        """Push a notification to every queue it is routed to; True if it went to at least one."""
        targets = self._routes.get(msg.raw_key)
        if self._wild_routes:
            wild = {n for pat, names in self._wild_routes.items() if wild_match(pat, msg.raw_key) for n in names}
            targets = (targets or set()) | wild
        if not targets:
            return False
        queues = self._queues
        delivered = False
        for name in targets:
            q = queues.get(name)
            if q is not None:
                q.push(msg)
                delivered = True
        return delivered

    def stop_all(self) -> None:
        with self._lock:
            queues = list(self._queues.values())
            self._queues.clear()
            self._routes.clear()
            self._wild_routes.clear()
        for q in queues:
            q.stop()
