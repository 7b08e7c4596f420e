"""goby-helm-example: the goby3-course day-3 homework helm, on our Goby-style portal, with no MOOS at all.

Drives a rough triangle through the frontseat interface: east at ``speed`` for ``east_duration`` s, south for
``south_duration`` s, then northwest until the vehicle stops closing on where it started, then speed 0 and, once,
an ``AUVCommand`` RECOVER on intervehicle ``goby3_course::auv_command`` (homework 3's second part: the AUVs
surface and station-keep).
Every loop (1 Hz of warped time, as the course's app) it publishes ``HELM_DRIVE`` on ``helm_state`` and a
``DesiredCourse`` on ``desired_course``; it reads ``node_status`` (the first one is the start).

Run: ``python -m behaviors.apps.goby_helm_example CONFIG`` (Goby text-format config, ``goby3_course.config.Helm``).
"""

from __future__ import annotations

import logging
import math
from collections import deque
from dataclasses import dataclass, field
from enum import Enum

from behaviors.protobuf.goby_helm_example_config_pb2 import Helm as HelmConfig
from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import DesiredCourse, NodeStatus
from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, HelmStateReport
from gateway.goby.portal import SingleThreadApplication, run_application
from translators.trail import groups as trail_groups
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand

log = logging.getLogger(__name__)


class Leg(Enum):
    EAST = 90.0
    SOUTH = 180.0
    NORTHWEST = 315.0
    RECOVER = 0.0


@dataclass
class TriangleLegs:
    """The leg logic, free of I/O: :meth:`update` with the time and the latest position gives the command."""

    speed: float
    east_duration: float
    south_duration: float
    window: int = 10
    leg: Leg = Leg.EAST
    leg_start: float | None = None
    start: tuple[float, float] | None = None
    _ranges: deque[float] = field(default_factory=deque)
    _closest: float | None = None

    def update(self, now: float, position: tuple[float, float] | None) -> tuple[float, float]:
        """Advance the leg if due; return (heading in compass degrees, speed in m/s)."""
        if self.leg_start is None:
            self.leg_start = now
        if self.start is None and position is not None:
            self.start = position
        if self.leg is Leg.EAST and now > self.leg_start + self.east_duration:
            self._switch(Leg.SOUTH, now)
        elif self.leg is Leg.SOUTH and now > self.leg_start + self.south_duration:
            self._switch(Leg.NORTHWEST, now)
        elif self.leg is Leg.NORTHWEST and position is not None and self.start is not None:
            self._check_closing(position)
        if self.leg is Leg.RECOVER:
            return 0.0, 0.0
        return self.leg.value, self.speed

    def _switch(self, leg: Leg, now: float) -> None:
        log.info("switched to the %s leg", leg.name)
        self.leg, self.leg_start = leg, now

    def _check_closing(self, position: tuple[float, float]) -> None:
        """Average the range to the start over ``window`` samples; stop once the average stops falling."""
        assert self.start is not None
        rng = math.hypot(position[0] - self.start[0], position[1] - self.start[1])
        if not self._ranges:
            self._closest = rng
        self._ranges.append(rng)
        if len(self._ranges) > self.window:
            self._ranges.popleft()
        if len(self._ranges) < self.window:
            return
        average = sum(self._ranges) / len(self._ranges)
        if self._closest is not None and average < self._closest:
            self._closest = average
        else:
            log.info("no longer closing on the start (average range %.1f m): stopping", average)
            self.leg = Leg.RECOVER


class GobyHelmExample(SingleThreadApplication):
    """Publishes helm_state and desired_course at 1 Hz (warped); subscribes node_status."""

    def __init__(self, cfg: HelmConfig) -> None:
        super().__init__(cfg, loop_frequency_hz=1.0)
        self.legs = TriangleLegs(cfg.speed, cfg.east_duration, cfg.south_duration, max(1, cfg.closing_window))
        self._position: tuple[float, float] | None = None
        self._recover_sent = False
        self.interprocess().subscribe(groups.node_status, NodeStatus, self._on_node_status)

    def _on_node_status(self, status: NodeStatus) -> None:
        """Keep the latest local position. Runs on the application's thread."""
        if status.HasField("local_fix") and status.local_fix.HasField("x") and status.local_fix.HasField("y"):
            self._position = (status.local_fix.x, status.local_fix.y)

    def loop(self) -> None:
        now = self.context.clock.now()
        heading, speed = self.legs.update(now, self._position)
        if self.legs.leg is Leg.RECOVER and not self._recover_sent:
            self._send_auv_command(now)
        self.interprocess().publish(groups.helm_state, HelmStateReport(state=HELM_DRIVE))
        self.interprocess().publish(groups.desired_course, DesiredCourse(time=now, heading=heading, speed=speed))
        log.debug("leg %s: heading %.0f speed %.1f", self.legs.leg.name, heading, speed)

    def _send_auv_command(self, now: float) -> None:
        """AUVCommand RECOVER, once, with the default publisher (the AUVs' subscriptions ask for the ack)."""
        self._recover_sent = True
        log.info("sending AUVCommand RECOVER on %s", trail_groups.auv_command)
        self.intervehicle().publish(trail_groups.auv_command, AUVCommand(time=now, desired_state=AUVCommand.RECOVER))


def main(argv: list[str] | None = None) -> int:
    return run_application(GobyHelmExample, HelmConfig, argv, prog="goby-helm-example")


if __name__ == "__main__":
    raise SystemExit(main())
