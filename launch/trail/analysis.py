"""Judge a recorded trail mission: state timelines, distances, how well each AUV trailed, commands and RECOVER.

Pure functions of the per-vehicle ``MissionRecord``s (times in sim seconds, t=0 when every vehicle was under
command); the demo prints them, the mission test asserts on them.
"""

from __future__ import annotations

import bisect
import math
import statistics
from dataclasses import dataclass

from launch.record import Event, MissionRecord, NavSample
from launch.trail.settings import Vehicle
from launch.usv.analysis import transitions

TRAIL_RANGE = 50.0  # auv.bhv's trail_range
STATION = (100.0, -100.0)  # auv.bhv's recover station_pt
SETTLED_WITHIN_M = 20.0  # an AUV counts as trailing from the first fix this close to its trail point
STATE_VARS = (("interface", "interface_state"), ("moos", "IVPHELM_STATE"), ("moos", "DEPLOY_STATE"),
              ("moos", "AUV_DEPLOY_STATE"))


def state_timeline(record: MissionRecord) -> list[tuple[float, str, str]]:
    """(t, what, value) at each change of the interface state, helm state and deploy state, in time order."""
    out: list[tuple[float, str, str]] = []
    for source, name in STATE_VARS:
        label = "interface" if name == "interface_state" else name
        out += [(t, label, v.removeprefix("INTERFACE_")) for t, v in transitions(record.events_named(name, source))]
    return sorted(out, key=lambda item: item[0])  # stable: same-time changes keep their arrival order


def distance_travelled(nav: list[NavSample]) -> float:
    return sum(math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(nav, nav[1:], strict=False))


def _interpolate(track: list[NavSample], times: list[float], t: float) -> NavSample | None:
    """The track's position and heading at ``t`` (linear between fixes); None outside the track."""
    i = bisect.bisect_left(times, t)
    if i == 0 or i >= len(track):
        return None
    a, b = track[i - 1], track[i]
    f = 0.0 if b.t == a.t else (t - a.t) / (b.t - a.t)
    heading = a.heading if a.heading is not None else b.heading
    return NavSample(t, a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), heading, a.speed, a.depth)


def relative_position(usv: NavSample, auv: NavSample) -> tuple[float, float]:
    """(range m, angle deg) of the AUV from the USV, the angle clockwise from the USV's heading (BHV_Trail's
    ``trail_angle_type = relative``: 90 is the starboard beam, 180 astern)."""
    dx, dy = auv.x - usv.x, auv.y - usv.y
    bearing = math.degrees(math.atan2(dx, dy))
    return math.hypot(dx, dy), (bearing - (usv.heading or 0.0)) % 360.0


