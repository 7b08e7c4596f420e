"""usv-health-monitor: the Goby3 course's goby3_course_usv_health_monitor (post-homework2,
``src/bin/health_monitor/app.cpp``).

On the USV: each ``VehicleHealth`` goby-coroner publishes on ``goby::health::report`` becomes the course's
``HealthStatus`` (``timestamp`` = now in microseconds, the application's warped clock) sent to the topside on
intervehicle: HEALTH__OK on ``health_status_good`` (``max_queue 1``, ``value_base 50``), anything else on
``health_status_failed`` (``max_queue 1``, ``value_base 500``: it wins the satellite slot over everything else).
The rules are in :mod:`translators.trail.health_status`.
"""

from __future__ import annotations

import logging

from gateway.goby.portal import SingleThreadApplication, run_application
from gateway.goby.portal.health import HEALTH_REPORT
from gateway.goby.portal.protobuf.coroner_pb2 import VehicleHealth
from translators.trail import groups
from translators.trail.health_status import health_publisher, health_status
from translators.trail.nav_links import short
from translators.trail.protobuf.health_monitor_config_pb2 import HealthMonitor as HealthMonitorConfig

log = logging.getLogger(__name__)


class HealthMonitor(SingleThreadApplication):
    """The coroner's vehicle report, GOOD or FAILED, to the topside over intervehicle."""

    def __init__(self, cfg: HealthMonitorConfig) -> None:
        super().__init__(cfg)
        self.interprocess().subscribe(HEALTH_REPORT, VehicleHealth, self._on_health_report)

    def _on_health_report(self, report: VehicleHealth) -> None:
        """Publish the report's HealthStatus. Runs on the application's main thread."""
        group, status = health_status(report, self.context.clock.now_micro())
        log.info("Publishing HealthStatus to %s: %s", group, short(status))
        if group == groups.health_status_good:  # one call per group, as the course's switch (and the interface)
            self.intervehicle().publish(groups.health_status_good, status,
                                        publisher=health_publisher(groups.health_status_good))
        else:
            self.intervehicle().publish(groups.health_status_failed, status,
                                        publisher=health_publisher(groups.health_status_failed))


def main(argv: list[str] | None = None) -> int:
    """Console script ``usv-health-monitor``: Goby-style config file / ``--interprocess`` / ``GOBY_INTERPROCESS``."""
    return run_application(HealthMonitor, HealthMonitorConfig, argv, prog="usv-health-monitor")


if __name__ == "__main__":
    raise SystemExit(main())
