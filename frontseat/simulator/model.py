"""The basic simulator's vehicle and mission logic, free of sockets and clocks (the server drives it).

One :meth:`Simulation.tick` is one iteration of Goby's simulator loop: the lines received since the last
tick are handled first (their replies come before that tick's NAV), then mission time advances, the
duration is checked, and the vehicle moves by ``dt = 1/FREQ`` simulated seconds.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field, replace

from frontseat.errors import SimulatorLineError
from frontseat.simulator import protocol
from frontseat.simulator.protocol import INT_MAX
from util.geodesy import UTMGeodesy

log = logging.getLogger(__name__)

MAX_FREQ = 10_000  # Hz; far beyond any real frontseat, and keeps the loop period sane
MAX_WARP = 10_000
MAX_TICK_RATE = 1_000
"""Most ticks per real second (FREQ x WARP): each tick handles lines, steps the model and writes NAV to every
client, so 10000 x 10000 would leave no time to serve them; the missions run 10 x 10-20."""


@dataclass(frozen=True)
class VehicleConfig:
    """Rate limits: acceleration (m/s²), heading rate (deg/s), dive rate (m/s)."""

    accel: float = 0.5
    hdg_rate: float = 45.0
    z_rate: float = 2.0


@dataclass(frozen=True)
class StartParams:
    """What a START line sets; every optional key falls back to its default on each START."""

    lat: float
    lon: float
    duration: int = 0  # seconds; 0 means no limit
    freq: int = 10  # control (and NAV) frequency, Hz
    warp: int = 1
    vehicle: VehicleConfig = field(default_factory=VehicleConfig)


@dataclass
class Kinematics:
    """Position x (east), y (north), z (up, m), speed v (m/s) and heading hdg (deg, not normalised)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    v: float = 0.0
    hdg: float = 0.0


def _approach(value: float, target: float, step: float) -> float:
    """Move ``value`` toward ``target`` by ``step``, landing on it when closer than ``step``."""
    if abs(value - target) > step:
        return value + (step if value < target else -step)
    return target


def step_dynamics(vehicle: Kinematics, desired: Kinematics, cfg: VehicleConfig, dt: float) -> None:
    """Advance ``vehicle`` one step toward ``desired`` (whose heading is unwrapped in place, as Goby does)."""
    vehicle.z = _approach(vehicle.z, desired.z, cfg.z_rate * dt)
    if vehicle.hdg - desired.hdg >= 180:
        desired.hdg += 360
    if vehicle.hdg - desired.hdg < -180:
        desired.hdg -= 360
    vehicle.hdg = _approach(vehicle.hdg, desired.hdg, cfg.hdg_rate * dt)
    vehicle.v = _approach(vehicle.v, desired.v, cfg.accel * dt)
    theta = math.radians(90 - vehicle.hdg)
    vehicle.x += vehicle.v * math.cos(theta) * dt
    vehicle.y += vehicle.v * math.sin(theta) * dt


def parse_start(fields: dict[str, str]) -> StartParams:
    """START fields -> parameters. Raises :class:`SimulatorLineError` naming the first bad field."""
    for name in ("LAT", "LON"):
        if name not in fields:
            raise SimulatorLineError(f"Invalid START: missing {name} field")
    lat, lon = protocol.as_double(fields["LAT"]), protocol.as_double(fields["LON"])
    if not (-90 <= lat <= 90 and -180 <= lon <= 180):
        raise SimulatorLineError(f"Invalid START: LAT/LON {fields['LAT']!r}/{fields['LON']!r} is not a position")

    def integer(name: str, default: int, low: int, high: int) -> int:
        if name not in fields:
            return default
        value = protocol.as_int(fields[name]) if protocol.is_int(fields[name]) else None
        if value is None or not low <= value <= high:
            raise SimulatorLineError(f"Invalid START: {name} {fields[name]!r} must be an integer in {low}..{high}")
        return value

    def real(name: str, default: float) -> float:
        if name not in fields:
            return default
        value = protocol.as_double(fields[name])
        if not (math.isfinite(value) and value >= 0):
            raise SimulatorLineError(f"Invalid START: {name} {fields[name]!r} must be a finite number >= 0")
        return value

    defaults = VehicleConfig()
    freq, warp = integer("FREQ", 10, 1, MAX_FREQ), integer("WARP", 1, 1, MAX_WARP)
    if freq * warp > MAX_TICK_RATE:
        raise SimulatorLineError(f"Invalid START: FREQ {freq} x WARP {warp} = {freq * warp} ticks per real second; "
                                 f"at most {MAX_TICK_RATE}")
    return StartParams(
        lat=lat,
        lon=lon,
        duration=integer("DURATION", 0, -INT_MAX, INT_MAX),
        freq=freq,
        warp=warp,
        vehicle=VehicleConfig(
            accel=real("ACCEL", defaults.accel),
            hdg_rate=real("HDG_RATE", defaults.hdg_rate),
            z_rate=real("Z_RATE", defaults.z_rate),
        ),
    )


