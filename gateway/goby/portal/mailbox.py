"""A thread's mailbox: work other threads hand to the owner, plus an eventfd that wakes the owner's poll.

The eventfd sits in the same ``zmq.Poller`` as the thread's subscriptions, so ``post`` from any thread wakes a
blocked owner within microseconds.  Work runs only when the owner drains the mailbox, on the owner's thread.
"""

from __future__ import annotations

import logging
import os
import threading
from collections import deque
from collections.abc import Callable
from typing import Any

from gateway.goby.portal.errors import ClosedError

log = logging.getLogger(__name__)


class Mailbox:
    """Thread-safe FIFO of callables with a pollable wake-up file descriptor."""

    def __init__(self, name: str = "") -> None:
        self.name = name
        self._fd = os.eventfd(0, os.EFD_NONBLOCK | os.EFD_CLOEXEC)
        self._items: deque[tuple[Callable[..., Any], tuple[Any, ...]]] = deque()
        # re-entrant: a signal handler on the owner thread may wake it while the owner is inside post()
        self._lock = threading.RLock()
        self._closed = False

    @property
    def fd(self) -> int:
        """The descriptor to register (POLLIN) in the owner's poller."""
        return self._fd

    def post(self, fn: Callable[..., Any], *args: Any) -> None:
        """Queue ``fn(*args)`` to run on the owner's thread and wake it; callable from any thread."""
        with self._lock:
            if self._closed:
                raise ClosedError(f"mailbox of {self.name or 'thread'} is closed")
            self._items.append((fn, args))
            os.eventfd_write(self._fd, 1)

    def wake(self) -> None:
        """Wake the owner without queuing work (a no-op once closed)."""
        with self._lock:
            if not self._closed:
                os.eventfd_write(self._fd, 1)

    def pending(self) -> int:
        return len(self._items)

    def drain(self) -> int:
        """Run the work queued so far (owner's thread only); returns how many items ran.

        Only the items present at entry run, so a flood from other threads cannot starve the owner's sockets.
        """
        try:
            os.eventfd_read(self._fd)
        except BlockingIOError:
            pass
        except OSError:
            return 0
        count = len(self._items)
        for _ in range(count):
            fn, args = self._items.popleft()
            try:
                fn(*args)
            except Exception:
                log.exception("error in work posted to %s (%r); continuing", self.name or "thread", fn)
        return count

    def close(self) -> None:
        """Refuse further posts and release the descriptor; idempotent."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            os.close(self._fd)
        if self._items:
            log.debug("%s closed with %d unprocessed item(s)", self.name or "mailbox", len(self._items))
        self._items.clear()

    @property
    def closed(self) -> bool:
        return self._closed
