"""``ivp-helm``: the helm as a MOOS app, reading its ``ProcessConfig = pHelmIvP`` block like pHelmIvP.

Threads: one. The helm lives on a :class:`util.reactor.Reactor` together with its MOOS client
(``comms(reactor=...)``), so one thread (the one calling :meth:`HelmApp.run`: the main thread in ``ivp-helm``, or
the ``helm-<name>`` thread of :meth:`HelmApp.start`) connects, reads, registers, handles the mail, iterates and
writes. As pHelmIvP (a MOOS app in its default REGULAR_ITERATE_AND_MAIL mode) it wakes for its AppTick
(``AppTick`` x MOOSTimeWarp per real second, a reactor timer): each tick handles the mail received since the last
one, then iterates; arriving mail only lands in the client's inbox. A failure in one message, one posting or one
iteration is logged (and posted as ``BHV_ERROR``) and the helm serves on; a failure it cannot serve through (its
start-up) stops the reactor, and :func:`main` then exits non-zero.
"""

from __future__ import annotations

import logging
import threading
from pathlib import Path

from behaviors.helm.config import config_from_mission
from behaviors.helm.helm import Helm, Post
from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.moos import MoosClock
from gateway.moos.message import BINARY, DOUBLE
from gateway.moos.mission_file import MissionFile
from gateway.moos.reactor_app import MoosReactorApp, serve
from util.reactor import Timer

log = logging.getLogger(__name__)
DEFAULT_APP_NAME = "pHelmIvP"


class HelmApp(MoosReactorApp):
    """One helm connected to one MOOSDB: :meth:`run` serves on the calling thread; :meth:`start` / :meth:`stop`
    (idempotent) serve on a thread of its own, or use it as a context manager."""

    def __init__(self, mission_path: str | Path, alias: str | None = None, clock: MoosClock | None = None,
                 host: str | None = None, port: int | None = None) -> None:
        self.mission = MissionFile(mission_path)
        name = alias or DEFAULT_APP_NAME
        config = config_from_mission(self.mission, name)
        if alias and not self.mission.has_process_config(alias) and self.mission.has_process_config(DEFAULT_APP_NAME):
            config = config_from_mission(self.mission, DEFAULT_APP_NAME)
        super().__init__(name, clock or MoosClock(config.time_warp), host or self.mission.server_host,
                         port or self.mission.server_port, f"helm-{name}")
        self.helm = Helm(config, app_name=self.name, ownship=self.mission.community)
        self._registrations = sorted(self.helm.registrations())
        self._tick: Timer | None = None
        self._thread: threading.Thread | None = None
        self._done = threading.Event()  # run() has returned

    @property
    def state(self) -> str:
        return self.helm.state

    # ---- running ----------------------------------------------------------------------------------------
    def run(self) -> None:
        """Connect and serve on the calling thread until :meth:`stop` (or a start-up failure: see :attr:`failure`)."""
        try:
            super().run()
        finally:
            self._done.set()

    def start(self) -> HelmApp:
        self._thread = threading.Thread(target=self._run_thread, name=f"helm-{self.name}", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Make :meth:`run` return (from any thread, a signal handler included); waits for :meth:`start`'s thread."""
        super().stop()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(10)
            self._thread = None

    def __enter__(self) -> HelmApp:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the helm has stopped (or ``timeout``); True if stopped."""
        return self._done.wait(timeout)

    def _run_thread(self) -> None:
        try:
            self.run()
        except BaseException as exc:  # recorded for the owner; the helm is not running any more
            self.failure = self.failure or f"the helm thread has stopped ({exc!r}); no helm is running"
            log.critical("the helm thread has stopped: %r", exc, exc_info=exc)

    # ---- reactor work ----------------------------------------------------------------------------------
    def on_connect(self) -> bool:
        """Every (re)connection: note the registration time and register; the first one also starts the helm."""
        self.helm.registered_at = self.clock.time()  # before registering: mail can only follow registration
        for var in self._registrations:
            self.comms.register(var, 0)
        if self._tick is None:
            try:
                self._publish(self.helm.startup(self.clock.time()))
            except Exception as exc:  # the helm cannot serve without its start-up: stop, main() exits non-zero
                log.critical("the helm has stopped: start-up failed: %r", exc, exc_info=exc)
                self._report_error(f"ivp-helm stopped: {exc!r}")
                self.fail(f"the helm's start-up failed ({exc!r}); exiting, no helm is running")
                return True
            self._tick = self.reactor.call_every(self._period, self._on_tick)
        return True

    def _period(self) -> float:
        """Real seconds between AppTicks: pHelmIvP iterates ``AppTick`` times per MOOS second."""
        return 1.0 / (self.helm.config.app_tick * self.clock.warp)

    def _on_tick(self) -> None:
        """pHelmIvP's DoRunWork: the mail received since the last tick (OnNewMail), then Iterate."""
        try:
            self._handle_mail()
        except Exception:  # e.g. the clock failed: the next tick may well succeed
            log.exception("helm mail pass failed")
            self._report_error("ivp-helm loop pass failed (see the helm's log)")
        try:
            posts = self.helm.iterate(self.clock.time())
        except Exception:  # a bug in one behaviour must not stop the helm
            log.exception("helm iteration failed")
            self._report_error("ivp-helm iteration failed (see the helm's log)")
        else:
            self._publish(posts)

    def _handle_mail(self) -> None:
        mail = self.comms.fetch()
        if not mail:
            return
        now = self.clock.time()
        handle = self.helm.handle_mail
        for msg in mail:
            kind = msg.data_type
            if kind == BINARY:
                log.debug("ignoring binary mail %s (no behaviour reads binary data)", msg.key())
                continue
            var = msg.key()
            value = msg.dval if kind == DOUBLE else msg.string()
            try:
                posts = handle(var, value, msg.msg_time, msg.source(), now)
            except Exception:  # drop this message, keep the rest of the batch
                log.exception("handling mail %s=%r from %s failed", var, value, msg.source())
                self._report_error(f"ivp-helm could not handle mail {var} (see the helm's log)")
                continue
            if posts:
                self._publish(posts)

    def _publish(self, posts: list[Post]) -> None:
        notify = self.comms.notify
        for post in posts:
            try:
                notify(post.var, post.value)
            except Exception:  # one bad posting must not lose the ones after it
                log.exception("posting %s=%r failed", post.var, post.value)
                self._report_error(f"ivp-helm could not post {post.var} (see the helm's log)")

    def _report_error(self, text: str) -> None:
        try:
            self.comms.notify("BHV_ERROR", text)
        except Exception:  # already failing: the log has the cause
            log.debug("could not post BHV_ERROR", exc_info=True)


def main(argv: list[str] | None = None) -> int:
    args = parse_moos_app_args(argv, "ivp-helm", "A pHelmIvP-compatible helm in Python.", DEFAULT_APP_NAME)
    return serve(lambda: HelmApp(args.mission, alias=args.alias),
                 lambda app: f"{app.name} connecting to {app.host}:{app.port} (state {app.state})", "ivp-helm")


if __name__ == "__main__":
    raise SystemExit(main())
