"""``python -m launch.usv.shore CONFIG [--schedule ...]``: the shore operator, sending USV commands at set sim times.

Sim time starts when the vehicle is first under helm command (the frontseat interface reports
INTERFACE_COMMAND), so the plan does not depend on how long the processes took to start. Each command is
published the way ``usv-command`` publishes it (a ``goby3_course.dccl.USVCommand``, checked against its DCCL
bounds first): with ``intervehicle: true`` on intervehicle over the topside broker's satellite link, with an ack
whose slot wait and ack time are printed and published as a USVCommandAck (LINK_ACKED / LINK_EXPIRED) on this
broker; otherwise on the shore group of a shared broker. Every acknowledgement is printed to this script's log. Publishing from
this process, rather than starting ``usv-command`` each time, keeps the commands on schedule: a Python
process start costs a second or more, which is tens of simulated seconds at high warp. The script stays up
until stopped.

Schedule format: comma-separated ``T:waypoints`` or ``T:polygon:SIDES:RADIUS`` entries, T in sim seconds;
``none`` for no commands at all (the operator then sends every command with ``usv-command``).
"""

from __future__ import annotations

import argparse
import bisect
import logging
import math
import os
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

from google.protobuf import text_format

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_pb2 import INTERFACE_COMMAND, InterfaceStatus
from gateway.goby.intervehicle import ExpireData
from gateway.goby.portal import SimpleThread, SingleThreadApplication, run_application
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from launch.errors import MissionConfigError
from launch.usv.settings import DEFAULT_SCHEDULE
from translators.apps.usv_command import describe_ack
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from translators.usv.protobuf.usv_config_pb2 import CommandTool
from translators.usv.satellite import SatelliteCommander
from translators.usv.validation import DcclBoundsError, check_dccl_bounds
from util.cli import HelpFormatter

log = logging.getLogger(__name__)
PROG = "usv-shore"


@dataclass(frozen=True)
class ScheduledCommand:
    """One planned command: when (sim seconds after COMMAND) and the usv-command arguments."""

    at: float
    args: tuple[str, ...]

    def describe(self) -> str:
        return " ".join(self.args)

    def to_message(self, now: float) -> USVCommand:
        """The USVCommand, stamped ``now`` (the stamp also identifies its acknowledgements)."""
        command = USVCommand(time=now)
        if self.args[0] == "polygon":
            command.desired_state = USVCommand.POLYGON
            command.polygon_sides = int(self.args[2])
            command.polygon_radius = int(self.args[4])
        else:
            command.desired_state = USVCommand.WAYPOINTS
        return command


NO_SCHEDULE = "none"
#: For this long after the plan clock starts (sim s), a command the satellite link expires for want of a subscriber
#: is sent again every ``RESEND_S``: at a high warp the vehicle reaches COMMAND before its intervehicle subscription
#: has crossed the link, and Goby expires a publication with no known subscriber at once (EXPIRED_NO_SUBSCRIBERS).
NO_SUBSCRIBER_RETRY_S = 120.0
NO_SUBSCRIBERS = ExpireData.ExpireReason.Name(ExpireData.EXPIRED_NO_SUBSCRIBERS)  # as SatelliteCommander reports it
RESEND_S = 5.0
SCHEDULE_HELP = f"T:waypoints / T:polygon:SIDES:RADIUS, comma-separated, T in sim seconds; {NO_SCHEDULE} for no commands"


