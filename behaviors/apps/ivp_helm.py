"""``ivp-helm``: the helm as a MOOS app, reading its ``ProcessConfig = pHelmIvP`` block like pHelmIvP.

Threads: the MOOS client's I/O thread runs the on-connect callback (registrations) and the on-mail
callback; both only wake the helm thread. The helm thread alone touches the :class:`Helm`: it notes the
registration time, fetches the mail, handles it, and iterates at ``AppTick`` (scaled by MOOSTimeWarp, as
MOOS apps are). A failure in one message, one posting or one iteration is logged and the helm serves on;
a failure it cannot serve through (start-up, or an error outside the loop) ends the helm thread, and
:func:`main` then exits non-zero.
"""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path

from behaviors.helm.config import config_from_mission
from behaviors.helm.helm import Helm, Post
from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.moos import MissionFileError, MoosClock, comms
from gateway.moos.mission_file import MissionFile
from util.process import handle_signals

log = logging.getLogger(__name__)
DEFAULT_APP_NAME = "pHelmIvP"


class HelmApp:
    """One helm connected to one MOOSDB; :meth:`start` / :meth:`stop` (idempotent), or use as a context manager."""

    def __init__(self, mission_path: str | Path, alias: str | None = None, clock: MoosClock | None = None,
                 host: str | None = None, port: int | None = None) -> None:
        self.mission = MissionFile(mission_path)
        self.name = alias or DEFAULT_APP_NAME
        config = config_from_mission(self.mission, self.name)
        if alias and not self.mission.has_process_config(alias) and self.mission.has_process_config(DEFAULT_APP_NAME):
            config = config_from_mission(self.mission, DEFAULT_APP_NAME)
        self.clock = clock or MoosClock(config.time_warp)
        self.host = host or self.mission.server_host
        self.port = port or self.mission.server_port
        self.helm = Helm(config, app_name=self.name, ownship=self.mission.community)
        self.comms = comms(clock=self.clock)
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._registrations = sorted(self.helm.registrations())
        self._registered_at: float | None = None  # written by the I/O thread, copied by the helm thread
        self.failure: BaseException | None = None  # why the helm thread ended early, if it did

    @property
    def state(self) -> str:
        return self.helm.state

    def start(self) -> HelmApp:
        self.comms.set_on_connect_callback(self._on_connect)
        self.comms.set_on_mail_callback(self._on_mail)
        self.comms.run(self.host, self.port, self.name)
        self._thread = threading.Thread(target=self._run, name=f"helm-{self.name}", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(10)
            self._thread = None
        self.comms.close(True)

    def __enter__(self) -> HelmApp:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until :meth:`stop` is called (or ``timeout``); True if stopped."""
        return self._stop.wait(timeout)

    def helm_thread_alive(self) -> bool:
        """False once the helm thread has ended (after :meth:`stop`, or early: see :attr:`failure`)."""
        return self._thread is not None and self._thread.is_alive()

    # ---- callbacks (MOOS client's I/O thread) ---------------------------------------------------
    def _on_connect(self) -> bool:
        """Register and wake the helm thread, which applies the registration time to the helm."""
        self._registered_at = self.clock.time()  # before registering: mail can only follow registration
        for var in self._registrations:
            self.comms.register(var, 0)
        self._wake.set()
        return True

    def _on_mail(self) -> bool:
        self._wake.set()
        return True

    # ---- the helm thread ----------------------------------------------------------------------------
    def _run(self) -> None:
        try:
            self._serve()
        except BaseException as exc:  # recorded for main(), which exits non-zero
            self.failure = exc
            log.critical("the helm thread has stopped: %r", exc, exc_info=exc)
            self._report_error(f"ivp-helm stopped: {exc!r}")

    def _serve(self) -> None:
        while not self._stop.is_set() and not self.comms.wait_until_connected(200):
            pass
        if self._stop.is_set():
            return
        self._apply_registration()
        self._publish(self.helm.startup(self.clock.time()))
        period = 1.0 / (self.helm.config.app_tick * self.clock.warp)
        next_tick = time.monotonic()  # ticks are scheduled in real time: AppTick x warp per second
        while not self._stop.is_set():
            self._wake.wait(max(0.0, next_tick - time.monotonic()))
            self._wake.clear()
            try:
                next_tick = self._serve_once(next_tick, period)
            except Exception:  # e.g. fetch or the clock failed: the next pass may well succeed
                log.exception("helm loop pass failed")
                self._report_error("ivp-helm loop pass failed (see the helm's log)")
                next_tick = max(next_tick + period, time.monotonic())

    def _serve_once(self, next_tick: float, period: float) -> float:
        """Handle the mail, then iterate if the tick is due; returns the next tick time."""
        self._apply_registration()
        self._handle_mail()
        now_real = time.monotonic()
        if now_real < next_tick:
            return next_tick
        try:
            posts = self.helm.iterate(self.clock.time())
        except Exception:  # a bug in one behaviour must not stop the helm thread
            log.exception("helm iteration failed")
            self._report_error("ivp-helm iteration failed (see the helm's log)")
        else:
            self._publish(posts)
        return max(next_tick + period, now_real)

    def _apply_registration(self) -> None:
        registered_at = self._registered_at
        if registered_at is not None:
            self.helm.registered_at = registered_at

    def _handle_mail(self) -> None:
        now = self.clock.time()
        for msg in self.comms.fetch():
            if msg.is_binary():
                log.debug("ignoring binary mail %s (no behaviour reads binary data)", msg.key())
                continue
            value = msg.double() if msg.is_double() else msg.string()
            try:
                posts = self.helm.handle_mail(msg.key(), value, msg.time(), msg.source(), now)
            except Exception:  # drop this message, keep the rest of the batch
                log.exception("handling mail %s=%r from %s failed", msg.key(), value, msg.source())
                self._report_error(f"ivp-helm could not handle mail {msg.key()} (see the helm's log)")
                continue
            self._publish(posts)

    def _publish(self, posts: list[Post]) -> None:
        for post in posts:
            try:
                self.comms.notify(post.var, post.value)
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
    try:
        app = HelmApp(args.mission, alias=args.alias)
    except MissionFileError as exc:
        log.error("%s", exc)
        return 2
    with handle_signals() as stop:
        app.start()
        log.info("%s connecting to %s:%d (state %s)", app.name, app.host, app.port, app.state)
        try:
            while not stop.wait(0.2):
                if not app.helm_thread_alive():
                    log.critical("ivp-helm: the helm thread has stopped (%r); exiting, no helm is running",
                                 app.failure)
                    return 1
        finally:
            app.stop()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
