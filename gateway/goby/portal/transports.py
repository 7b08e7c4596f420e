"""The per-thread transport set: mailbox, interthread handle, lazily-connected interprocess portal, one poller."""

from __future__ import annotations

import logging
import math
import time

import zmq

from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.errors import ClosedError
from gateway.goby.portal.interprocess import InterProcessPortal
from gateway.goby.portal.interthread import InterThreadTransporter
from util.reactor import Mailbox

log = logging.getLogger(__name__)


class ThreadTransports:
    """Everything one thread polls; all methods except ``mailbox.post`` belong to the owning thread."""

    def __init__(self, context: ProcessContext, thread_name: str) -> None:
        self.context = context
        self.thread_name = thread_name
        self.mailbox = Mailbox(thread_name, ClosedError)
        self._poller = zmq.Poller()
        self._poller.register(self.mailbox.fd, zmq.POLLIN)
        self._interthread = InterThreadTransporter(
            context.interthread, self.mailbox, thread_name, context.registry, context.application
        )
        self._interprocess: InterProcessPortal | None = None
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
                self._poller.register(sock, zmq.POLLIN)
            portal.on_pollable = self._on_pollable
            self._interprocess = portal
        return self._interprocess

    def _on_pollable(self, sock: zmq.Socket, add: bool) -> None:
        """The portal opened (or closed) a socket of its own, e.g. a manager query after a TCP broker restart."""
        if add:
            self._poller.register(sock, zmq.POLLIN)
        else:
            self._poller.unregister(sock)

    @property
    def has_interprocess(self) -> bool:
        return self._interprocess is not None

    def poll(self, timeout_s: float | None) -> int:
        """Wait up to ``timeout_s`` (None: forever) for work, run it on this thread; returns the events handled."""
        events = self.mailbox.drain() if self.mailbox.pending() else 0
        portal = self._interprocess
        if portal is not None:
            now = time.monotonic()
            events += portal.service(now)
            deadline = portal.next_deadline()
            if deadline is not None:
                wait = max(0.0, deadline - now)
                timeout_s = wait if timeout_s is None else min(timeout_s, wait)
        if events:
            timeout_s = 0.0
        timeout_ms = None if timeout_s is None else math.ceil(timeout_s * 1000)
        for sock, _ in self._poller.poll(timeout_ms):
            if sock == self.mailbox.fd:
                events += self.mailbox.drain()
            elif portal is not None:
                events += portal.handle(sock)
        if portal is not None:
            events += portal.service(time.monotonic())
        return events

    def close(self) -> None:
        """Drop interthread subscriptions, close the portal and the mailbox; idempotent."""
        if self._closed:
            return
        self._closed = True
        self._interthread.unsubscribe_all()
        if self._interprocess is not None:
            for sock in self._interprocess.pollables():
                self._poller.unregister(sock)
            self._interprocess.on_pollable = None
            self._interprocess.close()
        self._poller.unregister(self.mailbox.fd)
        self.mailbox.close()
