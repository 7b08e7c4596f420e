"""The live map's state: vehicles from NodeStatus (position, heading, trail), what the helm has (its VIEW_* postings
and DEPLOY_STATE, when the liaison reads the vehicle's MOOSDB), the mission's overlays, the vehicle's last health
(the course's HealthStatus, as topside-manager publishes it from the satellite link) and the local grid's datum.

Threads: :meth:`MapModel.ingest_node_status`, :meth:`ingest_command`, :meth:`ingest_health` and
:meth:`ingest_moos` run on the portal thread and only keep the newest payload (under a lock held for microseconds);
:meth:`tick` decodes them on the web thread, once per update period, so a fast node_status group costs the map one
decode per vehicle per tick.  Positions are local x/y metres (``local_fix``; the frontseat interface fills it),
drawn without map tiles.

What is drawn as the helm's objective: what the helm posts (VIEW_POLYGON, VIEW_SEGLIST, VIEW_POINT), never what was
sent.  A page without the vehicle's MOOSDB (the topside) can only model it: a POLYGON command while the helm is
already in POLYGON keeps the command's own centre (the translator posts ``x=0,y=0`` and BHV_Loiter re-centres only
when it becomes active, ``center_activate``); a POLYGON command that activates the loiter is centred on the
vehicle.  Such a ring is marked ``"polygon_source": "command"`` so the page says it is not the helm's own.

Why every value is checked here: anything on the broker or the MOOSDB reaches the map.  A USVCommand's polygon is
drawn only within the message's own DCCL bounds (3..10 sides: 3,000,000 sides would cost seconds and hundreds of
MB); a radial VIEW_POLYGON is refused above :data:`MAX_POLYGON_SIDES`, a VIEW_* text above
:data:`MAX_VIEW_CHARS`; a NodeStatus with a non-finite or absurd number is dropped (a NaN stored once would break
the JSON of every later page); names are cut and vehicles and helm views are capped.  Each refusal is counted
(:attr:`MapModel.refused`) and logged at most once per kind every 10 s.
"""

from __future__ import annotations

import logging
import math
import re
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol, TypeVar

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from launch.liaison.form_schema import dccl_bounds
from launch.usv.geometry import parse_points, parse_polygon, radial_polygon
from translators.trail.nav_convert import vehicle_name
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.geodesy import UTMGeodesy
from util.ratelimit import RateLimitedLog

log = logging.getLogger(__name__)

NODE_STATUS_TYPE = NodeStatus.DESCRIPTOR.full_name
USV_COMMAND_TYPE = USVCommand.DESCRIPTOR.full_name
HEALTH_STATUS_TYPE = HealthStatus.DESCRIPTOR.full_name
NAV_REPORT_TYPE = NavigationReport.DESCRIPTOR.full_name  # an AUV's acomms report, as the USV forwards it
HEALTH_RESEND_S = 1.0  # real seconds between updates of the ages and the clock when nothing arrived
Point = tuple[float, float]
_M = TypeVar("_M", NodeStatus, NavigationReport)


class Background(Protocol):
    """The edges of a background image (settings.BackgroundImage)."""

    @property
    def lat_north(self) -> float: ...
    @property
    def lat_south(self) -> float: ...
    @property
    def lon_east(self) -> float: ...
    @property
    def lon_west(self) -> float: ...

