"""Polygon strings as MOOS-IvP writes them, and distances to them, for judging the loiter.

Pure functions: ``radial::x=0,y=0,radius=200,pts=6`` (the BHV_Loiter and POLYGON_UPDATES form) and
``pts={x1,y1:x2,y2:...},label=..`` (the VIEW_POLYGON form), in local x/y metres.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

Point = tuple[float, float]
_PTS = re.compile(r"pts\s*=\s*\{([^}]*)\}")


@dataclass(frozen=True)
class Polygon:
    """A closed ring of vertices in local x/y metres, plus the label its poster gave it."""

    vertices: tuple[Point, ...]
    label: str = ""

    @property
    def center(self) -> Point:
        """The bounding-box centre, which is what BHV_Loiter calls the polygon's centre."""
        xs = [v[0] for v in self.vertices]
        ys = [v[1] for v in self.vertices]
        return ((min(xs) + max(xs)) / 2.0, (min(ys) + max(ys)) / 2.0)

    @property
    def mean_radius(self) -> float:
        cx, cy = self.center
        return sum(math.hypot(x - cx, y - cy) for x, y in self.vertices) / len(self.vertices)

    def distance(self, point: Point) -> float:
        """Distance from ``point`` to the nearest edge (positive inside and outside)."""
        ring = list(self.vertices) + [self.vertices[0]]
        return min(_segment_distance(point, a, b) for a, b in zip(ring, ring[1:], strict=False))

    def moved_to(self, center: Point) -> Polygon:
        """The same shape translated so its centre is ``center`` (BHV_Loiter's re-centring)."""
        cx, cy = self.center
        dx, dy = center[0] - cx, center[1] - cy
        return Polygon(tuple((x + dx, y + dy) for x, y in self.vertices), self.label)


def _segment_distance(p: Point, a: Point, b: Point) -> float:
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / length2))
    return math.hypot(p[0] - (ax + t * dx), p[1] - (ay + t * dy))


def _pairs(text: str) -> dict[str, str]:
    pairs: dict[str, str] = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        if sep:
            pairs[key.strip().lower()] = value.strip()
    return pairs


def radial_polygon(x: float, y: float, radius: float, pts: int, label: str = "") -> Polygon:
    """MOOS-IvP's radial polygon: vertex k at compass bearing delta/2 + k*delta, clockwise."""
    if radius <= 0 or pts < 3:
        raise ValueError(f"radial polygon needs radius > 0 and pts >= 3, not radius={radius}, pts={pts}")
    delta = 360.0 / pts
    vertices = []
    for k in range(pts):
        bearing = math.radians(delta / 2.0 + k * delta)
        vertices.append((x + radius * math.sin(bearing), y + radius * math.cos(bearing)))
    return Polygon(tuple(vertices), label)


def parse_polygon(spec: str) -> Polygon | None:
    """A polygon from a ``radial::`` / ``format=radial`` string or a ``pts={...}`` string.

    Returns None for an erase marker (``active=false``) or anything not understood, since viewers
    ignore those too.
    """
    text = spec.strip()
    if text.startswith("polygon="):
        text = text[len("polygon=") :]
    lowered = text.lower()
    if "active=false" in lowered.replace(" ", ""):
        return None
    match = _PTS.search(text)
    if match:
        vertices = []
        for pair in match.group(1).split(":"):
            coords = pair.split(",")
            if len(coords) < 2:
                continue
            try:
                vertices.append((float(coords[0]), float(coords[1])))
            except ValueError:
                return None
        rest = _pairs(_PTS.sub("", text))
        return Polygon(tuple(vertices), rest.get("label", "")) if len(vertices) >= 3 else None
    if lowered.startswith("radial::") or "format=radial" in lowered.replace(" ", ""):
        body = text.split("::", 1)[1] if "::" in text else text
        pairs = _pairs(body)
        try:
            return radial_polygon(
                float(pairs["x"]), float(pairs["y"]), float(pairs["radius"]), int(pairs["pts"]), pairs.get("label", "")
            )
        except (KeyError, ValueError):
            return None
    return None


def parse_points(spec: str) -> list[Point]:
    """Waypoints from ``x1,y1:x2,y2`` or ``pts={...}`` (VIEW_SEGLIST, a waypoint behaviour's points)."""
    match = _PTS.search(spec)
    body = match.group(1) if match else spec
    points = []
    for pair in body.split(":"):
        coords = pair.split(",")
        try:
            points.append((float(coords[0]), float(coords[1])))
        except (ValueError, IndexError):
            continue
    return points
