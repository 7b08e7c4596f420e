"""Health answers, as Goby3's coroner (src/middleware/coroner/): every application answers ``goby::health::request``
with a ``ProcessHealth`` on ``goby::health::response``.

A single-thread application answers at once from its main thread (Goby's ``coroner::Application``).  A multi-thread
application collects one ``ThreadHealth`` per launched thread (Goby's ``HealthMonitorThread``): on a request its main
thread posts a probe to each thread's mailbox, each thread fills its own answer on its own reactor and posts it
back, and the main thread publishes when all have answered or when the window (Goby's 1 s) closes, whichever comes
first.  A thread that has not answered by then stays as preseeded: ``HEALTH__FAILED`` with
``ERROR__THREAD_NOT_RESPONDING``, and the process's state is the worst of its threads.  Everything here runs on the
application's main thread (the probes on each launched thread); the window is a timer on the main reactor.

These calls are made by the application base classes, not by the application's own code; they are recorded in the
interface registry like any other (the same for terminate.py), and the interface analysis lists them for every
application class (launch/interfaces/analyze.py), as Goby's interface files do.
"""

from __future__ import annotations

import functools
import logging
import os
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from gateway.goby.portal.errors import ClosedError
from gateway.goby.portal.group import Group
from gateway.goby.portal.protobuf.coroner_pb2 import (
    ERROR__THREAD_NOT_RESPONDING,
    HEALTH__FAILED,
    HealthRequest,
    ProcessHealth,
    ThreadHealth,
)

if TYPE_CHECKING:
    from gateway.goby.portal.thread import SimpleThread
    from util.reactor import Timer

log = logging.getLogger(__name__)

#: Goby3's ``goby::middleware::groups::health_request`` / ``health_response`` / ``health_report``
#: (src/middleware/coroner/groups.h).
HEALTH_REQUEST = Group("goby::health::request")
HEALTH_RESPONSE = Group("goby::health::response")
HEALTH_REPORT = Group("goby::health::report")

#: Goby's ``HealthMonitorThread::health_request_timeout_`` (steady clock, not warped).
THREAD_RESPONSE_WINDOW_S = 1.0


def process_health(app_name: str, main: ThreadHealth) -> ProcessHealth:
    """A ``ProcessHealth`` for this process: ``name``, ``pid`` and the main thread's answer."""
    answer = ProcessHealth(name=app_name, pid=os.getpid())
    answer.main.CopyFrom(main)
    return answer


def answer_at_once(app: SimpleThread, app_name: Callable[[], str]) -> None:
    """Subscribe ``app`` (a single-thread application, on its main thread) to answer health requests directly."""

    def on_request(_request: HealthRequest) -> None:
        app.interprocess().publish(HEALTH_RESPONSE, process_health(app_name(), app.thread_health()))

    app.interprocess().subscribe(HEALTH_REQUEST, HealthRequest, on_request)


class ThreadHealthCollector:
    """A multi-thread application's answer: its main thread's health plus one child per launched thread.

    Built and used on the application's main thread; ``threads`` lists the launched threads at request time.
    """

    def __init__(self, app: SimpleThread, app_name: Callable[[], str], threads: Callable[[], Sequence[SimpleThread]],
                 window_s: float = THREAD_RESPONSE_WINDOW_S) -> None:
        self._app = app
        self._app_name = app_name
        self._threads = threads
        self._window_s = window_s
        self._request = 0  # numbers the requests: a late answer to an earlier one is dropped
        self._pending: ProcessHealth | None = None
        self._waiting: set[int] = set()
        self._timer: Timer | None = None
        app.interprocess().subscribe(HEALTH_REQUEST, HealthRequest, self._on_request)

    def _on_request(self, _request: HealthRequest) -> None:
        if self._pending is not None:
            return  # the answer to the request in progress goes out within the window
        self._request += 1
        number = self._request
        answer = process_health(self._app_name(), self._app.thread_health())
        self._waiting = set()
        for thread in self._threads():
            child = answer.main.child.add(name=thread.thread_name, uid=thread.uid, state=HEALTH__FAILED,
                                          error=ERROR__THREAD_NOT_RESPONDING)
            child.error_message = f"thread {thread.thread_name} did not answer within {self._window_s:g} s"
            try:
                thread.call_soon(functools.partial(self._probe, thread, number))
            except ClosedError:
                continue  # ending: stays reported as not responding
            self._waiting.add(thread.uid)
        self._pending = answer
        if not self._waiting:
            self._publish()
            return
        self._timer = self._app.reactor.call_later(self._window_s, self._publish)

    def _probe(self, thread: SimpleThread, number: int) -> None:
        """On ``thread``: fill its answer and hand it to the main thread."""
        health = thread.thread_health()
        try:
            self._app.call_soon(functools.partial(self._record, number, health))
        except ClosedError:
            log.debug("health answer of %s arrived after the application closed", thread.thread_name)

    def _record(self, number: int, health: ThreadHealth) -> None:
        answer = self._pending
        if answer is None or number != self._request:
            return
        for child in answer.main.child:
            if child.uid == health.uid:
                child.CopyFrom(health)
        self._waiting.discard(health.uid)
        if not self._waiting:
            self._publish()

    def _publish(self) -> None:
        answer, self._pending = self._pending, None
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        if answer is None:
            return
        if self._waiting:
            log.warning("threads not answering the health request: %s",
                        ", ".join(c.name for c in answer.main.child if c.uid in self._waiting))
        worst = max([answer.main.state, *(c.state for c in answer.main.child)])
        answer.main.state = worst
        self._app.interprocess().publish(HEALTH_RESPONSE, answer)
