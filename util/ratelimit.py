"""Rate-limited logging for events caused by remote input (bad datagrams, refused frames, misbehaving clients).

A sender that repeats a bad datagram 10,000 times a second must not fill the log (or the disk), yet nothing may go
unreported: :class:`RateLimitedLog` writes the first event of a kind at once, then at most one line per
``period_s`` for that kind, carrying the count of the events it held back. ``flush()`` writes the pending counts
of quiet kinds, so the last burst is reported too (call it from a periodic loop).

    bad = RateLimitedLog(logging.getLogger(__name__), period_s=10)
    bad.error("malformed", "link %d: dropping a malformed datagram from %s", link, addr)
    ...
    bad.flush()  # e.g. in the thread's 10 Hz loop

Thread-safe (one lock); bounded: at most ``max_keys`` kinds are tracked, later ones share one key.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Hashable

__all__ = ["RateLimitedLog"]

#: The key that kinds beyond ``max_keys`` share (so a stream of new kinds is still counted and reported).
OTHER_KINDS = ("ratelimit", "other kinds")


class _Kind:
    """One kind of event: when its next line may be written, and what was held back since the last one.

    (A plain class, not a dataclass: moos-db uses this module, and dataclasses imports inspect, 1.2 MiB.)"""

    __slots__ = ("next_t", "held", "level", "msg", "args")

    def __init__(self, next_t: float, held: int = 0, level: int = logging.ERROR, msg: str = "",
                 args: tuple[object, ...] = ()) -> None:
        self.next_t = next_t  # when the next line of this kind may be written
        self.held = held  # events held back since the last line
        self.level = level
        self.msg = msg
        self.args = args


class RateLimitedLog:
    """At most one line per key every ``period_s`` seconds; a later line says how many were held back."""

    def __init__(self, logger: logging.Logger, period_s: float = 10.0, max_keys: int = 1000,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.logger = logger
        self.period_s = period_s
        self.max_keys = max_keys
        self._clock = clock
        self._lock = threading.Lock()
        self._kinds: dict[Hashable, _Kind] = {}
        self.events = 0  # every event reported to this object (written or held back)
        self.held_back = 0  # events not written as a line of their own

    def log(self, level: int, key: Hashable, msg: str, *args: object) -> bool:
        """Report one event of kind ``key``; written now (True) or counted for a later summary line (False)."""
        with self._lock:
            now = self._clock()
            self.events += 1
            kind = self._kinds.get(key)
            if kind is None:
                key = self._admit(key, now)
                kind = self._kinds.get(key)
            if kind is not None and now < kind.next_t:
                kind.held += 1
                kind.level, kind.msg, kind.args = level, msg, args
                self.held_back += 1
                return False
            held = kind.held if kind is not None else 0
            self._kinds[key] = _Kind(next_t=now + self.period_s)
        self._write(level, msg, args, held)
        return True

    def error(self, key: Hashable, msg: str, *args: object) -> bool:
        return self.log(logging.ERROR, key, msg, *args)

    def warning(self, key: Hashable, msg: str, *args: object) -> bool:
        return self.log(logging.WARNING, key, msg, *args)

    def flush(self, final: bool = False) -> None:
        """Write the summary line of every kind whose quiet period is over (``final``: of every kind, e.g. on
        shutdown) and that held events back."""
        due: list[_Kind] = []
        with self._lock:
            now = self._clock()
            for key, kind in self._kinds.items():
                if kind.held and (final or now >= kind.next_t):
                    due.append(kind)
                    self._kinds[key] = _Kind(next_t=now + self.period_s)
        for kind in due:
            self._write(kind.level, kind.msg, kind.args, kind.held, last=True)

    def _admit(self, key: Hashable, now: float) -> Hashable:
        """``key``, or the shared key when ``max_keys`` kinds are tracked (quiet kinds are forgotten first)."""
        if len(self._kinds) < self.max_keys:
            return key
        for old in [k for k, kind in self._kinds.items() if not kind.held and kind.next_t <= now]:
            del self._kinds[old]
        return key if len(self._kinds) < self.max_keys else OTHER_KINDS

    def _write(self, level: int, msg: str, args: tuple[object, ...], held: int, last: bool = False) -> None:
        if held:
            what = f"the latest of {held}" if last else f"{held} more"
            msg = f"{msg} ({what} like this since the last such line, not logged one by one)"
        self.logger.log(level, msg, *args)
