"""Judge a recorded USV mission: state timelines, what each command did, how well the vehicle loitered.

Everything here is a pure function of a ``MissionRecord``; the demo prints it, the tests assert on it.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from launch.record import Event, MissionRecord, NavSample
from launch.usv.geometry import Point, Polygon, parse_points, parse_polygon, radial_polygon

COMMAND_VARS = ("POLYGON_UPDATES", "DEPLOY_STATE")
SETTLED_WITHIN_M = 15.0
DEFAULT_RING = radial_polygon(0.0, 0.0, 200.0, 6)


def transitions(events: list[Event]) -> list[tuple[float, str]]:
    """(time, value) at each change of value, in order."""
    out: list[tuple[float, str]] = []
    for event in events:
        if not out or out[-1][1] != event.value:
            out.append((event.t, event.value))
    return out


def interface_timeline(record: MissionRecord) -> list[tuple[float, str]]:
    return transitions(record.events_named("interface_state", source="interface"))


def helm_timeline(record: MissionRecord) -> list[tuple[float, str]]:
    return transitions(record.events_named("IVPHELM_STATE", source="moos"))


def _from_helm(event: Event) -> bool:
    # The helm's own `initialize` postings are not commands from shore.
    return "helm" in event.origin.lower()


@dataclass
class CommandEffect:
    """One shore command as MOOS saw it: the postings it produced, in arrival order."""

    posts: list[Event] = field(default_factory=list)

    @property
    def t(self) -> float:
        return self.posts[0].t

    @property
    def state(self) -> str:
        states = [p.value for p in self.posts if p.name == "DEPLOY_STATE"]
        return states[-1] if states else "?"

    @property
    def polygon_before_state(self) -> bool:
        names = [p.name for p in self.posts]
        return "POLYGON_UPDATES" in names and "DEPLOY_STATE" in names and (
            names.index("POLYGON_UPDATES") < names.index("DEPLOY_STATE")
        )

    def describe(self) -> str:
        return ", ".join(f"{p.name}={p.value}" for p in self.posts)


def command_effects(record: MissionRecord) -> list[CommandEffect]:
    """Group command postings: an optional POLYGON_UPDATES followed by DEPLOY_STATE is one command."""
    effects: list[CommandEffect] = []
    pending: CommandEffect | None = None
    for event in record.snapshot()[1]:
        if event.source != "moos" or event.name not in COMMAND_VARS or _from_helm(event):
            continue
        if pending is None:
            pending = CommandEffect()
        pending.posts.append(event)
        if event.name == "DEPLOY_STATE":
            effects.append(pending)
            pending = None
    if pending is not None:
        effects.append(pending)
    return effects


@dataclass(frozen=True)
class LinkAck:
    """The satellite link's answer to one shore command (recorded on the topside broker): sim seconds."""

    t: float
    acked: bool
    slot_wait: float
    latency: float
    responder: str


def link_acks(record: MissionRecord) -> list[LinkAck]:
    """LINK_ACKED / LINK_EXPIRED events, in order (value ``slot_wait=S;link_latency=L``)."""
    out = []
    for event in record.snapshot()[1]:
        if event.source != "ack" or event.name not in ("LINK_ACKED", "LINK_EXPIRED"):
            continue
        fields = dict(part.split("=", 1) for part in str(event.value).split(";") if "=" in part)
        out.append(LinkAck(event.t, event.name == "LINK_ACKED", float(fields.get("slot_wait", "nan")),
                           float(fields.get("link_latency", "nan")), event.origin))
    return out


@dataclass
class LoiterPhase:
    """An interval with DEPLOY_STATE=POLYGON and how the vehicle did on the ring in force."""

    start: float
    end: float
    ring: Polygon
    ring_source: str
    settled_at: float | None = None
    mean_distance: float | None = None
    samples: int = 0
    final_center_distance: float | None = None


def _deploy_intervals(record: MissionRecord, end_time: float) -> list[tuple[float, float, str]]:
    changes = transitions(record.events_named("DEPLOY_STATE", source="moos"))
    out = []
    for i, (t, state) in enumerate(changes):
        t_end = changes[i + 1][0] if i + 1 < len(changes) else end_time
        out.append((t, t_end, state))
    return out


def _position_at(nav: list[NavSample], t: float) -> Point | None:
    before = [s for s in nav if s.t <= t]
    sample = before[-1] if before else (nav[0] if nav else None)
    return None if sample is None else (sample.x, sample.y)


def _ring_for(record: MissionRecord, start: float, end: float, first: bool) -> tuple[Polygon, str]:
    views = [e for e in record.events_named("VIEW_POLYGON", source="moos") if start <= e.t <= end]
    for event in reversed(views):
        polygon = parse_polygon(event.value)
        if polygon is not None:
            return polygon, "VIEW_POLYGON"
    updates = [e for e in record.events_named("POLYGON_UPDATES", source="moos") if e.t <= start + 1.0]
    ring = DEFAULT_RING
    if updates:
        parsed = parse_polygon(updates[-1].value)
        ring = parsed or ring
    if not first:
        # BHV_Loiter with center_activate=true moves the ring to where the vehicle is when it activates.
        where = _position_at(record.snapshot()[0], start)
        if where is not None:
            ring = ring.moved_to(where)
    return ring, "derived"