def angle_difference(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def trail_point(usv: NavSample, angle: float, distance: float = TRAIL_RANGE) -> tuple[float, float]:
    bearing = math.radians((usv.heading or 0.0) + angle)
    return usv.x + distance * math.sin(bearing), usv.y + distance * math.cos(bearing)


@dataclass
class Stat:
    mean: float
    max: float
    samples: int

    def __str__(self) -> str:
        return f"mean {self.mean:.1f}, max {self.max:.1f} ({self.samples} fixes)"


def _stat(values: list[float]) -> Stat | None:
    return Stat(statistics.fmean(values), max(values), len(values)) if values else None


@dataclass
class TrailPerformance:
    """How one AUV trailed the USV between settling and RECOVER (or the end)."""

    name: str
    trail_angle: float
    depth: float
    settled_at: float | None
    end: float
    range_error: Stat | None
    angle_error: Stat | None
    depth_error: Stat | None
    relative: list[tuple[float, float, float]]  # (t, starboard m, ahead m) in the USV's frame, whole run


def trail_performance(vehicle: Vehicle, auv: MissionRecord, usv: MissionRecord, end: float | None = None) -> TrailPerformance:
    """Errors of the AUV's range, relative angle and depth against auv.bhv's trail_range, trail_angle and depth."""
    usv_track = usv.snapshot()[0]
    times = [s.t for s in usv_track]
    recover = next((e.t for e in auv.events_named("AUV_DEPLOY_STATE", "moos") if e.value == "RECOVER"), None)
    nav = auv.snapshot()[0]
    stop = min(x for x in (end, recover, nav[-1].t if nav else None, math.inf) if x is not None)
    settled_at: float | None = None
    ranges, angles, depths, relative = [], [], [], []
    for sample in nav:
        ref = _interpolate(usv_track, times, sample.t)
        if ref is None:
            continue
        rng, angle = relative_position(ref, sample)
        rad = math.radians(angle)
        relative.append((sample.t, rng * math.sin(rad), rng * math.cos(rad)))
        if sample.t < 0 or sample.t > stop:
            continue
        tx, ty = trail_point(ref, vehicle.trail_angle)
        if settled_at is None and math.hypot(sample.x - tx, sample.y - ty) < SETTLED_WITHIN_M:
            settled_at = sample.t
        if settled_at is None:
            continue
        ranges.append(abs(rng - TRAIL_RANGE))
        angles.append(angle_difference(angle, vehicle.trail_angle))
        if sample.depth is not None:
            depths.append(abs(sample.depth - vehicle.deploy_depth))
    return TrailPerformance(vehicle.display_name, vehicle.trail_angle, vehicle.deploy_depth, settled_at, stop,
                            _stat(ranges), _stat(angles), _stat(depths), relative)


@dataclass
class RecoverOutcome:
    name: str
    commanded_at: float | None  # AUV_DEPLOY_STATE=RECOVER in its MOOSDB
    depth_updates_first: bool  # DEPLOY_DEPTH_UPDATES=depth=0 came before it
    final_depth: float | None
    final_distance_to_station: float | None
    min_distance_to_station: float | None


def recover_outcome(name: str, auv: MissionRecord) -> RecoverOutcome:
    nav, events = auv.snapshot()
    state = next((e for e in events if e.name == "AUV_DEPLOY_STATE" and e.value == "RECOVER"), None)
    depth0 = next((e for e in events if e.name == "DEPLOY_DEPTH_UPDATES" and e.value.replace(" ", "") == "depth=0"),
                  None)
    after = [s for s in nav if state is not None and s.t >= state.t]
    distances = [math.hypot(s.x - STATION[0], s.y - STATION[1]) for s in after]
    return RecoverOutcome(
        name,
        None if state is None else state.t,
        state is not None and depth0 is not None and depth0.t <= state.t,
        after[-1].depth if after else None,
        distances[-1] if distances else None,
        min(distances) if distances else None,
    )


@dataclass
class CommandOutcome:
    """One command: when it left, whether it was acked, when its MOOS variable changed on the target."""

    what: str
    sent_at: float
    acks: list[tuple[float, str]]  # (time, who acked: "modem N, latency ...")
    expires: list[tuple[float, str]]  # (time, reason), e.g. on a link with no subscriber for it
    arrived_at: dict[str, float]  # vehicle name -> time its MOOSDB got the resulting state

    @property
    def acked_at(self) -> float | None:
        return self.acks[0][0] if self.acks else None

    @property
    def expired(self) -> str | None:
        """Why it expired, when it was never acked."""
        return self.expires[0][1] if self.expires and not self.acks else None

    @property
    def latencies(self) -> list[float]:
        return [t - self.sent_at for t in self.arrived_at.values()]


def command_outcomes(operator: MissionRecord, vehicles: dict[str, MissionRecord]) -> list[CommandOutcome]:
    """Each sent command with its ack and the first matching posting on its targets after it was sent."""
    events = operator.snapshot()[1]
    sent = [e for e in events if e.source == "command" and e.name == "sent"]
    out: list[CommandOutcome] = []
    for i, command in enumerate(sent):
        next_sent = sent[i + 1].t if i + 1 < len(sent) else math.inf
        arrived: dict[str, float] = {}
        if command.value == "recover":
            targets = {n: r for n, r in vehicles.items() if n.startswith("auv")}
            var, expected = "AUV_DEPLOY_STATE", "RECOVER"
        else:
            targets = {n: r for n, r in vehicles.items() if n == "usv"}
            var, expected = "DEPLOY_STATE", "WAYPOINTS" if command.value.startswith("waypoints") else "POLYGON"
        for name, record in targets.items():
            hit = _first(record.events_named(var, "moos"), command.t, next_sent, expected)
            if hit is not None:
                arrived[name] = hit.t
        mine = [e for e in events if command.t <= e.t < next_sent and e.value == command.value]
        out.append(CommandOutcome(command.value, command.t, [(e.t, e.origin) for e in mine if e.name == "ack"],
                                  [(e.t, e.origin) for e in mine if e.name == "expire"], arrived))
    return out


def _first(events: list[Event], start: float, end: float, value: str) -> Event | None:
    return next((e for e in events if start <= e.t < end and e.value == value), None)
