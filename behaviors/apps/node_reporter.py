"""``node-reporter``: pNodeReporter's role as a MOOS app, reading its ``ProcessConfig = pNodeReporter`` block.

It posts ``NODE_REPORT_LOCAL`` (``node_report_output``) in pNodeReporter's format every ``AppTick`` (scaled by
MOOSTimeWarp), once ownship's NAV_* make a valid record. Threads: the MOOS client's I/O thread runs the
on-connect callback (registrations); the thread that calls :meth:`NodeReporterApp.run` fetches mail and posts.
"""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path

from behaviors.node_reporter import REGISTRATIONS, NodeReporter, NodeReporterConfig
from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.moos import MissionFileError, MoosClock, comms
from gateway.moos.mission_file import MissionFile
from util.process import handle_signals

log = logging.getLogger(__name__)
DEFAULT_APP_NAME = "pNodeReporter"


class NodeReporterApp:
    """One reporter connected to the mission's MOOSDB."""

    def __init__(self, mission_path: str | Path, alias: str | None = None) -> None:
        self.mission = MissionFile(mission_path)
        self.name = alias or DEFAULT_APP_NAME
        block = self.name if self.mission.has_process_config(self.name) else DEFAULT_APP_NAME
        where = f"{self.mission.path}: ProcessConfig = {block}"
        self.config = NodeReporterConfig.from_pairs(self.mission.process_config(block), where)
        for problem in self.config.problems:
            log.warning("%s", problem)
        self.clock = MoosClock(self.mission.time_warp)
        self.reporter = NodeReporter(self.mission.community, self.config)
        self.comms = comms(clock=self.clock)
        self._wake = threading.Event()

    def run(self, stop: threading.Event) -> None:
        """Serve until ``stop`` is set; runs on the calling thread."""
        self.comms.set_on_connect_callback(lambda: all(self.comms.register(v, 0) for v in REGISTRATIONS))
        self.comms.set_on_mail_callback(self._on_mail)
        self.comms.run(self.mission.server_host, self.mission.server_port, self.name)
        period = 1.0 / (self.config.app_tick * self.clock.warp)
        next_tick = time.monotonic()
        try:
            while not stop.is_set():
                self._wake.wait(max(0.0, next_tick - time.monotonic()))
                self._wake.clear()
                now = self.clock.time()
                for msg in self.comms.fetch():
                    if not msg.is_binary():
                        self.reporter.handle_mail(msg.key(), msg.double() if msg.is_double() else msg.string(), now)
                if time.monotonic() >= next_tick:
                    for var, report in self.reporter.iterate(now):
                        self.comms.notify(var, report)
                    next_tick = max(next_tick + period, time.monotonic())
        finally:
            self.comms.close(True)

    def wake(self) -> None:
        self._wake.set()

    def _on_mail(self) -> bool:
        """Runs on the MOOS client's I/O thread: only wakes the loop."""
        self._wake.set()
        return True


def main(argv: list[str] | None = None) -> int:
    args = parse_moos_app_args(argv, "node-reporter", "NODE_REPORT_LOCAL from NAV_*, as pNodeReporter posts it.",
                               DEFAULT_APP_NAME)
    try:
        app = NodeReporterApp(args.mission, alias=args.alias)
    except MissionFileError as exc:
        log.error("%s", exc)
        return 2
    with handle_signals(lambda _signum: app.wake()) as stop:
        log.info("%s reporting %s on %s:%d", app.name, app.mission.community, app.mission.server_host,
                 app.mission.server_port)
        app.run(stop)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
