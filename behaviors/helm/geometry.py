"""Plane geometry in MOOS-IvP's conventions: x east, y north, compass angles (0 = +y, clockwise)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from translators.node_report_codec import double_to_string_x

Point = tuple[float, float]


def rel_ang(x1: float, y1: float, x2: float, y2: float) -> float:
    """Compass bearing from (x1,y1) to (x2,y2) in [0, 360)."""
    if x1 == x2 and y1 == y2:
        return 0.0
    return math.degrees(math.atan2(x2 - x1, y2 - y1)) % 360.0


def angle180(a: float) -> float:
    """An angle in (-180, 180]."""
    a = a % 360.0
    return a - 360.0 if a > 180.0 else a


def segment_angle(x1: float, y1: float, x2: float, y2: float, x3: float, y3: float) -> float:
    """Turn (degrees, clockwise positive) at (x2,y2) going from the leg 1→2 to the leg 2→3."""
    if (x1, y1) == (x2, y2) or (x2, y2) == (x3, y3):
        return 0.0
    result = angle180(rel_ang(x2, y2, x3, y3)) - angle180(rel_ang(x1, y1, x2, y2))
    if result > 180:
        result -= 360
    if result <= -180:
        result += 360
    return result


def project(x: float, y: float, bearing: float, dist: float) -> Point:
    """The point ``dist`` metres from (x,y) along a compass bearing."""
    rad = math.radians(bearing)
    return x + dist * math.sin(rad), y + dist * math.cos(rad)


def perp_on_segment(px: float, py: float, a: Point, b: Point) -> Point:
    """Foot of the perpendicular from p onto segment a-b, clamped to the segment."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    if length2 == 0:
        return a
    t = max(0.0, min(1.0, ((px - a[0]) * dx + (py - a[1]) * dy) / length2))
    return a[0] + t * dx, a[1] + t * dy


def dist_to_segment(px: float, py: float, a: Point, b: Point) -> float:
    fx, fy = perp_on_segment(px, py, a, b)
    return math.hypot(px - fx, py - fy)


def _cross(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


@dataclass
class Polygon:
    """A convex polygon; vertex order matters to the loiter (it is the order the vehicle visits them)."""

    vertices: list[Point]

    def is_convex(self) -> bool:
        pts = self.vertices
        if len(pts) < 3:
            return False
        signs = set()
        for i in range(len(pts)):
            c = _cross(pts[i], pts[(i + 1) % len(pts)], pts[(i + 2) % len(pts)])
            if abs(c) > 1e-9:
                signs.add(c > 0)
        return len(signs) == 1

    def is_clockwise(self) -> bool:
        """Clockwise seen from above with y north (negative signed area in math convention)."""
        pts = self.vertices
        area = sum(pts[i][0] * pts[(i + 1) % len(pts)][1] - pts[(i + 1) % len(pts)][0] * pts[i][1]
                   for i in range(len(pts)))
        return area < 0

    def reversed(self) -> Polygon:
        return Polygon(list(reversed(self.vertices)))

    def center(self) -> Point:
        """Centre of the bounding box (what MOOS-IvP re-centres on)."""
        xs = [p[0] for p in self.vertices]
        ys = [p[1] for p in self.vertices]
        return (min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0

    def moved_to(self, cx: float, cy: float) -> Polygon:
        ox, oy = self.center()
        return Polygon([(x + cx - ox, y + cy - oy) for x, y in self.vertices])

    def contains(self, x: float, y: float) -> bool:
        """Strictly inside a convex polygon."""
        pts = self.vertices
        signs = set()
        for i in range(len(pts)):
            c = _cross(pts[i], pts[(i + 1) % len(pts)], (x, y))
            if abs(c) < 1e-9:
                return False
            signs.add(c > 0)
        return len(signs) == 1

    def dist_to_edge(self, x: float, y: float) -> float:
        pts = self.vertices
        return min(dist_to_segment(x, y, pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts)))

    def signed_dist(self, x: float, y: float) -> float:
        """Distance to the nearest edge, negative inside (the loiter's ``dist_to_poly``)."""
        d = self.dist_to_edge(x, y)
        return -d if self.contains(x, y) else d

    def vertex_visible(self, i: int, x: float, y: float) -> bool:
        """True if the straight line from (x,y) to vertex i does not cross the polygon's interior."""
        vx, vy = self.vertices[i]
        d = math.hypot(x - vx, y - vy)
        if d == 0:
            return True
        step = min(1e-3, d / 2) / d
        return not self.contains(vx + (x - vx) * step, vy + (y - vy) * step)

    def max_radius(self) -> float:
        cx, cy = self.center()
        return max(math.hypot(px - cx, py - cy) for px, py in self.vertices)

    def spec(self) -> str:
        return "pts={" + ":".join(f"{fmt_num(x)},{fmt_num(y)}" for x, y in self.vertices) + "}"


fmt_num = double_to_string_x  # MBUtils' doubleToStringX; one implementation, in the node-report codec