TRAIL_SPACING_M = 5.0  # a trail point is kept once the vehicle has moved this far from the last one
MAX_VEHICLES = 256  # vehicles drawn; NodeStatus of further names is counted and dropped
MAX_NAME_CHARS = 64
MAX_COORDINATE_M = 1e7  # |x|, |y| of a local fix (10,000 km: beyond that the fix is garbage)
MAX_POLYGON_SIDES = 360  # a radial VIEW_POLYGON's pts, and a command's when its type carries no DCCL bounds
MAX_VIEW_CHARS = 20_000  # one VIEW_* posting (a pts={...} list of about 1,500 vertices)
MAX_HELM_VIEWS = 64  # distinct (variable, label) views kept
#: The MOOS variables the map reads from the helm (pMarineViewer's, plus the mode).
HELM_VARIABLES = ("VIEW_POLYGON", "VIEW_SEGLIST", "VIEW_POINT", "DEPLOY_STATE")
MODES = {"POLYGON": "polygon", "WAYPOINTS": "waypoints"}
GEO_STEP_M = 2000.0  # the step of the finite differences of the page's lat/lon polynomial
_USV_FIELDS = USVCommand.DESCRIPTOR.fields_by_name
_LABEL = re.compile(r"label\s*=\s*([^,}]*)")
_RADIAL_PTS = re.compile(r"pts\s*=\s*(\d+)")


def _command_bounds(name: str, fallback: tuple[float, float]) -> tuple[float, float]:
    """(min, max) of a USVCommand field from its DCCL options (what the link could ever carry)."""
    bounds = dccl_bounds(_USV_FIELDS[name])
    return (bounds[0], bounds[1]) if bounds is not None else fallback


POLYGON_SIDES = _command_bounds("polygon_sides", (3, MAX_POLYGON_SIDES))
POLYGON_RADIUS_M = _command_bounds("polygon_radius", (1e-3, MAX_COORDINATE_M))


def geo_polynomial(lat: float, lon: float) -> dict[str, Any]:
    """The page's local x/y -> lat/lon: a second-order polynomial fitted (finite differences of
    :class:`util.geodesy.UTMGeodesy`, the project's projection) at the datum.  Its error against UTM is under 2 mm
    within 5 km of the datum and under 8 cm within 10 km at latitude 70 (tests/liaison/test_map_model.py), so the
    page shows the same numbers as the vehicles' own NodeStatus without a projection library of its own.
    Coefficients per output: [c, x, y, x², xy, y²]."""
    geodesy = UTMGeodesy(lat, lon)
    h = GEO_STEP_M
    terms = []
    for index in (0, 1):
        def f(x: float, y: float, i: int = index) -> float:
            return geodesy.to_geo(x, y)[i]

        f0 = f(0.0, 0.0)
        terms.append([f0, (f(h, 0) - f(-h, 0)) / (2 * h), (f(0, h) - f(0, -h)) / (2 * h),
                      (f(h, 0) - 2 * f0 + f(-h, 0)) / (2 * h * h),
                      (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4 * h * h),
                      (f(0, h) - 2 * f0 + f(0, -h)) / (2 * h * h)])
    return {"lat": lat, "lon": lon, "lat_terms": terms[0], "lon_terms": terms[1]}


@dataclass(eq=False)
class _Vehicle:
    name: str
    trail: deque[Point]
    type: str = ""
    x: float = 0.0
    y: float = 0.0
    lat: float | None = None
    lon: float | None = None
    heading: float = 0.0
    speed: float = 0.0
    time: float = 0.0
    received: float = 0.0  # when its last NodeStatus arrived (this page's clock, sim s)
    appended: list[Point] = field(default_factory=list)

    def view(self, full: bool) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "type": self.type, "x": round(self.x, 2), "y": round(self.y, 2),
                               "heading": round(self.heading, 1), "speed": round(self.speed, 2), "time": self.time}
        if self.lat is not None and self.lon is not None:
            out["lat"], out["lon"] = round(self.lat, 7), round(self.lon, 7)
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


@dataclass(frozen=True)
class HelmView:
    """One of the helm's VIEW_* postings, decoded: a ring, a line of points or one point, with its label."""

    kind: str  # "polygon", "seglist" or "point"
    label: str
    points: tuple[Point, ...]

    def view(self) -> dict[str, Any]:
        return {"kind": self.kind, "label": self.label, "points": [list(p) for p in self.points]}


def _label(text: str) -> str:
    match = _LABEL.search(text)
    return match.group(1).strip()[:MAX_NAME_CHARS] if match else ""


