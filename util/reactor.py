"""The one way a thread waits: a reactor over ZeroMQ sockets, file descriptors, timers and cross-thread posts.

Every long-running thread of the project owns one ``Reactor`` and sleeps in exactly one place, its poll
(``select.poll`` over descriptors; ``zmq.Poller`` from the first ZeroMQ socket on, which takes both).  It wakes only when a registered source is
ready, a timer is due, or another thread posts work through the ``Mailbox`` eventfd: nothing polls on a period when
there is nothing to do.  Loops that Goby or MOOS run at a fixed rate (AppTick, the frontseat interface's 10 Hz loop,
TDMA slots) are ``call_every`` timers.  Why not asyncio: the hot paths are ZeroMQ sockets and small blocking-free
socket reads whose callbacks must run on a known thread (the portal's threading contract); a poller we own keeps
that contract with one system call per wake-up and no coroutine machinery.  The liaison's web server, an aiohttp
application, keeps asyncio (docs/ARCHITECTURE.md "One way to wait").

All methods except ``post``, ``wake`` and ``stop`` belong to the owning thread.
"""

from __future__ import annotations

import heapq
import itertools
import logging
import math
import os
import select
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias

if TYPE_CHECKING:
    import zmq

log = logging.getLogger(__name__)

READ = 1  # zmq.POLLIN
WRITE = 2  # zmq.POLLOUT
_ERROR = 4  # zmq.POLLERR
MAX_WAIT_S = 3600.0


class ReactorClosedError(RuntimeError):
    """Work was posted to a reactor (or mailbox) that has closed; the default ``closed_error``."""


class _HasFileno(Protocol):
    def fileno(self) -> int: ...


Source: TypeAlias = "zmq.Socket | int | _HasFileno"
Handler = Callable[[], object]


def _is_zmq_socket(source: object) -> bool:
    zmq_module = sys.modules.get("zmq")  # no ZeroMQ socket can exist before zmq is imported
    return zmq_module is not None and isinstance(source, zmq_module.Socket)


def _key(source: Source) -> zmq.Socket | int:
    """What the poller reports a source as: the zmq socket itself, else its descriptor number."""
    if isinstance(source, int) or _is_zmq_socket(source):
        return source  # type: ignore[return-value]  # narrowed by _is_zmq_socket
    return source.fileno()


class _DescriptorPoller:
    """``select.poll`` with ``zmq.Poller``'s interface and flags, for a reactor with no ZeroMQ socket.

    Why: importing pyzmq costs 2.4 MiB of private memory, and the MOOS processes and the frontseat simulator wait
    on plain sockets only.
    """

    _TO_SELECT = {READ: select.POLLIN, WRITE: select.POLLOUT}

    def __init__(self) -> None:
        self._poll = select.poll()

    def register(self, fd: int, mask: int) -> None:
        events = select.POLLIN if mask & READ else 0
        events |= select.POLLOUT if mask & WRITE else 0
        self._poll.register(fd, events)

    def unregister(self, fd: int) -> None:
        self._poll.unregister(fd)

    def poll(self, timeout_ms: int | None) -> list[tuple[int, int]]:
        ready = []
        for fd, events in self._poll.poll(timeout_ms):
            mask = READ if events & (select.POLLIN | select.POLLHUP) else 0
            mask |= WRITE if events & select.POLLOUT else 0
            mask |= _ERROR if events & (select.POLLERR | select.POLLNVAL) else 0
            ready.append((fd, mask))
        return ready


class Mailbox:
    """Thread-safe FIFO of callables with a pollable wake-up descriptor (an eventfd).

    ``post`` from any thread wakes a blocked owner within microseconds; the work runs only when the owner drains
    the mailbox, on the owner's thread.
    """

    def __init__(self, name: str = "", closed_error: Callable[[str], Exception] = ReactorClosedError) -> None:
        self.name = name
        self._closed_error = closed_error
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
                raise self._closed_error(f"mailbox of {self.name or 'thread'} is closed")
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