def parse_schedule(text: str) -> list[ScheduledCommand]:
    """Parse ``0:polygon:6:200,500:waypoints`` (or ``none``: no commands); MissionConfigError names the bad entry.

    Every command is also checked against the USVCommand's DCCL bounds, so a plan that could not be sent
    is refused before anything starts.
    """
    if text.strip().lower() == NO_SCHEDULE:
        return []
    if not text.strip():
        raise MissionConfigError(f"empty schedule {text!r}: give {SCHEDULE_HELP}")
    plan = []
    for item in (part.strip() for part in text.split(",")):
        if not item:
            raise MissionConfigError(f"empty entry in schedule {text!r} (two commas, or one at an end)")
        fields = item.split(":")
        try:
            at = float(fields[0])
            kind = fields[1].lower()
            if kind == "waypoints" and len(fields) == 2:
                args: tuple[str, ...] = ("waypoints",)
            elif kind == "polygon" and len(fields) == 4:
                args = ("polygon", "--sides", str(int(fields[2])), "--radius", str(int(fields[3])))
            else:
                raise ValueError(item)
        except (ValueError, IndexError):
            raise MissionConfigError(
                f"bad schedule entry {item!r}: use T:waypoints or T:polygon:SIDES:RADIUS (T in sim seconds)"
            ) from None
        if not math.isfinite(at) or at < 0:
            raise MissionConfigError(f"bad schedule entry {item!r}: time must be a number >= 0")
        command = ScheduledCommand(at, args)
        try:
            check_dccl_bounds(command.to_message(0.0))
        except DcclBoundsError as error:
            raise MissionConfigError(f"bad schedule entry {item!r}: {error}") from None
        plan.append(command)
    return sorted(plan, key=lambda c: c.at)


class VehicleWatcher(SimpleThread):
    """Watches the vehicle's frontseat status on the vehicle's own broker, for a shore on another broker.

    A simulation convenience: the course's topside sees the USV only through the satellite link, but the plan's
    clock starts at INTERFACE_COMMAND. Runs on its own Python thread with its own process context;
    ``on_status`` is called on that thread.
    """

    def __init__(self, cfg: CommandTool, on_status: Callable[[InterfaceStatus], None]) -> None:
        super().__init__(cfg)
        self.interprocess().subscribe(frontseat_groups.status, InterfaceStatus, on_status)


