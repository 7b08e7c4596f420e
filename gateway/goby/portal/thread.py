"""``SimpleThread``: a Goby thread with a loop frequency, its own transports, and ``call_soon``.

Construct a thread on the thread that runs it (``MultiThreadApplication.launch_thread`` does this) so its
sockets and identifiers belong to that thread.  Subscription callbacks, ``call_soon`` work and ``loop()`` all run
on that one thread, never concurrently.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from gateway.goby.portal.config import app_name_of, interprocess_config_of
from gateway.goby.portal.context import ProcessContext, current_context
from gateway.goby.portal.interprocess import InterProcessPortal
from gateway.goby.portal.interthread import InterThreadTransporter
from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__OK, ThreadHealth
from gateway.goby.portal.transports import ThreadTransports
from util.reactor import Reactor, Timer

if TYPE_CHECKING:
    from gateway.goby.intervehicle.forwarder import InterVehicleForwarder

log = logging.getLogger(__name__)


class SimpleThread:
    """Base for threads: override ``loop()`` (run at ``loop_frequency_hz * warp``), ``initialize()``, ``finalize()``.

    Subscribe in ``__init__`` or ``initialize()``; the thread owns its subscriptions and drops them on exit.
    """

    def __init__(self, cfg: Any, loop_frequency_hz: float = 0.0, index: int = -1) -> None:
        context = current_context()
        self._owns_context = context is None
        if context is None:
            context = ProcessContext(
                interprocess_config_of(cfg), application=app_name_of(cfg, type(self).__qualname__)
            )
        self._context: ProcessContext = context
        self._cfg = cfg
        self._index = index
        self._loop_hz = float(loop_frequency_hz)
        self._transports = ThreadTransports(context, type(self).__qualname__)
        self._alive = True
        self._closed = False
        self._loop_timer: Timer | None = None
        self._loop_error: Exception | None = None
        self._intervehicle: Any = None
        # Goby's Thread identity in health answers: the Linux thread id, a name and (launched threads) a uid
        self._thread_id = threading.get_native_id()
        self._thread_name = str(self._thread_id)
        self._uid = -1

    # ------------------------------------------------------------------------------------ accessors
    def cfg(self) -> Any:
        """The configuration this thread was built with."""
        return self._cfg

    @property
    def index(self) -> int:
        return self._index

    @property
    def context(self) -> ProcessContext:
        return self._context

    @property
    def loop_frequency_hz(self) -> float:
        """The configured loop frequency (before warp)."""
        return self._loop_hz

    def effective_loop_frequency_hz(self) -> float:
        """The real-time loop frequency: configured frequency times the clock's warp factor."""
        return self._loop_hz * self._context.clock.effective_warp

    def interprocess(self) -> InterProcessPortal:
        """This thread's interprocess transporter (connects to the broker on first use)."""
        return self._transports.interprocess()

    def intervehicle(self) -> InterVehicleForwarder:
        """This thread's intervehicle transporter (through interprocess to the broker's intervehicle portal)."""
        if self._intervehicle is None:
            from gateway.goby.intervehicle.forwarder import InterVehicleForwarder

            self._intervehicle = InterVehicleForwarder(self.interprocess(), self._context, type(self).__qualname__)
        return self._intervehicle

    def interthread(self) -> InterThreadTransporter:
        """This thread's interthread transporter."""
        return self._transports.interthread()

    @property
    def reactor(self) -> Reactor:
        """The thread's event loop: register sockets, descriptors and timers here (owning thread only)."""
        return self._transports.reactor

    @property
    def alive(self) -> bool:
        return self._alive

    # ------------------------------------------------------------------------------------ overrides
    def initialize(self) -> None:
        """Called on the thread before the first ``loop()``."""

    def loop(self) -> None:
        """Called on the thread at the loop frequency (never while a callback runs)."""

    def finalize(self) -> None:
        """Called on the thread after the last ``loop()``, before its transports close."""

    def health(self, health: ThreadHealth) -> None:
        """Fill this thread's state when goby-coroner asks (Goby's ``Thread::health``); runs on this thread.

        ``health`` already carries the name, thread id and uid; the default says ``HEALTH__OK``.  Override to
        report ``HEALTH__DEGRADED``/``HEALTH__FAILED`` with an ``error`` and ``error_message``.
        """
        health.state = HEALTH__OK

    # ------------------------------------------------------------------------------------- health
    @property
    def thread_name(self) -> str:
        """The name health answers give this thread (Goby: the thread id, or the launched class's name)."""
        return self._thread_name

    @property
    def uid(self) -> int:
        """The launch number a multi-thread application gave this thread (-1: not launched)."""
        return self._uid

    def set_identity(self, name: str, uid: int) -> None:
        """Set the name and uid health answers report (the launching application calls it, as Goby's launcher)."""
        self._thread_name = name
        self._uid = uid

    def thread_health(self) -> ThreadHealth:
        """This thread's ``ThreadHealth`` (Goby's ``Thread::thread_health``): identity, then :meth:`health`.

        Call it on this thread: :meth:`health` reads the thread's own state.
        """
        answer = ThreadHealth(name=self._thread_name, thread_id=self._thread_id)
        if self._uid >= 0:
            answer.uid = self._uid
        self.health(answer)
        return answer

    # ------------------------------------------------------------------------------ cross-thread API
    def call_soon(self, fn: Callable[[], Any]) -> None:
        """Run ``fn()`` on this thread as soon as possible; callable from any thread.

        Wakes the thread's poll through an eventfd, so the delay is the wake-up time of the thread (tens of µs),
        not a loop period.  Exceptions from ``fn`` are logged and the thread keeps running.  Raises
        ``ClosedError`` once the thread has closed (work handed over during shutdown is not dropped silently).
        """
        self._transports.mailbox.post(fn)

    def quit(self) -> None:
        """Ask the thread to leave its run loop (thread-safe; idempotent)."""
        self._alive = False
        self._transports.mailbox.wake()

    # ---------------------------------------------------------------------------------- run loop
    def poll(self, timeout_s: float | None = 0.0) -> int:
        """Run pending callbacks for up to ``timeout_s``; for code that drives a thread object by hand."""
        return self._transports.poll(timeout_s)

    def run_once(self) -> None:
        """One iteration: wait for an event or the next loop tick and run it.

        ``loop()`` is a periodic timer of the thread's reactor, so a due tick runs even under steady traffic
        (unlike Goby, which calls ``loop()`` only when a poll times out) and an idle thread sleeps until it.
        """
        hz = self.effective_loop_frequency_hz()
        if hz <= 0:
            self._transports.poll(None)
            return
        if math.isinf(hz):
            self._transports.poll(0.0)
            self.loop()
            return
        if self._loop_timer is None or not self._loop_timer.active:
            self._loop_timer = self._transports.reactor.call_every(self._loop_period, self._tick)
        self._transports.poll(None)
        error, self._loop_error = self._loop_error, None
        if error is not None:
            raise error

    def _loop_period(self) -> float:
        hz = self.effective_loop_frequency_hz()
        return 1.0 / hz if hz > 0 else math.inf

    def _tick(self) -> None:
        if self._alive:
            try:
                self.loop()
            except Exception as exc:  # noqa: BLE001 - re-raised by run_once: a failing loop() ends the thread
                self._loop_error = exc

    def run(self) -> None:
        """``initialize()``, loop until ``quit()``, ``finalize()``; runs on the calling thread."""
        self.initialize()
        self._after_initialize()
        try:
            while self._alive:
                self.run_once()
        finally:
            self.finalize()

    def _after_initialize(self) -> None:
        """Report ``ready`` to the manager when this thread runs its own process context (applications too)."""
        if self._owns_context and self._transports.has_interprocess:
            self.interprocess().ready()

    # ---------------------------------------------------------------------------------- shutdown
    def close(self) -> None:
        """Close the transports (and the process context if this thread created it); idempotent."""
        if self._closed:
            return
        self._closed = True
        self._alive = False
        self._transports.close()
        if self._owns_context:
            self._context.close()

    def __enter__(self) -> SimpleThread:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
