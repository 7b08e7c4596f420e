"""The demo's operator: USV commands from the topside over the satellite link, and RECOVER from the USV.

Two portal threads in the demo process, one on the topside's broker and one on the USV's, each running a
``SimpleThread`` on its own Python thread (portal threads own their sockets). The topside one publishes each
scheduled ``USVCommand`` on intervehicle ``usv_command``/0 with ack and expire callbacks, as the course's
liaison Commander (or ``goby3_course_command_test``) does; the USV one publishes ``AUVCommand`` RECOVER on
intervehicle ``auv_command``/0 (what homework 3's helm does at the end of its triangle, ``send_auv_command()``),
for runs whose USV helm is the MOOS helm. Publishing from here rather than starting a tool per command keeps the
commands on schedule at high warp. Every send, ack and expiry is filed as an event (source ``command``).

Schedule: comma-separated ``T:polygon:SIDES:RADIUS``, ``T:waypoints`` (USV commands, checked against the DCCL
bounds first, as usv-command does) and ``T:recover``; T in sim seconds after every vehicle is under command.
"""

from __future__ import annotations

import functools
import logging
import queue
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from gateway.goby.intervehicle import Publisher
from gateway.goby.portal import SimpleThread
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from launch.errors import MissionConfigError
from launch.portal_thread import BackgroundPortalThread
from launch.record import MissionRecord
from launch.recorder import SimClock
from launch.usv.shore import NO_SCHEDULE, ScheduledCommand, parse_schedule
from translators.trail import groups
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand, USVCommand
from translators.usv.validation import check_dccl_bounds

log = logging.getLogger(__name__)

RECOVER = "recover"
SCHEDULE_HELP = "T:polygon:SIDES:RADIUS, T:waypoints, T:recover (comma-separated, T in sim seconds) or none"


@dataclass(frozen=True)
class PlannedCommand:
    """One planned command: when (sim seconds after t0) and what."""

    at: float
    usv: ScheduledCommand | None  # None: RECOVER

    def describe(self) -> str:
        return self.usv.describe() if self.usv is not None else RECOVER


def parse_trail_schedule(text: str) -> list[PlannedCommand]:
    """USV commands as the USV mission's shore schedule, plus ``T:recover``; MissionConfigError names a bad entry."""
    if text.strip().lower() == NO_SCHEDULE:
        return []
    plan: list[PlannedCommand] = []
    for item in (part.strip() for part in text.split(",")):
        when, _, what = item.partition(":")
        if what.strip().lower() == RECOVER:
            try:
                at = float(when)
            except ValueError:
                raise MissionConfigError(f"bad schedule entry {item!r}: time must be a number >= 0") from None
            if at < 0:
                raise MissionConfigError(f"bad schedule entry {item!r}: time must be a number >= 0")
            plan.append(PlannedCommand(at, None))
        else:
            plan.extend(PlannedCommand(c.at, c) for c in parse_schedule(item))
    return sorted(plan, key=lambda c: c.at)


class _Worker(SimpleThread):
    """Runs queued jobs on the portal thread (publishing must happen on the thread that owns the portal)."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, jobs: queue.Queue[Callable[[SimpleThread], None]]) -> None:
        super().__init__(cfg, loop_frequency_hz=10.0)
        self._jobs = jobs

    def loop(self) -> None:
        while True:
            try:
                job = self._jobs.get_nowait()
            except queue.Empty:
                return
            job(self)


class PortalWorker(BackgroundPortalThread):
    """A ``_Worker`` on its own thread, attached to one platform's broker; ``submit(job)`` runs ``job(thread)`` there."""

    def __init__(self, platform: str, ipc_base: str, warp: int) -> None:
        super().__init__(f"{platform}-demo-operator", log, "operator thread stopped")
        self._cfg = GobyMOOSGatewayConfig()
        self._cfg.app.name = f"trail-demo-{platform}"
        self._cfg.app.simulation.time.use_sim_time = True
        self._cfg.app.simulation.time.warp_factor = warp
        self._cfg.app.simulation.time.reference_microtime = 0
        self._cfg.interprocess.platform = platform
        self._cfg.interprocess.socket_name = ipc_base
        self._cfg.interprocess.manager_timeout_seconds = 30
        self._jobs: queue.Queue[Callable[[SimpleThread], None]] = queue.Queue()

    def _build(self) -> SimpleThread:
        return _Worker(self._cfg, self._jobs)

    def submit(self, job: Callable[[SimpleThread], None]) -> None:
        self._jobs.put(job)


class Operator:
    """Sends the planned commands when their time comes (``poll()`` from the mission loop), files what happened."""

    def __init__(self, plan: list[PlannedCommand], record: MissionRecord, clock: SimClock,
                 topside: PortalWorker, usv: PortalWorker | None) -> None:
        self.plan = list(plan)
        self.record = record
        self.clock = clock
        self.topside = topside
        self.usv = usv
        self.t0: float | None = None

    def start(self, t0: float) -> None:
        self.t0 = t0

    def poll(self) -> None:
        while self.t0 is not None and self.plan and self.plan[0].at <= self.clock.now() - self.t0:
            planned = self.plan.pop(0)
            if planned.usv is not None:
                self.topside.submit(functools.partial(self._send_usv_command, planned=planned))
            elif self.usv is not None:
                self.usv.submit(self._send_recover)

    def _event(self, name: str, value: str, origin: str) -> None:
        self.record.add_event(self.clock.now(), "command", name, value, origin)

    def _send_usv_command(self, thread: SimpleThread, planned: PlannedCommand) -> None:
        assert planned.usv is not None
        message: USVCommand = check_dccl_bounds(planned.usv.to_message(thread.context.clock.now()),
                                                codec=thread.context.dccl)
        label = planned.describe()
        thread.intervehicle().publish(groups.usv_command, message, publisher=Publisher(
            on_ack=lambda _msg, ack: self._event("ack", label, _ack_origin(ack)),
            on_expire=lambda _msg, exp: self._event("expire", label, _expire_reason(exp))))
        self._event("sent", label, "topside")
        log.info("sent %s over the satellite link", label)

    def _send_recover(self, thread: SimpleThread) -> None:
        message = AUVCommand(time=thread.context.clock.now(), desired_state=AUVCommand.RECOVER)
        thread.intervehicle().publish(groups.auv_command, message, publisher=Publisher(
            on_ack=lambda _msg, ack: self._event("ack", RECOVER, _ack_origin(ack)),
            on_expire=lambda _msg, exp: self._event("expire", RECOVER, _expire_reason(exp))))
        self._event("sent", RECOVER, "usv")
        log.info("sent RECOVER over the acoustic link")


def _expire_reason(expire: Any) -> str:
    try:
        return str(expire.DESCRIPTOR.fields_by_name["reason"].enum_type.values_by_number[expire.reason].name)
    except (KeyError, AttributeError):
        return "expired"


def _ack_origin(ack: Any) -> str:
    """``modem N`` (who acked) and the link's latency in seconds, as AckData gives them."""
    return f"modem {ack.header.src}, latency {ack.latency / 1e6:.1f} s"