class Timer:
    """A scheduled call; ``cancel()`` stops it (owner's thread). Periodic timers re-arm themselves."""

    __slots__ = ("deadline", "_fn", "_period", "_cancelled", "_reactor")

    def __init__(
        self, reactor: Reactor, deadline: float, fn: Handler, period: Callable[[], float] | None
    ) -> None:
        self._reactor = reactor
        self.deadline = deadline
        self._fn = fn
        self._period = period
        self._cancelled = False

    @property
    def active(self) -> bool:
        return not self._cancelled

    def cancel(self) -> None:
        self._cancelled = True

    def reschedule(self, deadline: float) -> None:
        """Move a timer (owner's thread); cheaper than cancel + a new one for a deadline that moves often."""
        self._cancelled = False
        self.deadline = deadline
        self._reactor._push(self)

    def _fire(self, now: float) -> None:
        if self._period is None:
            self._cancelled = True
        else:
            period = self._period()
            if period > 0 and math.isfinite(period):
                self.deadline += period
                if self.deadline <= now:  # fell behind: skip the missed ticks rather than bursting
                    self.deadline = (math.floor(now / period) + 1) * period
                self._reactor._push(self)
            else:
                self._cancelled = True
        self._fn()


class Reactor:
    """One thread's event loop: ``add_reader``/``add_writer``, ``call_later``/``call_at``/``call_every``, ``post``."""

    def __init__(self, name: str = "", closed_error: Callable[[str], Exception] = ReactorClosedError) -> None:
        self.name = name
        self.mailbox = Mailbox(name, closed_error)
        self._poller: Any = _DescriptorPoller()
        self._poller.register(self.mailbox.fd, READ)
        self._readers: dict[Any, Handler] = {}
        self._writers: dict[Any, Handler] = {}
        self._masks: dict[Any, int] = {}
        self._timers: list[tuple[float, int, Timer]] = []
        self._sequence = itertools.count()
        self._running = False
        self._closed = False
        self._owner = threading.get_ident()  # the thread that runs it (last to call run_once), else its creator

    def in_owner_thread(self) -> bool:
        """True on the thread that runs this reactor (or, before it first ran, the one that created it).

        Lets a component on a reactor it was given refuse to block the thread that would have to wake it.
        """
        return threading.get_ident() == self._owner

    # -------------------------------------------------------------------------------- sources
    def add_reader(self, source: Source, handler: Handler) -> None:
        """Call ``handler()`` whenever ``source`` (a zmq socket, a descriptor or an object with ``fileno``) is readable.

        ZeroMQ sockets are edge-triggered underneath: the handler must drain what is ready (recv with NOBLOCK
        until ``zmq.Again``), or the rest waits for the next message.
        """
        key = _key(source)
        self._readers[key] = handler
        self._set_mask(key, self._masks.get(key, 0) | READ)

    def remove_reader(self, source: Source) -> None:
        key = _key(source)
        if self._readers.pop(key, None) is not None:
            self._set_mask(key, self._masks.get(key, 0) & ~READ)

    def add_writer(self, source: Source, handler: Handler) -> None:
        """Call ``handler()`` while ``source`` is writable (remove it once the output is flushed)."""
        key = _key(source)
        self._writers[key] = handler
        self._set_mask(key, self._masks.get(key, 0) | WRITE)

    def remove_writer(self, source: Source) -> None:
        key = _key(source)
        if self._writers.pop(key, None) is not None:
            self._set_mask(key, self._masks.get(key, 0) & ~WRITE)

    def _set_mask(self, source: zmq.Socket | int, mask: int) -> None:
        if mask and isinstance(self._poller, _DescriptorPoller) and not isinstance(source, int):
            self._use_zmq_poller()
        if mask:
            self._masks[source] = mask
            self._poller.register(source, mask)
        elif self._masks.pop(source, None) is not None:
            self._poller.unregister(source)

    def _use_zmq_poller(self) -> None:
        """The first ZeroMQ socket: move every registration to a ``zmq.Poller``, which polls both kinds."""
        import zmq

        poller = zmq.Poller()
        poller.register(self.mailbox.fd, READ)
        for source, mask in self._masks.items():
            poller.register(source, mask)
        self._poller = poller

    # -------------------------------------------------------------------------------- timers
    def call_at(self, deadline: float, fn: Handler) -> Timer:
        """Run ``fn()`` once at ``deadline`` (``time.monotonic()`` seconds)."""
        timer = Timer(self, deadline, fn, None)
        self._push(timer)
        return timer

    def call_later(self, delay_s: float, fn: Handler) -> Timer:
        return self.call_at(time.monotonic() + max(0.0, delay_s), fn)

    def call_every(self, period_s: float | Callable[[], float], fn: Handler, align: bool = True) -> Timer:
        """Run ``fn()`` every period (a number, or a function read at each tick so a warp change takes effect).

        ``align`` puts the ticks on multiples of the period of the monotonic clock, as Goby's loop does; a tick
        that falls behind is skipped, never burst.  A period that becomes 0 or infinite stops the timer.
        """
        period = period_s if callable(period_s) else (lambda: float(period_s))
        first = period()
        if not (first > 0 and math.isfinite(first)):
            raise ValueError(f"timer period must be finite and > 0, got {first!r}")
        now = time.monotonic()
        deadline = (math.floor(now / first) + 1) * first if align else now + first
        timer = Timer(self, deadline, fn, period)
        self._push(timer)
        return timer

    def _push(self, timer: Timer) -> None:
        heapq.heappush(self._timers, (timer.deadline, next(self._sequence), timer))

    def next_deadline(self) -> float | None:
        """When the earliest live timer is due (monotonic seconds), or None."""
        timers = self._timers
        while timers:
            deadline, _, timer = timers[0]
            if timer.active and timer.deadline == deadline:
                return deadline
            heapq.heappop(timers)  # cancelled or rescheduled: its live entry (if any) is elsewhere in the heap
        return None

    def _run_due_timers(self, now: float) -> int:
        ran = 0
        timers = self._timers
        while timers and timers[0][0] <= now:
            deadline, _, timer = heapq.heappop(timers)
            if not timer.active or timer.deadline != deadline:
                continue
            try:
                timer._fire(now)
            except Exception:
                log.exception("error in a timer of %s (%r); continuing", self.name or "reactor", timer._fn)
            ran += 1
        return ran

    # -------------------------------------------------------------------------------- cross-thread
    def post(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` on the owning thread as soon as possible; callable from any thread."""
        self.mailbox.post(fn, *args)

    def wake(self) -> None:
        """Interrupt the current poll (thread-safe)."""
        self.mailbox.wake()

    def stop(self) -> None:
        """Make ``run()`` return after the current iteration (thread-safe; idempotent)."""
        self._running = False
        self.mailbox.wake()

    # -------------------------------------------------------------------------------- running
    def run_once(self, timeout_s: float | None = None) -> int:
        """Wait up to ``timeout_s`` (None: until something happens) and run what is ready; returns the events run.

        Due timers run before and after the poll, so a periodic tick is never starved by steady traffic.
        """
        self._owner = threading.get_ident()
        events = self.mailbox.drain() if self.mailbox.pending() else 0
        events += self._run_due_timers(time.monotonic())
        if events:
            timeout_s = 0.0
        deadline = self.next_deadline()
        if deadline is not None:
            wait = max(0.0, deadline - time.monotonic())
            timeout_s = wait if timeout_s is None else min(timeout_s, wait)
        # poll(2) takes an int of milliseconds: a timer weeks away waits in hour-long naps instead of overflowing
        timeout_ms = None if timeout_s is None else math.ceil(min(timeout_s, MAX_WAIT_S) * 1000)
        for source, ready in self._poller.poll(timeout_ms):
            if source == self.mailbox.fd:
                events += self.mailbox.drain()
                continue
            if ready & READ:
                handler = self._readers.get(source)
                if handler is not None:
                    events += self._call(handler)
            if ready & WRITE:
                handler = self._writers.get(source)
                if handler is not None:
                    events += self._call(handler)
            if ready & _ERROR and source not in self._readers and source not in self._writers:
                self._set_mask(source, 0)
        events += self._run_due_timers(time.monotonic())
        return events

    def _call(self, handler: Handler) -> int:
        try:
            handler()
        except Exception:
            log.exception("error in a handler of %s (%r); continuing", self.name or "reactor", handler)
        return 1

    def run(self, until: Callable[[], bool] | None = None) -> None:
        """Run until ``stop()`` (or until ``until()`` is true, checked after each iteration)."""
        self._running = True
        while self._running and not self._closed:
            self.run_once()
            if until is not None and until():
                break
        self._running = False

    @property
    def running(self) -> bool:
        return self._running

    # -------------------------------------------------------------------------------- shutdown
    def close(self) -> None:
        """Unregister every source, drop the timers, close the mailbox; idempotent. Sources are not closed."""
        if self._closed:
            return
        self._closed = True
        self._running = False
        for source in list(self._masks):
            self._poller.unregister(source)
        self._masks.clear()
        self._readers.clear()
        self._writers.clear()
        self._timers.clear()
        self._poller.unregister(self.mailbox.fd)
        self.mailbox.close()

    @property
    def closed(self) -> bool:
        return self._closed
