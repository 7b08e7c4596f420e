"""Driver for the basic frontseat simulator (Goby's ``basic_simulator`` plugin), over its TCP line protocol.

Entry point ``frontseat_driver_load(cfg)``. Config: the ``basic_simulator_config`` extension (1001) of
``Config``, exactly Goby's; importing this module registers it, which is why driver protos are loaded per driver.
Our own settings (data timeout, reconnect interval) are the project extension ``basic_simulator_tuning`` (1900),
kept out of Goby's message so that Goby-only config files work with both drivers.

Unlike Goby's driver, this one notices a lost link (the frontseat becomes NOT_CONNECTED) and, on every new
connection, sends START again, so a restarted simulator brings the interface from FS_ERROR back to
STANDBY and on to COMMAND.

The link is a :class:`~frontseat.line_client.LineConnection` on the host's reactor: every line is handled when it
arrives (a NAV fix is emitted as data at once); :meth:`BasicSimulatorDriver.loop` only checks the data timeout.
"""

from __future__ import annotations

import logging
import math

from frontseat.driver import Clock, FrontSeatDriver
from frontseat.errors import DriverConfigError, SimulatorLineError
from frontseat.line_client import LineConnection
from frontseat.protobuf import basic_simulator_config_pb2 as sim_pb
from frontseat.protobuf import basic_simulator_tuning_pb2 as tuning_pb
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_pb2 as fs_pb
from frontseat.simulator import protocol
from util.descriptors import initialization_errors
from util.reactor import Reactor

log = logging.getLogger(__name__)

CONFIG_EXTENSION = sim_pb.basic_simulator_config
EXTENSION_NAME = "goby.middleware.frontseat.protobuf.basic_simulator_config"
TUNING_EXTENSION = tuning_pb.basic_simulator_tuning

_CTRL_STATES: dict[str, fs_pb.FrontSeatState.ValueType] = {
    "PAYLOAD": fs_pb.FRONTSEAT_ACCEPTING_COMMANDS,
    "AUV": fs_pb.FRONTSEAT_IN_CONTROL,
}


def frontseat_driver_load(cfg: config_pb.Config) -> FrontSeatDriver:
    """The driver factory the interface looks up (Goby's ``frontseat_driver_load``)."""
    return BasicSimulatorDriver(cfg)


