"""``ivp-helm``: the helm as a MOOS app, reading its ``ProcessConfig = pHelmIvP`` block like pHelmIvP.

Threads: the MOOS client's I/O thread runs the on-connect callback (registrations) and the on-mail
callback, which only wakes the helm thread; the helm thread fetches the mail, handles it, and iterates
at ``AppTick`` (scaled by MOOSTimeWarp, as MOOS apps are).
"""

from __future__ import annotations

import argparse
import logging
import signal
import threading
import time
from pathlib import Path

from gateway.logsetup import add_verbosity_argument, configure_logging
from gateway.moos import MissionFileError, MoosClock, comms
from gateway.moos.mission_file import MissionFile

from .config import config_from_mission
from .helm import Helm, Post

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

    # ---- callbacks (MOOS client's I/O thread) ---------------------------------------------------
    def _on_connect(self) -> bool:
        self.helm.registered_at = self.clock.time()
        for var in self._registrations:
            self.comms.register(var, 0)
        return True

    def _on_mail(self) -> bool:
        self._wake.set()
        return True

    # ---- the helm thread ----------------------------------------------------------------------------
    def _run(self) -> None:
        while not self._stop.is_set() and not self.comms.wait_until_connected(200):
            pass
        if self._stop.is_set():
            return
        self._publish(self.helm.startup(self.clock.time()))
        period = 1.0 / (self.helm.config.app_tick * self.clock.warp)
        next_tick = time.monotonic()  # ticks are scheduled in real time: AppTick x warp per second
        while not self._stop.is_set():
            self._wake.wait(max(0.0, next_tick - time.monotonic()))
            self._wake.clear()
            self._handle_mail()
            now_real = time.monotonic()
            if now_real >= next_tick:
                try:
                    self._publish(self.helm.iterate(self.clock.time()))
                except Exception:  # a bug in one behaviour must not silently stop the helm thread
                    log.exception("helm iteration failed")
                    self.comms.notify("BHV_ERROR", "ivp-helm iteration failed (see the helm's log)")
                next_tick = max(next_tick + period, now_real)

    def _handle_mail(self) -> None:
        now = self.clock.time()
        for msg in self.comms.fetch():
            if msg.is_binary():
                log.debug("ignoring binary mail %s (no behaviour reads binary data)", msg.key())
                continue
            value = msg.double() if msg.is_double() else msg.string()
            self._publish(self.helm.handle_mail(msg.key(), value, msg.time(), msg.source(), now))

    def _publish(self, posts: list[Post]) -> None:
        for post in posts:
            self.comms.notify(post.var, post.value)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="ivp-helm", description="A pHelmIvP-compatible helm in Python.")
    parser.add_argument("mission", help=".moos mission file with a ProcessConfig = pHelmIvP block")
    parser.add_argument("--alias", help="MOOS name (and ProcessConfig block) to use instead of pHelmIvP")
    add_verbosity_argument(parser)
    args = parser.parse_args(argv)
    configure_logging(args.verbose, args.alias or DEFAULT_APP_NAME)
    try:
        app = HelmApp(args.mission, alias=args.alias)
    except MissionFileError as exc:
        log.error("%s", exc)
        return 2
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    app.start()
    log.info("%s connecting to %s:%d (state %s)", app.name, app.host, app.port, app.state)
    try:
        while not stop.wait(0.2):
            pass
    finally:
        app.stop()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
