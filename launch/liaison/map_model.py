"""The live map's state: vehicles from NodeStatus (position, heading, trail), the mission's overlays, and the
vehicle's last health (the course's HealthStatus, as topside-manager publishes it from the satellite link).

Threads: :meth:`MapModel.ingest_node_status` and :meth:`ingest_command` run on the portal thread and only keep the
newest payload (under a lock held for microseconds); :meth:`tick` decodes them on the web thread, once per update
period, so a fast node_status group costs the map one decode per vehicle per tick.  Positions are local x/y metres
(``local_fix``; the frontseat interface fills it), drawn without map tiles.

Why every value is checked here: anything on the broker reaches the map.  A USVCommand's polygon is drawn only
within the message's own DCCL bounds (3..10 sides: 3,000,000 sides would cost seconds and hundreds of MB); a
NodeStatus with a non-finite or absurd number is dropped (a NaN stored once would break the JSON of every later
page); names are cut and vehicles are capped.  Each refusal is counted (:attr:`MapModel.refused`) and logged at
most once per kind every 10 s.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from launch.liaison.form_schema import dccl_bounds
from launch.usv.geometry import radial_polygon
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.ratelimit import RateLimitedLog

log = logging.getLogger(__name__)

NODE_STATUS_TYPE = NodeStatus.DESCRIPTOR.full_name
USV_COMMAND_TYPE = USVCommand.DESCRIPTOR.full_name
HEALTH_STATUS_TYPE = HealthStatus.DESCRIPTOR.full_name
HEALTH_RESEND_S = 1.0  # real seconds between updates of the ages (health rows, last reports) when nothing arrived
Point = tuple[float, float]
TRAIL_SPACING_M = 5.0  # a trail point is kept once the vehicle has moved this far from the last one
MAX_VEHICLES = 256  # vehicles drawn; NodeStatus of further names is counted and dropped
MAX_NAME_CHARS = 64
MAX_COORDINATE_M = 1e7  # |x|, |y| of a local fix (10,000 km: beyond that the fix is garbage)
MAX_POLYGON_SIDES = 360  # when the command type carries no DCCL bounds
_USV_FIELDS = USVCommand.DESCRIPTOR.fields_by_name


def _command_bounds(name: str, fallback: tuple[float, float]) -> tuple[float, float]:
    """(min, max) of a USVCommand field from its DCCL options (what the link could ever carry)."""
    bounds = dccl_bounds(_USV_FIELDS[name])
    return (bounds[0], bounds[1]) if bounds is not None else fallback


POLYGON_SIDES = _command_bounds("polygon_sides", (3, MAX_POLYGON_SIDES))
POLYGON_RADIUS_M = _command_bounds("polygon_radius", (1e-3, MAX_COORDINATE_M))


@dataclass(eq=False)
class _Vehicle:
    name: str
    trail: deque[Point]
    type: str = ""
    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    speed: float = 0.0
    time: float = 0.0
    received: float = 0.0  # when its last NodeStatus arrived (this page's clock, sim s)
    appended: list[Point] = field(default_factory=list)

    def view(self, full: bool) -> dict[str, Any]:
        out = {"name": self.name, "type": self.type, "x": round(self.x, 2), "y": round(self.y, 2),
               "heading": round(self.heading, 1), "speed": round(self.speed, 2), "time": self.time}
        if full:
            out["trail"] = [list(p) for p in self.trail]
        else:
            out["append"] = [list(p) for p in self.appended]
        return out


@dataclass(eq=False)
class _Health:
    """A vehicle's last HealthStatus and when (this page's clock, sim s) it arrived."""

    state: str
    timestamp: float  # the status's own time, s (time2: only the second of the day travels the link)
    received: float

    def view(self, vehicle: str, now: float) -> dict[str, Any]:
        return {"vehicle": vehicle, "state": self.state, "time_of_day": round(self.timestamp % 86400.0),
                "age": max(0, round(now - self.received))}


class MapModel:
    """Vehicles by name, the waypoint track and the loiter polygon (from the config, moved by USV commands)."""

    def __init__(self, waypoints: list[Point], polygon: list[Point], center_activate: bool = False,
                 trail_points: int = 600, clock_now: Callable[[], float] = time.time) -> None:
        self.waypoints = list(waypoints)
        self.polygon = list(polygon)
        self.mode: str | None = None
        self.center_activate = center_activate
        self.trail_points = max(2, trail_points)
        self._lock = threading.Lock()
        self._node_payloads: dict[str, bytes] = {}
        self._command_payload: bytes | None = None
        self._health_payload: tuple[bytes, float] | None = None
        self._health: dict[str, _Health] = {}
        self._health_sent = 0.0  # time.monotonic() of the last health rows sent
        self._now = clock_now
        self._vehicles: dict[str, _Vehicle] = {}
        self._last_command_time: float | None = None
        self._overlay_changed = True
        self._centred = not center_activate
        self.refused: Counter[str] = Counter()  # inputs dropped, by reason (web thread)
        self._warn = RateLimitedLog(log, period_s=10.0)

    def _refuse(self, reason: str, msg: str, *args: object) -> None:
        self.refused[reason] += 1
        self._warn.warning(reason, "map: " + msg + " (%d dropped for this reason so far)", *args, self.refused[reason])

    # ---------------------------------------------------------------------------------- portal thread
    def ingest_node_status(self, group: str, payload: bytes) -> None:
        """Keep the newest NodeStatus of a group. Runs on the portal thread."""
        with self._lock:
            self._node_payloads[group] = payload

    def ingest_command(self, payload: bytes) -> None:
        """Keep the newest USVCommand seen on any group. Runs on the portal thread."""
        with self._lock:
            self._command_payload = payload

    def ingest_health(self, payload: bytes) -> None:
        """Keep the newest HealthStatus, with its arrival time. Runs on the portal thread."""
        received = self._now()
        with self._lock:
            self._health_payload = (payload, received)

    # ------------------------------------------------------------------------------------- web thread
    def tick(self) -> dict[str, Any] | None:
        """Decode what arrived since the last tick; the changes as a view, or None. Web thread."""
        with self._lock:
            nodes, self._node_payloads = self._node_payloads, {}
            command, self._command_payload = self._command_payload, None
            health, self._health_payload = self._health_payload, None
        health_changed = health is not None and self._update_health(*health)
        changed = []
        for group, payload in nodes.items():
            vehicle = self._update_vehicle(group, payload)
            if vehicle is not None:
                changed.append(vehicle)
        ages_due = bool(self._health or self._vehicles) and time.monotonic() - self._health_sent >= HEALTH_RESEND_S
        if command is not None:
            self._apply_command(command)
        if not self._centred and self._usv() is not None:
            self._centre_polygon()
            self._centred = True
        if not changed and not self._overlay_changed and not health_changed and not ages_due:
            return None
        update: dict[str, Any] = {"vehicles": [v.view(full=False) for v in changed]}
        if health_changed or ages_due:
            update["health"] = self._health_view()
            update["ages"] = self._report_ages()
        for vehicle in changed:
            vehicle.appended.clear()
        if self._overlay_changed:
            update.update(self._overlays())
            self._overlay_changed = False
        return update

    def snapshot(self) -> dict[str, Any]:
        """Everything, trails included, for a page that just connected. Web thread."""
        return {"vehicles": [v.view(full=True) for v in self._vehicles.values()], **self._overlays(),
                "health": self._health_view(), "ages": self._report_ages()}

    def _report_ages(self) -> dict[str, int]:
        """Seconds (sim) since each vehicle's last NodeStatus arrived: how stale the topside's picture of it is."""
        now = self._now()
        return {name: max(0, round(now - vehicle.received)) for name, vehicle in self._vehicles.items()}

    def _health_view(self) -> list[dict[str, Any]]:
        self._health_sent = time.monotonic()
        now = self._now()
        return [health.view(vehicle, now) for vehicle, health in self._health.items()]

    def _update_health(self, payload: bytes, received: float) -> bool:
        """Store a HealthStatus as the USV's (it carries no vehicle; in the course only the USV reports it, over
        the satellite link, so it is the USV's on the map, or ``USV`` before its first NodeStatus)."""
        status = HealthStatus()
        try:
            status.ParseFromString(payload)
        except Exception as exc:  # noqa: BLE001 - bad input from the broker: report, keep serving
            self._refuse("unparsable", "HealthStatus does not parse: %s", exc)
            return False
        if not status.HasField("state") or status.state not in HealthStatus.HealthState.values():
            self._refuse("health-state", "HealthStatus without a known state: dropped")
            return False
        usv = self._usv()
        self._health[usv.name if usv is not None else "USV"] = _Health(
            HealthStatus.HealthState.Name(status.state), status.timestamp / 1e6, received)
        return True

    def _overlays(self) -> dict[str, Any]:
        return {"waypoints": [list(p) for p in self.waypoints], "polygon": [list(p) for p in self.polygon],
                "mode": self.mode}

    def _update_vehicle(self, group: str, payload: bytes) -> _Vehicle | None:
        status = NodeStatus()
        try:
            status.ParseFromString(payload)
        except Exception as exc:  # noqa: BLE001 - bad input from the broker: report, keep serving
            self._refuse("unparsable", "NodeStatus on %s does not parse: %s", group, exc)
            return None
        if not status.HasField("local_fix"):
            return None
        x, y = status.local_fix.x, status.local_fix.y
        numbers = (x, y, status.pose.heading, status.speed.over_ground, status.time)
        if not all(math.isfinite(v) for v in numbers) or max(abs(x), abs(y)) > MAX_COORDINATE_M:
            self._refuse("non-finite", "NodeStatus on %s has a non-finite or out-of-range number (x %r, y %r, "
                         "heading %r, speed %r, time %r): dropped", group, *numbers)
            return None
        name = (status.name or group)[:MAX_NAME_CHARS]
        vehicle = self._vehicles.get(name)
        if vehicle is None:
            if len(self._vehicles) >= MAX_VEHICLES:
                self._refuse("too-many-vehicles", "more than %d vehicles: NodeStatus of %r on %s dropped",
                             MAX_VEHICLES, name, group)
                return None
            vehicle = self._vehicles[name] = _Vehicle(name, deque(maxlen=self.trail_points))
        vehicle.type = VehicleType.Name(status.type) if status.HasField("type") else ""
        vehicle.x, vehicle.y = x, y
        vehicle.heading = status.pose.heading % 360.0
        vehicle.speed = status.speed.over_ground
        vehicle.time = status.time
        vehicle.received = self._now()
        point = (round(vehicle.x, 1), round(vehicle.y, 1))
        last = vehicle.trail[-1] if vehicle.trail else None
        if last is None or math.hypot(point[0] - last[0], point[1] - last[1]) >= TRAIL_SPACING_M:
            vehicle.trail.append(point)
            vehicle.appended.append(point)
        return vehicle

    def _usv(self) -> _Vehicle | None:
        usvs = [v for v in self._vehicles.values() if v.type == "USV"]
        if usvs:
            return usvs[0]
        return next(iter(self._vehicles.values())) if len(self._vehicles) == 1 else None

    def _centre_polygon(self) -> None:
        usv = self._usv()
        if usv is None or not self.polygon:
            return
        xs = [p[0] for p in self.polygon]
        ys = [p[1] for p in self.polygon]
        dx = usv.x - (min(xs) + max(xs)) / 2
        dy = usv.y - (min(ys) + max(ys)) / 2
        self.polygon = [(x + dx, y + dy) for x, y in self.polygon]
        self._overlay_changed = True

    def _apply_command(self, payload: bytes) -> None:
        command = USVCommand()
        try:
            command.ParseFromString(payload)
        except Exception as exc:  # noqa: BLE001 - bad input from the broker: report, keep serving
            self._refuse("unparsable", "USVCommand does not parse: %s", exc)
            return
        if command.time == self._last_command_time:
            return  # the same command seen again on another group (the manager republishes it)
        self._last_command_time = command.time
        if command.desired_state == USVCommand.POLYGON and not (
                POLYGON_SIDES[0] <= command.polygon_sides <= POLYGON_SIDES[1]
                and POLYGON_RADIUS_M[0] <= command.polygon_radius <= POLYGON_RADIUS_M[1]):
            self._refuse("polygon-bounds", "USVCommand POLYGON with %d sides, radius %d is outside its DCCL bounds "
                         "(sides %g..%g, radius %g..%g): not drawn", command.polygon_sides, command.polygon_radius,
                         *POLYGON_SIDES, *POLYGON_RADIUS_M)
            return
        if command.desired_state == USVCommand.POLYGON:
            ring = radial_polygon(0.0, 0.0, command.polygon_radius, command.polygon_sides)
            self.polygon = [(round(x, 1), round(y, 1)) for x, y in ring.vertices]
            if self.center_activate:
                self._centre_polygon()
            self.mode = "polygon"
        elif command.desired_state == USVCommand.WAYPOINTS:
            self.mode = "waypoints"
        self._overlay_changed = True