class ShoreOperator(SingleThreadApplication):
    """Waits for INTERFACE_COMMAND, then publishes each planned command when its sim time comes."""

    def __init__(self, cfg: CommandTool, plan: list[ScheduledCommand],
                 vehicle_interprocess: InterProcessPortalConfig | None = None) -> None:
        super().__init__(cfg, loop_frequency_hz=2.0)
        self._plan = list(plan)
        self._warp = max(1, cfg.app.simulation.time.warp_factor) if cfg.app.simulation.time.use_sim_time else 1
        self._t0: float | None = None
        self._sent: dict[float, ScheduledCommand] = {}
        self._watcher: VehicleWatcher | None = None
        self._watcher_thread: threading.Thread | None = None
        self.interprocess().subscribe(frontseat_groups.status, InterfaceStatus, self._on_status)
        if vehicle_interprocess is not None:
            self._watch(cfg, vehicle_interprocess)
        self.interprocess().subscribe(usv_groups.usv_command_ack, USVCommandAck, self._on_ack)
        # intervehicle: the link's ack or expiry is published here too, so recorders on this broker see it
        self._satellite = SatelliteCommander(self, self._publish_link_ack) if cfg.intervehicle else None
        if plan:
            print(f"shore: {len(plan)} commands planned: "
                  + "; ".join(f"t={c.at:g} s {c.describe()}" for c in plan), flush=True)
        else:
            print("shore: no commands planned (schedule none); send them with usv-command", flush=True)

    def _watch(self, cfg: CommandTool, vehicle_interprocess: InterProcessPortalConfig) -> None:
        watcher_cfg = CommandTool()
        watcher_cfg.CopyFrom(cfg)
        watcher_cfg.interprocess.CopyFrom(vehicle_interprocess)
        watcher_cfg.app.name = f"{cfg.app.name or PROG}-watcher"
        started = threading.Event()

        def target() -> None:
            try:
                self._watcher = VehicleWatcher(watcher_cfg, lambda s: self.call_soon(lambda: self._on_status(s)))
            except Exception as exc:  # noqa: BLE001 - reported here; the plan then never starts
                log.error("cannot watch the vehicle's broker (%s): %s",
                          text_format.MessageToString(vehicle_interprocess, as_one_line=True), exc)
                return
            finally:
                started.set()
            try:
                self._watcher.run()
            finally:
                self._watcher.close()

        self._watcher_thread = threading.Thread(target=target, name="VehicleWatcher")
        self._watcher_thread.start()
        started.wait()

    def finalize(self) -> None:
        if self._watcher is not None:
            self._watcher.quit()
        if self._watcher_thread is not None:
            self._watcher_thread.join(10)

    def _publish_link_ack(self, ack: USVCommandAck) -> None:
        """The link's ack or expiry of one of our commands, for this broker (our own subscription prints it)."""
        self.interprocess().publish(usv_groups.usv_command_ack, ack)

    def _sim_elapsed(self) -> float:
        return 0.0 if self._t0 is None else (time.monotonic() - self._t0) * self._warp

    def _on_status(self, status: InterfaceStatus) -> None:
        """Start the plan's clock at the first INTERFACE_COMMAND. Runs on the main thread."""
        if self._t0 is None and status.state == INTERFACE_COMMAND:
            self._t0 = time.monotonic()
            print("shore: vehicle is under helm command; plan clock started", flush=True)

    def _on_ack(self, ack: USVCommandAck) -> None:
        """Print acknowledgements of our commands. Runs on the main thread."""
        command = self._sent.get(ack.command_time) if ack.HasField("command_time") else None
        if command is None:
            return
        now = self._sim_elapsed()
        if (ack.stage == USVCommandAck.LINK_EXPIRED and ack.error == NO_SUBSCRIBERS
                and now < NO_SUBSCRIBER_RETRY_S):
            again = replace(command, at=now + RESEND_S)
            bisect.insort(self._plan, again, key=lambda c: c.at)
            print(f"shore: t={now:.0f} s {command.describe()}: no subscriber on the satellite link yet (the USV's "
                  f"subscription has not crossed it); sending again at t={again.at:.0f} s", flush=True)
            return
        print(f"shore: t={now:.0f} s {command.describe()}: {describe_ack(ack)}", flush=True)
        if ack.stage in (USVCommandAck.REFUSED, USVCommandAck.LINK_EXPIRED):
            log.error("command %s not carried out: %s", command.describe(), describe_ack(ack))

    def loop(self) -> None:
        """Publish every command whose time has come. Runs on the main thread at 2 Hz (times warp)."""
        if self._satellite is not None:
            self._satellite.service()
        while self._t0 is not None and self._plan and self._plan[0].at <= self._sim_elapsed():
            planned: ScheduledCommand = self._plan.pop(0)
            try:
                message = check_dccl_bounds(planned.to_message(self.context.clock.now()), codec=self.context.dccl)
            except DcclBoundsError as error:
                log.error("not sending %s: %s", planned.describe(), error)
                continue
            self._sent[message.time] = planned
            if self._satellite is not None:
                self._satellite.send(message)
            else:
                self.interprocess().publish(usv_groups.shore_usv_command, message)
            print(f"shore: t={self._sim_elapsed():.0f} s sent {planned.describe()}: "
                  f"{text_format.MessageToString(message, as_one_line=True)}", flush=True)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog=PROG, description=__doc__.split("\n\n")[0])
    # An empty USV_SHORE_SCHEDULE counts as unset (as every USV_* variable does): no commands is spelled "none".
    parser.add_argument("--schedule", default=os.environ.get("USV_SHORE_SCHEDULE") or DEFAULT_SCHEDULE,
                        help=f"{SCHEDULE_HELP} (default $USV_SHORE_SCHEDULE or {DEFAULT_SCHEDULE})")
    parser.add_argument("--vehicle-interprocess", metavar="TEXT",
                        help="the vehicle broker's interprocess block (text format), when this shore runs on its own "
                             "broker: the plan's clock starts at the vehicle's INTERFACE_COMMAND seen there")
    args, goby_argv = parser.parse_known_args(argv)
    try:
        plan = parse_schedule(args.schedule)
        vehicle = None
        if args.vehicle_interprocess:
            vehicle = text_format.Parse(args.vehicle_interprocess, InterProcessPortalConfig())
    except (MissionConfigError, text_format.ParseError) as exc:
        print(f"{PROG}: {exc}", file=sys.stderr)
        return 2
    return run_application(lambda cfg: ShoreOperator(cfg, plan, vehicle), CommandTool, goby_argv, prog=PROG)


if __name__ == "__main__":
    sys.exit(main())