def _pairs(text: str) -> dict[str, str]:
    out = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        if sep:
            out[key.strip().lower()] = value.strip()
    return out


def _finite_points(points: list[Point]) -> bool:
    return all(math.isfinite(x) and math.isfinite(y) and max(abs(x), abs(y)) <= MAX_COORDINATE_M
               for x, y in points)


def parse_helm_view(variable: str, text: str) -> HelmView | None | str:
    """A VIEW_* posting as a :class:`HelmView`, None for an erase (``active=false``), or the reason it is refused."""
    if len(text) > MAX_VIEW_CHARS:
        return f"{len(text)} characters (at most {MAX_VIEW_CHARS})"
    label = _label(text)
    if "active=false" in text.replace(" ", "").lower():
        return None
    points: list[Point]
    if variable == "VIEW_POLYGON":
        if "radial" in text.lower():
            pts = _RADIAL_PTS.search(text)
            if pts is None or not 3 <= int(pts.group(1)) <= MAX_POLYGON_SIDES:
                return f"a radial polygon needs pts in [3, {MAX_POLYGON_SIDES}]"
        polygon = parse_polygon(text)
        if polygon is None:
            return "not a polygon"
        points, kind = [(round(x, 1), round(y, 1)) for x, y in polygon.vertices], "polygon"
    elif variable == "VIEW_SEGLIST":
        points, kind = [(round(x, 1), round(y, 1)) for x, y in parse_points(text)], "seglist"
        if not points:
            return "no points"
    else:
        pairs = _pairs(text)
        try:
            points, kind = [(round(float(pairs["x"]), 2), round(float(pairs["y"]), 2))], "point"
        except (KeyError, ValueError):
            return "a point needs x= and y="
    if not _finite_points(points):
        return "a non-finite or out-of-range coordinate"
    return HelmView(kind, label, tuple(points))


