"""Point lists and polygons written as MOOS-IvP strings (XYFormatUtils): ``pts={..}``, ``x,y:x,y``, ``radial::``."""

from __future__ import annotations

import math

from .errors import ParamError
from .geometry import Point, Polygon, project
from .logic import is_number

MAX_POINTS = 10_000
"""Most vertices a polygon or waypoint list may have (``radial:: pts=`` included).  pHelmIvP builds whatever is
asked (``pts=100000000`` is 100 million vertices, gigabytes); a mission needs tens, so more is a bad parameter."""


def _check_count(count: int, text: str) -> None:
    if count > MAX_POINTS:
        raise ParamError(f"'{text[:80]}' asks for {count} points; at most {MAX_POINTS} are allowed")

_DISPLAY_KEYS = {
    "label", "label_color", "edge_color", "vertex_color", "vertex_size", "edge_size", "active", "msg",
    "source", "type", "time", "duration", "fill_color", "fill_transparency", "comment",
}


def _pairs(body: str) -> list[Point]:
    """``x1,y1:x2,y2`` (or ``x=1,y=2:...``) into points; ``label,foo`` elements are display-only."""
    points: list[Point] = []
    for element in body.split(":"):
        element = element.strip()
        if not element:
            continue
        fields = [f.strip() for f in element.split(",")]
        if fields[0].lower() in _DISPLAY_KEYS:
            continue
        if "=" in element:
            kv = dict(f.split("=", 1) for f in fields if "=" in f)
            kv = {k.strip().lower(): v.strip() for k, v in kv.items()}
            if not (is_number(kv.get("x", "")) and is_number(kv.get("y", ""))):
                raise ParamError(f"bad vertex '{element}'")
            points.append((float(kv["x"]), float(kv["y"])))
            continue
        if len(fields) < 2 or not (is_number(fields[0]) and is_number(fields[1])):
            raise ParamError(f"bad vertex '{element}'")
        points.append((float(fields[0]), float(fields[1])))
    return points


def parse_point(text: str) -> Point:
    """One point: ``x,y``, ``x:y`` or ``x=..,y=..``."""
    text = text.strip()
    if "=" in text:
        pts = _pairs(text)
    else:
        pts = _pairs(text.replace(":", ",")) if text.count(":") == 1 and "," not in text else _pairs(text)
    if len(pts) != 1:
        raise ParamError(f"'{text}' is not one point")
    return pts[0]


def parse_seglist(text: str) -> list[Point]:
    """A waypoint list: the standard, abbreviated or polygon forms (polygons keep their vertex order)."""
    text = text.strip()
    lowered = text.lower()
    if lowered.startswith("pts=") or lowered.startswith("points="):
        body = text.split("=", 1)[1].strip()
        close = body.find("}")
        if not body.startswith("{") or close < 0:
            raise ParamError(f"'{text}': expected pts={{x,y:x,y...}}")
        points = _pairs(body[1:close])
    elif lowered.startswith(("radial", "format=")):
        points = parse_polygon(text).vertices
    elif lowered.startswith(("zigzag", "lawnmower", "bowtie", "ellipse", "wedge", "piewedge", "oval", "pylon")):
        raise ParamError(f"'{text.split(':')[0].split(',')[0]}' point patterns are not supported by this helm")
    else:
        points = _pairs(text)
    if not points:
        raise ParamError(f"'{text}' holds no points")
    _check_count(len(points), text)
    return points


def parse_polygon(text: str) -> Polygon:
    """A convex polygon from any supported form; raises ParamError naming what is wrong."""
    text = text.strip()
    lowered = text.lower()
    if lowered.startswith("radial::"):
        poly = _radial_keyed(text[len("radial::"):])
    elif lowered.startswith("format=radial"):
        poly = _radial_keyed(text.split(",", 1)[1] if "," in text else "")
    elif lowered.startswith("format="):
        raise ParamError(f"polygon {text.split(',')[0]} is not supported by this helm")
    elif lowered.startswith("radial:"):
        poly = _radial_short(text[len("radial:"):])
    elif lowered.split(":")[0] in ("ellipse", "wedge", "piewedge", "rangewedge", "pylon", "oval"):
        raise ParamError(f"polygon format '{lowered.split(':')[0]}' is not supported by this helm")
    else:
        poly = Polygon(parse_seglist(text))
    if not poly.is_convex():
        raise ParamError(f"polygon '{text}' is not convex")
    return poly


def _radial(x: float, y: float, radius: float, pts: float, snap: float | None) -> Polygon:
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(radius) and radius > 0
            and 3 <= pts <= MAX_POINTS):
        raise ParamError(f"radial polygon needs finite x, y, radius > 0 and 3 <= pts <= {MAX_POINTS} "
                         f"(got x={x:g}, y={y:g}, radius={radius:g}, pts={pts:g})")
    pts = int(pts)
    delta = 360.0 / pts
    vertices = [project(x, y, delta / 2 + k * delta, radius) for k in range(pts)]
    poly = Polygon(vertices)
    if snap and snap > 0:
        snapped = Polygon([(math.floor(vx / snap + 0.5) * snap, math.floor(vy / snap + 0.5) * snap)
                           for vx, vy in vertices])
        if snapped.is_convex():
            poly = snapped
    return poly


def _radial_keyed(body: str) -> Polygon:
    values: dict[str, str] = {}
    for field in body.split(","):
        field = field.strip()
        if not field:
            continue
        key, sep, value = field.partition("=")
        key = key.strip().lower()
        if not sep:
            raise ParamError(f"radial polygon: '{field}' is not key=value")
        if key in _DISPLAY_KEYS:
            continue
        if key not in ("x", "y", "z", "radius", "pts", "snap", "shiftx", "shifty"):
            raise ParamError(f"radial polygon: unknown key '{key}'")
        if not is_number(value):
            raise ParamError(f"radial polygon: '{field}' is not a number")
        values[key] = value.strip()
    missing = [k for k in ("x", "y", "radius", "pts") if k not in values]
    if missing:
        raise ParamError(f"radial polygon: missing {', '.join(missing)}")
    x = float(values["x"]) + float(values.get("shiftx", 0))
    y = float(values["y"]) + float(values.get("shifty", 0))
    snap = float(values["snap"]) if "snap" in values else None
    return _radial(x, y, float(values["radius"]), float(values["pts"]), snap)


def _radial_short(body: str) -> Polygon:
    fields = [f.strip() for f in body.split(",")]
    if len(fields) < 4 or not all(is_number(f) for f in fields[:4]):
        raise ParamError(f"radial: expects x, y, radius, pts[, snap] (got '{body}')")
    snap = float(fields[4]) if len(fields) > 4 and is_number(fields[4]) else None
    return _radial(float(fields[0]), float(fields[1]), float(fields[2]), float(fields[3]), snap)
