"""``node-reporter``: pNodeReporter's role as a MOOS app, reading its ``ProcessConfig = pNodeReporter`` block.

It posts ``NODE_REPORT_LOCAL`` (``node_report_output``) in pNodeReporter's format every ``AppTick`` (scaled by
MOOSTimeWarp), once ownship's NAV_* make a valid record. Threads: one. The reporter and its MOOS client live on one
:class:`util.reactor.Reactor` (``comms(reactor=...)``), as ivp-helm: the AppTick is a reactor timer that handles the
mail received since the last tick, then iterates; arriving mail only lands in the client's inbox.
"""

from __future__ import annotations

import logging
from pathlib import Path

from behaviors.node_reporter import REGISTRATIONS, NodeReporter, NodeReporterConfig
from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.moos import MoosClock
from gateway.moos.mission_file import MissionFile
from gateway.moos.reactor_app import MoosReactorApp, serve
from util.reactor import Timer

log = logging.getLogger(__name__)
DEFAULT_APP_NAME = "pNodeReporter"


class NodeReporterApp(MoosReactorApp):
    """One reporter connected to the mission's MOOSDB, served by :meth:`run` on the calling thread."""

    def __init__(self, mission_path: str | Path, alias: str | None = None) -> None:
        self.mission = MissionFile(mission_path)
        name = alias or DEFAULT_APP_NAME
        block = name if self.mission.has_process_config(name) else DEFAULT_APP_NAME
        where = f"{self.mission.path}: ProcessConfig = {block}"
        self.config = NodeReporterConfig.from_pairs(self.mission.process_config(block), where)
        for problem in self.config.problems:
            log.warning("%s", problem)
        super().__init__(name, MoosClock(self.mission.time_warp), self.mission.server_host, self.mission.server_port,
                         f"node-reporter-{name}")
        self.reporter = NodeReporter(self.mission.community, self.config)
        self._tick: Timer | None = None

    def on_connect(self) -> bool:
        """Every (re)connection registers; the first one starts the AppTick."""
        ok = all(self.comms.register(v, 0) for v in REGISTRATIONS)
        if self._tick is None:
            self._tick = self.reactor.call_every(lambda: 1.0 / (self.config.app_tick * self.clock.warp), self._on_tick)
        return ok

    def _on_tick(self) -> None:
        """pNodeReporter's DoRunWork: the mail since the last tick, then Iterate."""
        now = self.clock.time()
        for msg in self.comms.fetch():
            if not msg.is_binary():
                self.reporter.handle_mail(msg.key(), msg.double() if msg.is_double() else msg.string(), now)
        for var, report in self.reporter.iterate(now):
            self.comms.notify(var, report)


def main(argv: list[str] | None = None) -> int:
    args = parse_moos_app_args(argv, "node-reporter", "NODE_REPORT_LOCAL from NAV_*, as pNodeReporter posts it.",
                               DEFAULT_APP_NAME)
    return serve(lambda: NodeReporterApp(args.mission, alias=args.alias),
                 lambda app: f"{app.name} reporting {app.mission.community} on {app.host}:{app.port}",
                 "node-reporter")


if __name__ == "__main__":
    raise SystemExit(main())