class BasicSimulatorDriver(FrontSeatDriver):
    """Talks START/CMD to the simulator and turns its CTRL/NAV/CMD lines into states, data and responses."""

    def __init__(self, cfg: config_pb.Config, *, clock: Clock | None = None, reactor: Reactor | None = None) -> None:
        super().__init__(cfg, clock=clock, reactor=reactor)
        if not cfg.HasExtension(CONFIG_EXTENSION):
            raise DriverConfigError(f"frontseat_cfg has no [{EXTENSION_NAME}] block; the basic simulator driver needs one")
        self.sim_cfg = sim_pb.BasicSimulatorFrontSeatConfig()
        self.sim_cfg.CopyFrom(cfg.Extensions[CONFIG_EXTENSION])
        missing = initialization_errors(self.sim_cfg)
        if missing:
            raise DriverConfigError(f"[{EXTENSION_NAME}] is missing required field(s): {', '.join(missing)}")
        self.tuning = tuning_pb.BasicSimulatorTuning()
        self.tuning.CopyFrom(cfg.Extensions[TUNING_EXTENSION])
        self._fs_state: fs_pb.FrontSeatState.ValueType = fs_pb.FRONTSEAT_NOT_CONNECTED
        self._providing_data = False
        self._last_data_time = -math.inf
        self._last_request = fs_pb.CommandRequest()
        self._link = LineConnection(
            self.reactor,
            self.sim_cfg.tcp_address,
            self.sim_cfg.tcp_port,
            on_line=self._on_line,
            on_connect=self._on_connect,
            on_disconnect=self._on_disconnect,
            reconnect_interval=self.tuning.reconnect_interval,
            name="frontseat-basic-sim-link",
        ).start()

    def close(self) -> None:
        """Disconnect from the simulator and stop reconnecting. Idempotent."""
        self._link.close()

    # ----- the six driver methods -------------------------------------------------------------------------
    def frontseat_state(self) -> fs_pb.FrontSeatState.ValueType:
        return self._fs_state

    def frontseat_providing_data(self) -> bool:
        return self._providing_data

    def send_command_to_frontseat(self, command: fs_pb.CommandRequest) -> None:
        if not command.HasField("desired_course"):
            log.info("unhandled command (only desired_course is supported): %s", command)
            return
        course = command.desired_course
        self._write(protocol.command_line(course.heading, course.speed, course.depth))
        self._last_request.CopyFrom(command)

    def send_data_to_frontseat(self, data: fs_pb.InterfaceData) -> None:
        log.debug("the basic simulator takes no data; ignoring InterfaceData with %d field(s)", len(data.ListFields()))

    def send_raw_to_frontseat(self, raw: fs_pb.Raw) -> None:
        text = raw.raw.decode("utf-8", errors="replace")
        self._write(text[:-2] if text.endswith("\r\n") else text)

    def loop(self) -> None:
        """The tick: only the data timeout (lines are handled on arrival, by the link's callbacks)."""
        if self.now() > self._last_data_time + self.tuning.data_timeout:
            if self._providing_data:
                log.warning("no NAV from the simulator for %.1f s", self.tuning.data_timeout)
            self._providing_data = False

    # ----- the link's callbacks (the host's main thread) ----------------------------------------------------
    def _on_connect(self) -> None:
        log.info("connected to the basic vehicle simulator at %s", self._link.address)
        self._fs_state = fs_pb.FRONTSEAT_IDLE
        self._write(self._start_line())

    def _on_disconnect(self) -> None:
        log.warning("connection to the frontseat at %s lost", self._link.address)
        self._fs_state = fs_pb.FRONTSEAT_NOT_CONNECTED
        self._providing_data = False

    def _on_line(self, line: str) -> None:
        self._process_line(line.strip())

    # ----- internals --------------------------------------------------------------------------------------
    def _start_line(self) -> str:
        start = self.sim_cfg.start
        return protocol.start_line(
            lat=start.lat,
            lon=start.lon,
            duration=start.duration,
            freq=start.control_freq,
            accel=start.vehicle.accel,
            hdg_rate=start.vehicle.hdg_rate,
            z_rate=start.vehicle.z_rate,
            warp=self.cfg().sim_warp_factor,
        )

    def _write(self, line: str) -> None:
        if self._link.write_line(line):
            self.signal_raw_to_frontseat.emit(fs_pb.Raw(raw=line.encode()))
        else:
            log.warning("could not send to the frontseat at %s (%s); dropped %r", self._link.address,
                        "not connected" if not self._link.connected else "over the output bound", line)

    def _process_line(self, line: str) -> None:
        self.signal_raw_from_frontseat.emit(fs_pb.Raw(raw=line.encode()))
        try:
            key, fields = protocol.parse_line(line)
        except SimulatorLineError as exc:
            log.warning("failed to handle message from the frontseat %r: %s", line, exc)
            return
        if key == "CTRL":
            self._fs_state = _CTRL_STATES.get(fields.get("STATE", ""), fs_pb.FRONTSEAT_IDLE)
        elif key == "NAV":
            self._on_nav(fields)
            log.debug("got NAV update: %s", line)
        elif key == "CMD":
            if self._last_request.response_requested:
                self.signal_command_response.emit(
                    fs_pb.CommandResponse(
                        request_successful=fields.get("RESULT") == "OK",
                        request_id=self._last_request.request_id,
                    )
                )
        else:
            log.info("unknown message from the frontseat: %s", line)

    def _on_nav(self, fields: dict[str, str]) -> None:
        data = fs_pb.InterfaceData()
        status = data.node_status
        status.pose.heading = protocol.as_double(fields.get("HEADING"))
        status.speed.over_ground = protocol.as_double(fields.get("SPEED"))
        status.global_fix.depth = protocol.as_double(fields.get("DEPTH"))
        status.global_fix.lon = protocol.as_double(fields.get("LON"))
        status.global_fix.lat = protocol.as_double(fields.get("LAT"))
        self.compute_missing(status)
        self.signal_data_from_frontseat.emit(data)
        self._providing_data = True
        self._last_data_time = self.now()
