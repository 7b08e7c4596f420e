"""The waypoint list walker shared by BHV_Waypoint and BHV_Loiter: arrival by capture, slip or capture line."""

from __future__ import annotations

import math

from .geometry import Point, rel_ang


def _angle_at(p: Point, a: Point, b: Point) -> float:
    """Angle (degrees, 0..180) at p between the rays p→a and p→b."""
    if p == a or p == b:
        return 0.0
    d = abs(rel_ang(p[0], p[1], a[0], a[1]) - rel_ang(p[0], p[1], b[0], b[1])) % 360.0
    return min(d, 360.0 - d)


class WaypointEngine:
    """Walks a point list; :meth:`step` returns ``in-transit``, ``advanced``, ``cycled``, ``completed`` or ``empty``."""

    def __init__(self) -> None:
        self.points: list[Point] = []
        self.index = 0
        self.capture_radius = 3.0
        self.slip_radius = 15.0
        self.capture_line = False
        self.perpetual = False
        self.repeat = 0
        self.repeat_forever = False
        self.cycle_count = 0
        self.repeats_sofar = 0
        self.capture_hits = 0
        self.nonmono_hits = 0
        self.complete = False
        self.prevpt: Point | None = None
        self._cpa: float | None = None

    def set_points(self, points: list[Point]) -> None:
        """New list: index, cycles and the previous point start over."""
        self.points = list(points)
        self.index = 0
        self.cycle_count = 0
        self.repeats_sofar = 0
        self.complete = False
        self.prevpt = None
        self._cpa = None

    def reset_for_new_traversal(self) -> None:
        self.index = 0
        self.repeats_sofar = 0
        self.complete = False
        self._cpa = None

    def reset_cpa(self) -> None:
        self._cpa = None

    def set_index(self, index: int) -> None:
        if 0 <= index < len(self.points) and index != self.index:
            self.index = index
            self._cpa = None

    def translate(self, dx: float, dy: float) -> None:
        self.points = [(x + dx, y + dy) for x, y in self.points]

    @property
    def target(self) -> Point:
        return self.points[self.index]

    @property
    def total_hits(self) -> int:
        return self.capture_hits + self.nonmono_hits

    def step(self, osx: float, osy: float) -> str:
        """One arrival test for the vehicle at (osx, osy), advancing the index on arrival."""
        if not self.points:
            return "empty"
        if self.complete:
            return "completed"
        target = self.target
        dist = math.hypot(osx - target[0], osy - target[1])
        if self._cpa is None or dist < self._cpa:
            self._cpa = dist
        advance = False
        if dist < self.capture_radius:
            advance = True
            self.capture_hits += 1
        elif self.slip_radius > self.capture_radius and dist > self._cpa and self._cpa <= self.slip_radius:
            advance = True
            self.nonmono_hits += 1
        if self.capture_line and self.prevpt is not None and _angle_at(target, self.prevpt, (osx, osy)) >= 90:
            advance = True
        if not advance:
            return "in-transit"
        self.index += 1
        if self.index >= len(self.points):
            self.cycle_count += 1
            self.index = 0
            self._cpa = None
            if self.perpetual:
                self.repeats_sofar += 1
                if not self.repeat_forever and self.repeats_sofar > self.repeat:
                    self.complete = True
            else:
                self.complete = True
            return "completed" if self.complete else "cycled"
        nxt = self.target
        self._cpa = math.hypot(osx - nxt[0], osy - nxt[1])
        return "advanced"