# What a CMD may ask (the vehicle model has no other limits): heading in degrees either way round, speed
# forward only and below any real vessel's, depth from the surface to the deepest ocean.
COMMAND_RANGES = {"HEADING": (-360.0, 360.0), "SPEED": (0.0, 100.0), "DEPTH": (0.0, 11_000.0)}


def parse_command(fields: dict[str, str]) -> tuple[float, float, float]:
    """CMD fields -> (heading, speed, depth). Raises :class:`SimulatorLineError` for a missing, non-numeric,
    non-finite or out-of-range value (see ``COMMAND_RANGES``)."""
    values = []
    for name, (low, high) in COMMAND_RANGES.items():
        if name not in fields:
            raise SimulatorLineError(f"Invalid CMD: missing {name} field")
        value = protocol.as_double(fields[name])
        if not math.isfinite(value):
            raise SimulatorLineError(f"Invalid CMD: {name} {fields[name]!r} is not a finite number")
        if not low <= value <= high:
            raise SimulatorLineError(f"Invalid CMD: {name} {fields[name]!r} is outside {low:g}..{high:g}")
        values.append(value)
    return values[0], values[1], values[2]


class Simulation:
    """The simulator's whole state; not thread-safe (the server calls it from its one thread)."""

    def __init__(self) -> None:
        self.params: StartParams | None = None  # None: not started (no datum)
        self.vehicle = Kinematics()
        self.desired = Kinematics()
        self.time_in_mission = 0
        self._geodesy: UTMGeodesy | None = None
        self._freq, self._warp = 10, 1  # kept after DURATION expiry, as Goby keeps its globals

    @property
    def started(self) -> bool:
        return self.params is not None

    @property
    def period(self) -> float:
        """Real seconds between ticks: ``1 / (FREQ * WARP)``."""
        return 1.0 / (self._freq * self._warp)

    def handle_line(self, line: str) -> list[str]:
        """Act on one received line (without its ``\\r\\n``); return the replies to send to every client.

        Never raises: a line that cannot be acted on is logged with its cause. A CMD that cannot be applied
        is answered ``CMD,RESULT:ERROR``, an invalid START ``START,RESULT:ERROR`` (so the driver's log says why
        no ``CTRL,STATE:PAYLOAD`` comes); other bad lines get no reply (there is no reply type for them).
        """
        line = line.strip()
        key = protocol.line_key(line)
        try:
            try:
                _, fields = protocol.parse_line(line)
            except SimulatorLineError as exc:
                raise SimulatorLineError(f"Invalid line: {exc}") from exc
            if key == "CMD":
                if not self.started:
                    raise SimulatorLineError("CMD before START (or after DURATION ran out)")
                self._apply_command(fields)
                return [protocol.CMD_OK]
            if key == "START":
                self._apply_start(parse_start(fields))
                log.info("Initialized using: %s", line)
                return [protocol.CTRL_PAYLOAD]
            raise SimulatorLineError(f"Unknown key {key!r}")
        except SimulatorLineError as exc:
            log.warning("rejected line from payload %r: %s", _shorten(line), exc)
            return {"CMD": [protocol.CMD_ERROR], "START": [protocol.START_ERROR]}.get(key, [])

    def tick(self) -> list[str]:
        """One iteration after the lines are handled: returns ``CTRL,STATE:IDLE`` or a NAV line, or nothing."""
        self.time_in_mission += 1
        params = self.params
        if params is None:
            return []
        if params.duration and self.time_in_mission // params.freq > params.duration:
            self.params = None
            log.info("DURATION %d s ran out; going idle", params.duration)
            return [protocol.CTRL_IDLE]
        step_dynamics(self.vehicle, self.desired, params.vehicle, 1.0 / params.freq)
        assert self._geodesy is not None
        lat, lon = self._geodesy.to_geo(self.vehicle.x, self.vehicle.y)
        return [protocol.nav_line(lat, lon, -self.vehicle.z, self.vehicle.hdg, self.vehicle.v)]

    def _apply_start(self, params: StartParams) -> None:
        self._geodesy = UTMGeodesy(params.lat, params.lon)
        self.params = replace(params)
        self._freq, self._warp = params.freq, params.warp
        self.time_in_mission = 0

    def _apply_command(self, fields: dict[str, str]) -> None:
        heading, speed, depth = parse_command(fields)
        self.desired.z, self.desired.v, self.desired.hdg = -depth, speed, heading


def _shorten(line: str, limit: int = 200) -> str:
    return line if len(line) <= limit else f"{line[:limit]}... ({len(line)} characters)"
