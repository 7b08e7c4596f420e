"""The lecture's "Time in Goby" subscriber (goby3-course ``interprocess1/subscriber``): for each HealthStatus on
interprocess ``goby3_course::health_status`` it prints the timestamp as a date (Boost's ``to_simple_string``) and
the latency in microseconds (now minus the timestamp, both on the application's warped clock).

    python -m translators.trail.examples.health_subscriber --interprocess 'platform: "demo"'
"""

from __future__ import annotations

import sys

from gateway.goby.dccl import units
from gateway.goby.portal import SingleThreadApplication, run_application
from gateway.goby.portal.timeutil import time_str
from translators.trail import groups
from translators.trail.protobuf.health_monitor_config_pb2 import HealthMonitor
from translators.trail.protobuf.health_status_pb2 import HealthStatus


class HealthSubscriber(SingleThreadApplication):
    """Prints each HealthStatus's timestamp as a date and its latency."""

    def __init__(self, cfg: HealthMonitor) -> None:
        super().__init__(cfg)
        self.interprocess().subscribe(groups.health_status, HealthStatus, self.on_health_status)

    def on_health_status(self, status: HealthStatus) -> None:
        timestamp = units.with_units(status, "timestamp")
        latency = units.now(self.context.clock) - timestamp
        print(f"Timestamp as date: {time_str(units.to_micro(timestamp))}", flush=True)
        print(f"Latency (microsec): {units.to_micro(latency)}", flush=True)


def main(argv: list[str] | None = None) -> int:
    return run_application(HealthSubscriber, HealthMonitor, argv, prog="health_subscriber")


if __name__ == "__main__":
    sys.exit(main())
