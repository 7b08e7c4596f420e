"""What the threads of one application share: the ZeroMQ context, the interthread hub, the start-up hold, the
config, the clock and the interface registry.

An application creates one ``ProcessContext`` and its threads find it through :func:`current_context` (set on each
thread the application launches), so user thread classes need not pass it around.  Nothing here is module-level:
two applications in one process (tests do this) have separate clocks and registries.
"""

from __future__ import annotations

import logging
import os
import sys
import threading
import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, TypeVar

import zmq

from gateway.goby.portal.interface_registry import InterfaceRegistry
from gateway.goby.portal.interthread import InterThread
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from util.reactor import Mailbox

if TYPE_CHECKING:
    from gateway.goby.dccl import Codec as DcclCodec

log = logging.getLogger(__name__)

_current = threading.local()

#: Seconds between a released hold and flushing buffered publications (Goby sleeps 1 s to let subscriptions settle).
DEFAULT_HOLD_SETTLE_S = 1.0


class ProcessContext:
    """Shared state of one application's portal threads; close it after every thread using it has closed.

    ``clock``: the application's (possibly warped) clock, a real-time ``SystemClock`` unless given;
    ``registry``: where every publish/subscribe call is recorded, a new one unless given.
    """

    def __init__(
        self,
        interprocess: InterProcessPortalConfig | None = None,
        *,
        client_name: str | None = None,
        application: str = "",
        clock: SystemClock | None = None,
        registry: InterfaceRegistry | None = None,
        hold_settle_s: float = DEFAULT_HOLD_SETTLE_S,
    ) -> None:
        self.interprocess_cfg = interprocess if interprocess is not None else InterProcessPortalConfig()
        self.application = application or os.path.basename(sys.argv[0] or "python")
        if self.interprocess_cfg.HasField("client_name"):
            self.client_name = self.interprocess_cfg.client_name
        else:
            self.client_name = client_name or self.application
        self.clock = clock if clock is not None else SystemClock()
        self.registry = registry if registry is not None else InterfaceRegistry()
        self.hold_settle_s = hold_settle_s
        self.interthread = InterThread()
        self._dccl: DcclCodec | None = None
        self.ready_flag = False
        self._hold_released = threading.Event()
        self._primary_claimed = False
        self._mailboxes: weakref.WeakSet[Mailbox] = weakref.WeakSet()
        self._closables: weakref.WeakSet[Any] = weakref.WeakSet()
        self._lock = threading.Lock()
        self._zmq: zmq.Context | None = None
        self._closed = False

    @property
    def dccl(self) -> DcclCodec:
        """The process's DCCL codec (Goby keeps one per process), made on first use: a process that never meets a
        DCCL message does not pay for the codec's imports (2.6 MiB)."""
        codec = self._dccl
        if codec is None:
            with self._lock:
                if self._dccl is None:
                    from gateway.goby.dccl import Codec

                    self._dccl = Codec()
                codec = self._dccl
        return codec

    @property
    def zmq_context(self) -> zmq.Context:
        """The process's ZeroMQ context, created on first use with ``zeromq_number_io_threads`` I/O threads."""
        with self._lock:
            if self._zmq is None:
                self._zmq = zmq.Context(io_threads=max(1, self.interprocess_cfg.zeromq_number_io_threads))
            return self._zmq

    def claim_primary(self) -> bool:
        """True for the first portal of the process: it runs the hold handshake for everyone."""
        with self._lock:
            if self._primary_claimed:
                return False
            self._primary_claimed = True
            return True

    def register_closable(self, thing: Any) -> None:
        """Track per-thread transports so ``close()`` can release those whose owner never closed them (e.g. a
        thread constructor that raised after connecting)."""
        self._closables.add(thing)

    def register_mailbox(self, mailbox: Mailbox) -> None:
        """Wake ``mailbox`` when the hold is released (so its buffered publications flush)."""
        self._mailboxes.add(mailbox)

    @property
    def hold_released(self) -> bool:
        return self._hold_released.is_set()

    def release_hold(self) -> None:
        """Let every thread publish; wakes all portal threads so they flush what they buffered."""
        if self._hold_released.is_set():
            return
        self._hold_released.set()
        for mailbox in list(self._mailboxes):
            mailbox.wake()

    def close(self) -> None:
        """Close transports left open, then terminate the ZeroMQ context; idempotent.

        Call it after every thread using the context has finished (their sockets are closed here otherwise).
        """
        with self._lock:
            if self._closed:
                return
            self._closed = True
            zctx, self._zmq = self._zmq, None
        for leftover in list(self._closables):
            if not getattr(leftover, "closed", True):
                log.debug("closing transports of %s left open by their thread", getattr(leftover, "thread_name", "?"))
                leftover.close()
        if zctx is not None:
            zctx.destroy()  # closes any socket still open instead of blocking forever in term()

    def __enter__(self) -> ProcessContext:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def current_context() -> ProcessContext | None:
    """The context set for the calling thread by :func:`use_context`, if any."""
    return getattr(_current, "context", None)


@contextmanager
def use_context(context: ProcessContext) -> Iterator[ProcessContext]:
    """Make ``context`` the calling thread's current context for the duration of the block."""
    previous = current_context()
    _current.context = context
    try:
        yield context
    finally:
        _current.context = previous


T = TypeVar("T")


def start_on_thread(context: ProcessContext, build: Callable[[], T], run: Callable[[T], None],
                    name: str) -> tuple[T, threading.Thread]:
    """Call ``build()`` on a new Python thread under ``context`` (so what it creates belongs to that thread), then
    ``run(built)`` there; returns once ``build`` has finished, with what it built and the thread.

    If ``build`` raises, the thread ends and the exception is raised here.
    """
    built = threading.Event()
    box: dict[str, Any] = {}

    def target() -> None:
        with use_context(context):
            try:
                obj = build()
            except BaseException as exc:  # noqa: BLE001 - raised again on the starting thread
                box["error"] = exc
                built.set()
                return
            box["built"] = obj
            built.set()
            run(obj)

    pythread = threading.Thread(target=target, name=name)
    pythread.start()
    built.wait()
    if "error" in box:
        pythread.join()
        raise box["error"]
    return box["built"], pythread