def loiter_phases(record: MissionRecord, end_time: float | None = None) -> list[LoiterPhase]:
    nav = record.snapshot()[0]
    if end_time is None:
        end_time = nav[-1].t if nav else 0.0
    phases = []
    first = True
    for start, end, state in _deploy_intervals(record, end_time):
        if state != "POLYGON":
            first = False
            continue
        ring, source = _ring_for(record, start, end, first)
        phase = LoiterPhase(start, end, ring, source)
        inside = [s for s in nav if start <= s.t <= end]
        settled = next((s.t for s in inside if ring.distance((s.x, s.y)) <= SETTLED_WITHIN_M), None)
        phase.settled_at = settled
        if settled is not None:
            after = [ring.distance((s.x, s.y)) for s in inside if s.t >= settled]
            phase.samples = len(after)
            phase.mean_distance = sum(after) / len(after)
        if inside:
            cx, cy = ring.center
            phase.final_center_distance = math.hypot(inside[-1].x - cx, inside[-1].y - cy)
        phases.append(phase)
        first = False
    return phases


def normalized_heading(heading: float) -> float:
    """A heading in [0, 360): the basic simulator, like Goby's, never wraps NAV_HEADING (540 is 180)."""
    wrapped = heading % 360.0
    return 0.0 if wrapped >= 360.0 else wrapped  # -1e-15 % 360 is 360.0


@dataclass
class WaypointApproach:
    """How the vehicle reacted to WAYPOINTS, over the WAYPOINTS phase (until the next command or the end).

    ``t_end`` is when the phase ended; ``ended_by_command`` says whether another command ended it (else the
    record, or ``window_s``, did).
    """

    t_command: float
    t_end: float
    ended_by_command: bool
    waypoint: Point
    start_range: float
    min_range: float
    start_heading_error: float | None
    min_heading_error: float | None

    @property
    def duration(self) -> float:
        return self.t_end - self.t_command


def bhv_waypoints(bhv_file: Path) -> list[Point]:
    """The points of the first BHV_Waypoint block in a .bhv file (``points =`` or ``polygon =``)."""
    text = re.sub(r"//[^\n]*", "", bhv_file.read_text())
    block = re.search(r"BHV_Waypoint\s*\{(.*?)\}", text, flags=re.S)
    if not block:
        return []
    match = re.search(r"^\s*(?:points|polygon)\s*=\s*(.+)$", block.group(1), flags=re.M)
    return parse_points(match.group(1).strip()) if match else []


def bhv_loiter_polygon(bhv_file: Path) -> Polygon | None:
    """The ``polygon =`` of the first BHV_Loiter block in a .bhv file, if it is one this module can read."""
    text = re.sub(r"//[^\n]*", "", bhv_file.read_text())
    block = re.search(r"BHV_Loiter\s*\{(.*?)\}", text, flags=re.S)
    if not block:
        return None
    match = re.search(r"^\s*polygon\s*=\s*(.+)$", block.group(1), flags=re.M)
    return parse_polygon(match.group(1).strip()) if match else None


def _bearing(a: Point, b: Point) -> float:
    return math.degrees(math.atan2(b[0] - a[0], b[1] - a[1])) % 360.0


def _angle_error(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def waypoint_approach(
    record: MissionRecord, waypoints: list[Point], window_s: float | None = None
) -> WaypointApproach | None:
    """The vehicle's reaction to the first WAYPOINTS command, from when it reached MOOS until the next command
    reached MOOS (or the record ends; at most ``window_s`` when given)."""
    effects = command_effects(record)
    index = next((i for i, c in enumerate(effects) if c.state == "WAYPOINTS"), None)
    if index is None:
        return None
    t0 = effects[index].t
    next_command = effects[index + 1].t if index + 1 < len(effects) else None
    all_nav = record.snapshot()[0]
    t_end = next_command if next_command is not None else (all_nav[-1].t if all_nav else t0)
    ended_by_command = next_command is not None
    if window_s is not None and t_end > t0 + window_s:
        t_end, ended_by_command = t0 + window_s, False
    seglists = [e for e in record.events_named("VIEW_SEGLIST", source="moos") if t0 <= e.t <= t_end]
    points = parse_points(seglists[0].value) if seglists else []
    targets = points or waypoints
    if not targets:
        return None
    target = targets[0]
    nav = [s for s in all_nav if t0 <= s.t <= t_end]
    if not nav:
        return None
    ranges = [math.hypot(target[0] - s.x, target[1] - s.y) for s in nav]
    errors = [_angle_error(s.heading, _bearing((s.x, s.y), target)) for s in nav if s.heading is not None]
    return WaypointApproach(
        t_command=t0,
        t_end=t_end,
        ended_by_command=ended_by_command,
        waypoint=target,
        start_range=ranges[0],
        min_range=min(ranges),
        start_heading_error=errors[0] if errors else None,
        min_heading_error=min(errors) if errors else None,
    )
