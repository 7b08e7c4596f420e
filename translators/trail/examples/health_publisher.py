"""The lecture's "Time in Goby" publisher (goby3-course ``interprocess1/publisher``): a HealthStatus stamped with
``set_timestamp_with_units(SystemClock::now<MicroTime>())`` on interprocess ``goby3_course::health_status``, 1 Hz.

    goby-broker --interprocess 'platform: "demo"' &
    python -m translators.trail.examples.health_publisher --interprocess 'platform: "demo"' -v
"""

from __future__ import annotations

import logging
import sys

from gateway.goby.dccl import units
from gateway.goby.portal import SingleThreadApplication, run_application
from translators.trail import groups
from translators.trail.protobuf.health_monitor_config_pb2 import HealthMonitor
from translators.trail.protobuf.health_status_pb2 import HealthStatus

log = logging.getLogger(__name__)


class HealthPublisher(SingleThreadApplication):
    """Publishes a GOOD HealthStatus with the (warped) time of publication each second."""

    def __init__(self, cfg: HealthMonitor) -> None:
        super().__init__(cfg, loop_frequency_hz=1)

    def loop(self) -> None:
        status = HealthStatus(state=HealthStatus.GOOD)
        units.set_with_units(status, "timestamp", units.now(self.context.clock))
        log.info("publishing HealthStatus at %d us", status.timestamp)
        self.interprocess().publish(groups.health_status, status)


def main(argv: list[str] | None = None) -> int:
    return run_application(HealthPublisher, HealthMonitor, argv, prog="health_publisher")


if __name__ == "__main__":
    sys.exit(main())
