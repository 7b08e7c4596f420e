"""Record a running mission from inside the demo process: a MOOS client and a portal subscriber per vehicle.

The MOOS side gives the track (NAV_*), the helm (IVPHELM_STATE, VIEW_*) and what commands posted
(DEPLOY_STATE, POLYGON_UPDATES, with their posters); the portal side gives the frontseat interface's
state (``goby::middleware::frontseat::status``) and the command acknowledgements. All events are stamped
with one clock (sim seconds since the recorder started), so the two sides line up.
"""

from __future__ import annotations

import logging
import time
from collections import Counter
from typing import Any

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_pb2 import InterfaceState, InterfaceStatus
from gateway.goby.portal import SimpleThread
from gateway.moos import MoosClock, comms
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from launch.portal_thread import BackgroundPortalThread
from launch.record import MissionRecord

log = logging.getLogger(__name__)

NAV_VARS = ("NAV_X", "NAV_Y", "NAV_HEADING", "NAV_SPEED", "NAV_DEPTH")
EVENT_VARS = (
    "DEPLOY_STATE",
    "POLYGON_UPDATES",
    "IVPHELM_STATE",
    "VIEW_POLYGON",
    "VIEW_SEGLIST",
    "LOITER_MODE",
    "WPT_INDEX",
    "AUV_DEPLOY_STATE",
    "DEPLOY_DEPTH_UPDATES",
)
# Posted every helm iteration; only changes are worth keeping. (Command variables are kept every time:
# the same command twice is two commands.)
CHANGES_ONLY = frozenset({"IVPHELM_STATE", "VIEW_POLYGON", "VIEW_SEGLIST", "LOITER_MODE", "WPT_INDEX"})


class SimClock:
    """Sim seconds since construction: real elapsed time times the warp."""

    def __init__(self, warp: float) -> None:
        self.warp = warp
        self._start = time.monotonic()

    def now(self) -> float:
        return (time.monotonic() - self._start) * self.warp


class MoosRecorder:
    """A MOOS client registered for the mission's variables; ``poll()`` files new mail into the record.

    ``poll()`` runs on the caller's thread (the demo's main loop); the client's own I/O thread only
    queues mail, as the pymoos contract wants.
    """

    def __init__(self, record: MissionRecord, clock: SimClock, moos_port: int, name: str = "uUsvDemoRecorder",
                 variables: tuple[str, ...] | None = None):
        self.record = record
        self.variables = variables if variables is not None else (*NAV_VARS, *EVENT_VARS)
        self.clock = clock
        self.moos_port = moos_port
        self.name = name
        self.comms = comms(clock=MoosClock(clock.warp))
        self.comms.set_on_connect_callback(self._on_connect)
        self.mail_count = 0
        self.counts: Counter[str] = Counter()  # messages per variable (the fleet benchmark's NAV rate)
        self._last: dict[str, str] = {}

    def _on_connect(self) -> bool:
        for var in self.variables:
            self.comms.register(var, 0)
        return True

    def start(self) -> None:
        self.comms.run("127.0.0.1", self.moos_port, self.name)

    def connected(self) -> bool:
        return self.comms.is_connected()

    def poll(self) -> int:
        """File every message fetched since the last call; returns how many."""
        messages = self.comms.fetch()
        now = self.clock.now()
        for msg in messages:
            name = msg.key()
            self.counts[name] += 1
            if name in NAV_VARS and msg.is_double():
                self.record.add_nav(now, name, msg.double())
            elif name in EVENT_VARS:
                value = msg.string() if msg.is_string() else f"{msg.double():g}"
                if name in CHANGES_ONLY and self._last.get(name) == value:
                    continue
                self._last[name] = value
                self.record.add_event(now, "moos", name, value, msg.source())
        self.mail_count += len(messages)
        return len(messages)

    def close(self) -> None:
        self.comms.close(True)


class _PortalListener(SimpleThread):
    """Subscribes to the interface status and (if the USV command path is installed) its acknowledgements."""

    def __init__(self, cfg: GobyMOOSGatewayConfig, record: MissionRecord, clock: SimClock) -> None:
        super().__init__(cfg)
        self._record = record
        self._clock = clock
        self._last_state: int | None = None
        self.interprocess().subscribe(frontseat_groups.status, InterfaceStatus, self._on_status)
        try:
            from translators.usv import groups as usv_groups
            from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
        except ImportError:  # the command path is optional for recording
            return
        self.interprocess().subscribe(usv_groups.usv_command_ack, USVCommandAck, self._on_ack)

    def _on_status(self, status: InterfaceStatus) -> None:
        """Keep each change of the interface's state. Runs on the listener's thread."""
        if status.HasField("state") and status.state != self._last_state:
            self._last_state = status.state
            self._record.add_event(self._clock.now(), "interface", "interface_state", InterfaceState.Name(status.state))

    def _on_ack(self, ack: Any) -> None:
        stage = ack.DESCRIPTOR.fields_by_name["stage"].enum_type.values_by_number[ack.stage].name
        posts = ";".join(ack.moos_post)
        if stage.startswith("LINK_"):  # the satellite link's ack (or expiry), sim seconds
            posts = f"slot_wait={ack.slot_wait:.2f};link_latency={ack.link_latency:.2f}"
        self._record.add_event(self._clock.now(), "ack", stage, posts or ack.error, ack.responder)


class PortalRecorder(BackgroundPortalThread):
    """Runs the portal listener on its own thread (built there, as portal threads own their sockets)."""

    def __init__(self, record: MissionRecord, clock: SimClock, platform: str, ipc_base: str) -> None:
        super().__init__(f"{platform}-demo-portal", log, "portal recorder stopped")
        self._cfg = GobyMOOSGatewayConfig()
        self._cfg.app.name = "usv-demo-recorder"
        self._cfg.interprocess.platform = platform
        self._cfg.interprocess.socket_name = ipc_base
        self._cfg.interprocess.manager_timeout_seconds = 30  # a loaded machine's broker can be slow to answer
        self._record = record
        self._clock = clock

    def _build(self) -> SimpleThread:
        return _PortalListener(self._cfg, self._record, self._clock)
