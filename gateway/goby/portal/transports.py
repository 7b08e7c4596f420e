"""The per-thread transport set: a reactor (with its mailbox), interthread handle, lazily-connected interprocess portal."""

from __future__ import annotations

import logging
import time

import zmq

from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.errors import ClosedError
from gateway.goby.portal.interprocess import InterProcessPortal
from gateway.goby.portal.interthread import InterThreadTransporter
from util.reactor import Reactor, Timer

log = logging.getLogger(__name__)


def _end_the_poll() -> None:
    """The service timer's callback: nothing, its firing only ends the poll (``ThreadTransports.poll`` then runs the
    portal's timed work)."""


class ThreadTransports:
    """Everything one thread waits on, in one ``Reactor``; all methods except ``mailbox.post`` belong to the owner."""

    def __init__(self, context: ProcessContext, thread_name: str) -> None:
        self.context = context
        self.thread_name = thread_name
        self.reactor = Reactor(thread_name, ClosedError)
        self.mailbox = self.reactor.mailbox
        self._interthread = InterThreadTransporter(
            context.interthread, self.mailbox, thread_name, context.registry, context.application
        )
        self._interprocess: InterProcessPortal | None = None
        self._service_timer: Timer | None = None
        self._closed = False
        context.register_closable(self)

    @property
    def closed(self) -> bool:
        return self._closed

    def interthread(self) -> InterThreadTransporter:
        return self._interthread

    def interprocess(self) -> InterProcessPortal:
        """The thread's portal, connecting to the broker on first use (may raise ``BrokerUnavailableError``)."""
        if self._interprocess is None:
            if self._closed:
                raise ClosedError(f"transports of {self.thread_name} are closed")
            portal = InterProcessPortal(self.context, self.mailbox, self.thread_name)
            for sock in portal.pollables():
                self._on_pollable(sock, True)
            portal.on_pollable = self._on_pollable
            self._interprocess = portal
            self._service_timer = self.reactor.call_later(0.0, _end_the_poll)
        return self._interprocess

    def _on_pollable(self, sock: zmq.Socket, add: bool) -> None:
        """The portal opened (or closed) a socket of its own, e.g. a manager query after a TCP broker restart."""
        if add:
            portal_handle = self._handle
            self.reactor.add_reader(sock, lambda: portal_handle(sock))
        else:
            self.reactor.remove_reader(sock)

    def _handle(self, sock: zmq.Socket) -> None:
        portal = self._interprocess
        if portal is not None:
            portal.handle(sock)

    def _arm_service(self, portal: InterProcessPortal) -> None:
        """Keep one timer at the portal's next deadline (hold requests, probes, re-queries, give-ups), so the poll
        ends then; ``poll`` runs the portal's timed work after every wake-up, this one included."""
        deadline = portal.next_deadline()
        timer = self._service_timer
        if timer is None:
            return
        if deadline is None:
            timer.cancel()
        elif not timer.active or timer.deadline != deadline:
            timer.reschedule(deadline)

    @property
    def has_interprocess(self) -> bool:
        return self._interprocess is not None

    def poll(self, timeout_s: float | None) -> int:
        """Wait up to ``timeout_s`` (None: until something happens) for work, run it on this thread; returns the
        events handled."""
        portal = self._interprocess
        if portal is None:
            return self.reactor.run_once(timeout_s)
        # the portal's timed work also runs around every wake-up (a hold released by another thread wakes this
        # one with no work of its own, only so that it flushes what it buffered)
        events = portal.service(time.monotonic())
        self._arm_service(portal)
        events += self.reactor.run_once(0.0 if events else timeout_s)
        return events + portal.service(time.monotonic())

    def close(self) -> None:
        """Drop interthread subscriptions, close the portal and the reactor; idempotent."""
        if self._closed:
            return
        self._closed = True
        self._interthread.unsubscribe_all()
        if self._interprocess is not None:
            for sock in self._interprocess.pollables():
                self.reactor.remove_reader(sock)
            self._interprocess.on_pollable = None
            self._interprocess.close()
        self.reactor.close()
