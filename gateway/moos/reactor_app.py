"""The skeleton every MOOS app of ours shares (ivp-helm, node-reporter, moos-share, moos-logger): one thread, one
:class:`util.reactor.Reactor` holding the app's MOOS client (``comms(reactor=...)``) and whatever else it waits for.

Why one base: the four apps connect, serve until a signal and close in the same order (MOOS client, the app's own
resources, the reactor); written once, a fix to that order reaches all of them. An app supplies its registrations
(:meth:`MoosReactorApp.on_connect`) and, if it needs them, the hooks around the connection.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TypeVar

from gateway.moos.client import comms
from gateway.moos.clock import MoosClock
from gateway.moos.mission_file import MissionFileError
from util.process import handle_signals
from util.reactor import Reactor

log = logging.getLogger(__name__)
App = TypeVar("App", bound="MoosReactorApp")


class MoosReactorApp:
    """A MOOS app served by :meth:`run` on the calling thread until :meth:`stop`.

    ``failure`` (a text) is why the app stopped on its own; :func:`serve` turns it into exit status 1."""

    def __init__(self, name: str, clock: MoosClock, host: str, port: int, reactor_name: str) -> None:
        self.name, self.clock, self.host, self.port = name, clock, host, port
        self.reactor = Reactor(reactor_name)
        self.comms = comms(clock=clock, reactor=self.reactor)
        self.comms_tick = 5.0  # the client's CommsTick (MOOS's default)
        self.failure: str | None = None
        self._stop_requested = False

    # ---- hooks ------------------------------------------------------------------------------------------
    def on_connect(self) -> bool:
        """Every (re)connection to the MOOSDB: register (pymoos's on-connect callback contract)."""
        raise NotImplementedError

    def before_connect(self) -> bool:
        """Work before connecting (open files, ...); False (with :attr:`failure` set) stops the app there."""
        return True

    def after_connect(self) -> None:
        """Work once the client runs (timers)."""

    def after_close(self) -> None:
        """Release the app's own resources; the MOOS client is closed, the reactor not yet."""

    # ---- running ----------------------------------------------------------------------------------------
    def run(self) -> None:
        """Connect and serve on the calling thread until :meth:`stop` (or a failure: see :attr:`failure`)."""
        try:
            if not self.before_connect():
                return
            self.comms.set_on_connect_callback(self.on_connect)
            self.comms.run(self.host, self.port, self.name, self.comms_tick)
            self.after_connect()
            self.reactor.run(until=lambda: self._stop_requested)
        finally:
            self.comms.close(True)  # on this thread: writes out what the last pass posted
            try:
                self.after_close()
            finally:
                self.reactor.close()

    def stop(self) -> None:
        """Make :meth:`run` return (from any thread, a signal handler included)."""
        self._stop_requested = True
        self.reactor.stop()

    def fail(self, text: str) -> None:
        """Stop the app because of ``text`` (the first failure is the one reported)."""
        self.failure = self.failure or text
        self.stop()


def serve(build: Callable[[], App], started: Callable[[App], str], program: str) -> int:
    """A MOOS app's ``main``: build it (a bad mission file: its message, status 2), run it until SIGINT/SIGTERM
    after logging ``started(app)``; status 1 if it stopped on a failure, else 0."""
    try:
        app = build()
    except MissionFileError as exc:
        log.error("%s", exc)
        return 2
    with handle_signals(lambda _signum: app.stop()):
        log.info("%s", started(app))
        app.run()
    if app.failure is not None:
        log.critical("%s stopped: %s", program, app.failure)
        return 1
    return 0