class MapModel:
    """Vehicles by name, the helm's views, the waypoint track and the loiter polygon (from the config, replaced by
    what the helm posts), the mode, and the datum."""

    def __init__(self, waypoints: list[Point], polygon: list[Point], center_activate: bool = False,
                 trail_points: int = 600, clock_now: Callable[[], float] = time.time, *,
                 initial_mode: str | None = None, datum: tuple[float, float] | None = None,
                 helm_views: bool = False, background: Background | None = None) -> None:
        self.waypoints = list(waypoints)
        self.polygon = list(polygon)
        self.polygon_source = "config"
        self.mode: str | None = MODES.get(initial_mode or "")
        self.mode_source = "config" if self.mode else ""
        self.center_activate = center_activate
        self.trail_points = max(2, trail_points)
        self.helm_views = helm_views  # whether the helm's MOOSDB is read (then commands draw nothing themselves)
        self.background = background
        self._lock = threading.Lock()
        self._node_payloads: dict[str, bytes] = {}
        self._nav_payloads: dict[str, bytes] = {}
        self._command_payload: bytes | None = None
        self._health_payload: tuple[bytes, float] | None = None
        self._moos: dict[tuple[str, str], str] = {}  # (variable, label) -> newest text (portal thread writes)
        self._views: dict[tuple[str, str], HelmView] = {}
        self._view_order: dict[tuple[str, str], int] = {}  # when each view last changed (a counter)
        self._view_counter = 0
        self._health: dict[str, _Health] = {}
        self._health_sent = 0.0  # time.monotonic() of the last ages sent
        self._now = clock_now
        self._vehicles: dict[str, _Vehicle] = {}
        self._last_command_time: float | None = None
        self._overlay_changed = True
        self._centred = not center_activate
        self.datum = datum
        self.geo: dict[str, Any] | None = geo_polynomial(*datum) if datum is not None else None
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

    def ingest_nav_report(self, group: str, payload: bytes) -> None:
        """Keep the newest NavigationReport of a group (the AUVs' acomms reports the USV forwards: how the USV's
        own map knows them). Runs on the portal thread."""
        with self._lock:
            self._nav_payloads[group] = payload

    def ingest_command(self, payload: bytes) -> None:
        """Keep the newest USVCommand seen on any group. Runs on the portal thread."""
        with self._lock:
            self._command_payload = payload

    def ingest_health(self, payload: bytes) -> None:
        """Keep the newest HealthStatus, with its arrival time. Runs on the portal thread."""
        received = self._now()
        with self._lock:
            self._health_payload = (payload, received)

    def ingest_moos(self, variable: str, text: str) -> None:
        """Keep the helm's newest posting of one VIEW_* (per label) or DEPLOY_STATE. Runs on the MOOS client's
        thread (the portal thread's reactor)."""
        key = (variable, _label(text[:MAX_VIEW_CHARS]) if variable != "DEPLOY_STATE" else "")
        with self._lock:
            if key in self._moos or len(self._moos) < MAX_HELM_VIEWS:
                self._moos[key] = text
                return
        self._refuse("too-many-views", "more than %d helm views: %s %r dropped", MAX_HELM_VIEWS, *key)

    # ------------------------------------------------------------------------------------- web thread
    def tick(self) -> dict[str, Any] | None:
        """Decode what arrived since the last tick; the changes as a view, or None. Web thread."""
        with self._lock:
            nodes, self._node_payloads = self._node_payloads, {}
            navs, self._nav_payloads = self._nav_payloads, {}
            command, self._command_payload = self._command_payload, None
            health, self._health_payload = self._health_payload, None
            moos, self._moos = self._moos, {}
        health_changed = health is not None and self._update_health(*health)
        changed = []
        for group, payload in nodes.items():
            vehicle = self._update_vehicle(group, payload)
            if vehicle is not None:
                changed.append(vehicle)
        for group, payload in navs.items():
            vehicle = self._update_from_nav(group, payload)
            if vehicle is not None and vehicle not in changed:
                changed.append(vehicle)
        for (variable, _), text in moos.items():
            self._update_helm(variable, text)
        ages_due = time.monotonic() - self._health_sent >= HEALTH_RESEND_S
        if command is not None:
            self._apply_command(command)
        if not self._centred and self._usv() is not None:
            self._centre_polygon()
            self._centred = True
        if not changed and not self._overlay_changed and not health_changed and not ages_due:
            return None
        update: dict[str, Any] = {"vehicles": [v.view(full=False) for v in changed], "clock": self._now()}
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
                "health": self._health_view(), "ages": self._report_ages(), "clock": self._now(),
                "trail_points": self.trail_points, "background": self._background_view()}

    def _background_view(self) -> dict[str, Any] | None:
        """The background image's URL and its edges in local metres (on the datum's UTM grid), once a datum
        is known."""
        if self.background is None or self.datum is None:
            return None
        geodesy = UTMGeodesy(*self.datum)
        west, south = geodesy.to_local(self.background.lat_south, self.background.lon_west)
        east, north = geodesy.to_local(self.background.lat_north, self.background.lon_east)
        return {"url": "/map/background", "west": round(west, 1), "east": round(east, 1), "south": round(south, 1),
                "north": round(north, 1)}

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

    def _update_helm(self, variable: str, text: str) -> None:
        if variable == "DEPLOY_STATE":
            mode = MODES.get(text.strip().upper())
            if mode is None:
                self._refuse("deploy-state", "DEPLOY_STATE %r is neither POLYGON nor WAYPOINTS", text[:40])
                return
            if (mode, "helm") != (self.mode, self.mode_source):
                self.mode, self.mode_source = mode, "helm"
                self._overlay_changed = True
            return
        view = parse_helm_view(variable, text)
        key = (variable, _label(text[:MAX_VIEW_CHARS]))
        if isinstance(view, str):
            self._refuse("helm-view", "%s %r refused: %s", variable, text[:60], view)
            return
        if view is None:
            if self._views.pop(key, None) is not None:
                self._overlay_changed = True
            return
        if self._views.get(key) != view:
            self._views[key] = view
            self._view_counter += 1
            self._view_order[key] = self._view_counter
            self._overlay_changed = True

    def _loiter_key(self) -> tuple[str, str] | None:
        """The helm's VIEW_POLYGON that is the loiter polygon: one labelled ``loiter``/``polygon`` (usv.bhv's
        behaviour is ``polygon``: label ``usv_polygon``), else the one posted last."""
        polygons = [k for k in self._views if k[0] == "VIEW_POLYGON"]
        named = [k for k in polygons if "loiter" in k[1].lower() or "polygon" in k[1].lower()]
        chosen = named or polygons
        return max(chosen, key=lambda k: self._view_order.get(k, 0)) if chosen else None

    def _overlays(self) -> dict[str, Any]:
        loiter = self._loiter_key()
        polygon = [list(p) for p in self._views[loiter].points] if loiter else [list(p) for p in self.polygon]
        source = "helm" if loiter else self.polygon_source
        views = [v.view() for k, v in self._views.items() if k != loiter]
        return {"waypoints": [list(p) for p in self.waypoints], "polygon": polygon, "polygon_source": source,
                "mode": self.mode, "mode_source": self.mode_source, "views": views, "geo": self.geo,
                "helm_read": self.helm_views}

    def _parse(self, cls: type[_M], group: str, payload: bytes) -> _M | None:
        """``payload`` as a ``cls``, or None (counted and logged): bad input from the broker never stops the page."""
        msg = cls()
        try:
            msg.ParseFromString(payload)
        except Exception as exc:  # noqa: BLE001 - bad input from the broker: report, keep serving
            self._refuse("unparsable", "%s on %s does not parse: %s", cls.__name__, group, exc)
            return None
        return msg

    def _in_range(self, what: str, group: str, numbers: tuple[float, ...]) -> bool:
        """Position, heading, speed and time all finite and the position on the map's grid; else refused (logged)."""
        x, y = numbers[0], numbers[1]
        if all(math.isfinite(v) for v in numbers) and max(abs(x), abs(y)) <= MAX_COORDINATE_M:
            return True
        self._refuse("non-finite", "%s on %s has a non-finite or out-of-range number (x %r, y %r, heading %r, "
                     "speed %r, time %r): dropped", what, group, *numbers)
        return False

    def _update_vehicle(self, group: str, payload: bytes) -> _Vehicle | None:
        status = self._parse(NodeStatus, group, payload)
        if status is None or not status.HasField("local_fix"):
            return None
        x, y = status.local_fix.x, status.local_fix.y
        numbers = (x, y, status.pose.heading, status.speed.over_ground, status.time)
        if not self._in_range("NodeStatus", group, numbers):
            return None
        kind = VehicleType.Name(status.type) if status.HasField("type") else ""
        vehicle = self._place((status.name or group)[:MAX_NAME_CHARS], group, kind, *numbers)
        if vehicle is None:
            return None
        vehicle.lat = vehicle.lon = None
        if status.HasField("global_fix"):
            lat, lon = status.global_fix.lat, status.global_fix.lon
            if math.isfinite(lat) and math.isfinite(lon) and abs(lat) <= 90 and abs(lon) <= 180:
                vehicle.lat, vehicle.lon = lat, lon
                if self.geo is None:
                    self._derive_datum(lat, lon, x, y)
        return vehicle

    def _update_from_nav(self, group: str, payload: bytes) -> _Vehicle | None:
        """An AUV's NavigationReport (x/y on the same grid); a USV's or topside's is skipped (its own NodeStatus
        is drawn under its own name)."""
        nav = self._parse(NavigationReport, group, payload)
        if nav is None or nav.type != NavigationReport.AUV or not nav.IsInitialized():
            return None
        numbers = (nav.x, nav.y, nav.heading, nav.speed_over_ground, nav.time)
        if not self._in_range("NavigationReport", group, numbers):
            return None
        return self._place(vehicle_name(nav), group, "AUV", *numbers)

    def _place(self, name: str, group: str, kind: str, x: float, y: float, heading: float, speed: float,
               when: float) -> _Vehicle | None:
        """Move a vehicle (made on its first report, up to MAX_VEHICLES) and grow its trail."""
        vehicle = self._vehicles.get(name)
        if vehicle is None:
            if len(self._vehicles) >= MAX_VEHICLES:
                self._refuse("too-many-vehicles", "more than %d vehicles: the report of %r on %s dropped",
                             MAX_VEHICLES, name, group)
                return None
            vehicle = self._vehicles[name] = _Vehicle(name, deque(maxlen=self.trail_points))
        vehicle.type = kind
        vehicle.x, vehicle.y = x, y
        vehicle.heading = heading % 360.0
        vehicle.speed = speed
        vehicle.time = when
        vehicle.received = self._now()
        point = (round(vehicle.x, 1), round(vehicle.y, 1))
        last = vehicle.trail[-1] if vehicle.trail else None
        if last is None or math.hypot(point[0] - last[0], point[1] - last[1]) >= TRAIL_SPACING_M:
            vehicle.trail.append(point)
            vehicle.appended.append(point)
        return vehicle

    def _derive_datum(self, lat: float, lon: float, x: float, y: float) -> None:
        """The datum from a fix that has both lat/lon and x/y: the point (-x, -y) from it on its UTM grid."""
        if not (-80.0 <= lat <= 84.0):
            return
        try:
            datum = UTMGeodesy(lat, lon).to_geo(-x, -y)
            self.geo = geo_polynomial(*datum)
            self.datum = datum
        except (ValueError, ArithmeticError) as exc:
            self._refuse("datum", "no datum from the fix %g, %g at %g, %g: %s", lat, lon, x, y, exc)
            return
        self._overlay_changed = True

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
        self.polygon = [(round(x + dx, 1), round(y + dy, 1)) for x, y in self.polygon]
        self._overlay_changed = True

    def _apply_command(self, payload: bytes) -> None:
        """A USVCommand seen on the broker.  With the helm's MOOSDB read, it changes nothing drawn (the helm's
        postings do); without it (the topside), the helm is modelled: see the module's docstring."""
        command = USVCommand()
        try:
            command.ParseFromString(payload)
        except Exception as exc:  # noqa: BLE001 - bad input from the broker: report, keep serving
            self._refuse("unparsable", "USVCommand does not parse: %s", exc)
            return
        if command.time == self._last_command_time:
            return  # the same command seen again on another group (the manager republishes it)
        self._last_command_time = command.time
        if self.helm_views:
            return
        if command.desired_state == USVCommand.POLYGON and not (
                POLYGON_SIDES[0] <= command.polygon_sides <= POLYGON_SIDES[1]
                and POLYGON_RADIUS_M[0] <= command.polygon_radius <= POLYGON_RADIUS_M[1]):
            self._refuse("polygon-bounds", "USVCommand POLYGON with %d sides, radius %d is outside its DCCL bounds "
                         "(sides %g..%g, radius %g..%g): not drawn", command.polygon_sides, command.polygon_radius,
                         *POLYGON_SIDES, *POLYGON_RADIUS_M)
            return
        if command.desired_state == USVCommand.POLYGON:
            activates = self.mode != "polygon"
            ring = radial_polygon(0.0, 0.0, command.polygon_radius, command.polygon_sides)
            self.polygon = [(round(x, 1), round(y, 1)) for x, y in ring.vertices]
            if activates and self.center_activate:
                self._centre_polygon()
            self.polygon_source = "command"
            self.mode, self.mode_source = "polygon", "command"
        elif command.desired_state == USVCommand.WAYPOINTS:
            self.mode, self.mode_source = "waypoints", "command"
        self._overlay_changed = True
