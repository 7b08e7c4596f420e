"""BHV_Loiter: go round a convex polygon in a set direction, acquiring it from outside first."""

from __future__ import annotations

import math
from typing import Any

from .behavior import Behavior, parse_bool, parse_float
from .cruise_speed import CruiseSpeed
from .errors import ParamError
from .geometry import Polygon, fmt_num, rel_ang, segment_angle
from .ivp import ObjectiveFunction, zaic_piece
from .point_strings import parse_point, parse_polygon
from .waypoint_engine import WaypointEngine


class LoiterBehavior(CruiseSpeed, Behavior):
    TYPE = "BHV_Loiter"
    DEFAULT_NAME = "bhv_loiter"
    DOMAIN_VARS = ("course", "speed")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.polygon: Polygon | None = None
        self.polygon_spec = ""
        self.clockwise = True
        self.clockwise_best = False
        self._init_cruise_speed()
        self.acquire_dist = 10.0
        self.center_activate = False
        self.patience = 50.0
        self.spiral_factor = -2.0
        self.suffix = ""
        self.engine = WaypointEngine()
        self.engine.perpetual, self.engine.repeat_forever = True, True
        self.loiter_mode = "idle"
        self.acquire_mode = False
        self._center_pending: str | None = None
        self._ptx = self._pty = 0.0

    def set_specific_param(self, param: str, value: str) -> bool:
        if param == "polygon":
            poly = parse_polygon(value)
            self.polygon = Polygon([(round(x, 1), round(y, 1)) for x, y in poly.vertices])
            self.polygon_spec = value
            self._apply_direction()
        elif param == "clockwise":
            if value.lower() == "best":
                self.clockwise_best = True
            else:
                self.clockwise_best = False
                self.clockwise = parse_bool(value, param)
                self._apply_direction()
        elif self._set_cruise_speed_param(param, value):
            pass
        elif param in ("capture_radius", "radius"):
            self.engine.capture_radius = parse_float(value, param, low=0.0)
        elif param in ("slip_radius", "nm_radius"):
            self.engine.slip_radius = parse_float(value, param, low=0.0)
        elif param in ("acquire_dist", "acquire_distance"):
            self.acquire_dist = parse_float(value, param, low=0.0)
        elif param == "center_activate":
            self.center_activate = parse_bool(value, param)
        elif param == "center_assign":
            self._assign_center(value)
        elif param in ("xcenter_assign", "ycenter_assign"):
            self._assign_center(f"{param[0]}={value}")
        elif param == "mod_poly_rad":
            self._mod_radius(parse_float(value, param))
        elif param == "patience":
            self.patience = parse_float(value, param, low=1.0, high=99.0)
        elif param == "spiral_factor":
            pct = parse_float(value, param, low=0.0, high=100.0) / 100.0
            self.spiral_factor = -75 + pct * 74
        elif param == "post_suffix":
            self.suffix = "_" + value.upper() if value else ""
        elif param == "ipf_type":
            if value.lower() != "zaic":
                raise ParamError(f"ipf_type '{value}' is not supported by this helm (only zaic)")
        elif param == "visual_hints":
            pass  # display only
        else:
            return False
        return True

    def check_config(self) -> None:
        super().check_config()
        if self.polygon is None:
            raise ParamError("BHV_Loiter needs a polygon")

    def _apply_direction(self) -> None:
        """Order the vertices in the loiter direction; a new polygon or direction re-enters acquire mode."""
        if self.polygon is None:
            return
        if self.polygon.is_clockwise() != self.clockwise:
            self.polygon = self.polygon.reversed()
        self.engine.set_points(self.polygon.vertices)
        self.acquire_mode = True

    def _set_center(self, cx: float, cy: float) -> None:
        if self.polygon is None:
            return
        ox, oy = self.polygon.center()
        self.polygon = self.polygon.moved_to(cx, cy)
        self.engine.translate(cx - ox, cy - oy)

    def _assign_center(self, value: str) -> None:
        """``present_position`` waits for the next run; ``x,y`` and ``x=..,y=..`` apply at once."""
        if value.strip().lower() == "present_position":
            self._center_pending = "present_position"
            return
        if self.polygon is None:
            raise ParamError("center_assign before a polygon is set")
        cx, cy = self.polygon.center()
        if "=" in value:
            for part in value.split(","):
                key, _, num = part.partition("=")
                key = key.strip().lower()
                if key not in ("x", "y"):
                    raise ParamError(f"center_assign: unknown key '{key}'")
                if key == "x":
                    cx = parse_float(num, "center x")
                else:
                    cy = parse_float(num, "center y")
        else:
            cx, cy = parse_point(value)
        self._set_center(cx, cy)

    def _mod_radius(self, amount: float) -> None:
        if self.polygon is None:
            raise ParamError("mod_poly_rad before a polygon is set")
        cx, cy = self.polygon.center()
        radius = self.polygon.max_radius()
        scale = max(radius + amount, 5.0) / radius
        self.polygon = Polygon([(cx + (x - cx) * scale, cy + (y - cy) * scale) for x, y in self.polygon.vertices])
        index = self.engine.index
        self.engine.set_points(self.polygon.vertices)
        self.engine.set_index(index)

    def on_set_param_complete(self) -> None:
        if self.polygon is None:
            return
        cx, cy = self.polygon.center()
        self.post("BHV_SETTINGS", f"type=BHV_Loiter,name={self.name},x={fmt_num(cx)},y={fmt_num(cy)},"
                                  f"clockwise={str(self.clockwise).lower()},"
                                  f"dynamic_clockwise={str(self.clockwise_best).lower()},"
                                  f"center_activate={str(self.center_activate).lower()},"
                                  f"desired_speed={fmt_num(self.cruise_speed())},"
                                  f"polygon=\"{self.polygon.spec()}\"", repeatable=True)

    # ---- states --------------------------------------------------------------------------------
    def on_idle_state(self) -> None:
        self.loiter_mode = "idle"
        self._post_status(None)
        if self.center_activate:
            self._center_pending = "present_position"

    def on_idle_to_run_state(self) -> None:
        if self.clockwise_best:
            nav = self.nav()
            if nav is not None and self.polygon is not None and not self.polygon.contains(nav[0], nav[1]):
                cw = self._acquire_outside(nav[0], nav[1], True)
                ccw = self._acquire_outside(nav[0], nav[1], False)
                d_cw = abs((nav[2] - rel_ang(nav[0], nav[1], *self.polygon.vertices[cw]) + 180) % 360 - 180)
                d_ccw = abs((nav[2] - rel_ang(nav[0], nav[1], *self.polygon.vertices[ccw]) + 180) % 360 - 180)
                self.clockwise = d_cw < d_ccw
                self._apply_direction()

    def on_run_state(self) -> ObjectiveFunction | None:
        nav = self.nav()
        if nav is None or self.polygon is None:
            return None
        osx, osy, osh, _ = nav
        if self._center_pending == "present_position":
            self._set_center(osx, osy)
        self._center_pending = None
        dist = self.polygon.signed_dist(osx, osy)
        self._update_mode(dist)
        self.acquire_mode = dist > self.acquire_dist
        if self.acquire_mode:
            self.engine.set_index(self._acquire_vertex(osh, osx, osy))
        self.engine.prevpt = None
        result = self.engine.step(osx, osy)
        if result in ("advanced", "cycled"):
            self.acquire_mode = False
        self._ptx, self._pty = self.engine.target
        self.post("LOITER_DIST_TO_VERT", round(math.hypot(osx - self._ptx, osy - self._pty), 2))
        self._post_status(dist)
        self.post("VIEW_POLYGON", f"{self.polygon.spec()},label={self.ownship}_{self.name}")
        course, speed = self.domain.vars["course"], self.domain.vars["speed"]
        spd = zaic_piece(speed, self.cruise_speed(), 0, 0.3, 0, 0, 100)
        crs = zaic_piece(course, rel_ang(osx, osy, self._ptx, self._pty), 0, 180, 0, 0, 100, wrap=True)
        return ObjectiveFunction.coupled(self.pwt, "course", crs, self.patience, "speed", spd, 100 - self.patience)

    def _update_mode(self, dist: float) -> None:
        if abs(dist) <= self.acquire_dist:
            self.loiter_mode = "stable"
        elif dist > 0:
            self.loiter_mode = ("recovering_external" if self.loiter_mode in ("stable", "recovering_external")
                                else "acquiring_external")
        else:
            self.loiter_mode = ("recovering_internal" if self.loiter_mode in ("stable", "recovering_internal")
                                else "acquiring_internal")

    def _acquire_vertex(self, osh: float, osx: float, osy: float) -> int:
        assert self.polygon is not None
        if self.polygon.contains(osx, osy):
            return self._acquire_inside(osh, osx, osy)
        return self._acquire_outside(osx, osy, self.clockwise)

    def _acquire_outside(self, osx: float, osy: float, clockwise: bool) -> int:
        """Among visible vertices, the one whose onward turn is largest (clockwise) or smallest."""
        assert self.polygon is not None
        verts = self.polygon.vertices
        best_index, best_angle = 0, None
        for i, (vx, vy) in enumerate(verts):
            if not self.polygon.vertex_visible(i, osx, osy):
                continue
            nx, ny = verts[(i + 1) % len(verts)]
            angle = segment_angle(osx, osy, vx, vy, nx, ny)
            if best_angle is None or (angle > best_angle if clockwise else angle < best_angle):
                best_index, best_angle = i, angle
        return best_index

    def _acquire_inside(self, osh: float, osx: float, osy: float) -> int:
        assert self.polygon is not None
        verts = self.polygon.vertices
        ahead = min(range(len(verts)), key=lambda i: abs(osh % 360 - rel_ang(osx, osy, *verts[i])))
        scores = [abs(segment_angle(osx, osy, *verts[i], *verts[(i + 1) % len(verts)])) for i in range(len(verts))]
        scores[ahead] += self.spiral_factor
        return min(range(len(verts)), key=lambda i: scores[i])

    def _post_status(self, dist: float | None) -> None:
        eng, sfx = self.engine, self.suffix
        self.post("LOITER_REPORT" + sfx, f"index={eng.index},capture_hits={eng.capture_hits},"
                                         f"nonmono_hits={eng.nonmono_hits},acquire_mode={str(self.acquire_mode).lower()}")
        self.post("LOITER_INDEX" + sfx, float(eng.index))
        self.post("LOITER_MODE" + sfx, self.loiter_mode)
        self.post("LOITER_ACQUIRE" + sfx, 1.0 if self.acquire_mode else 0.0)
        if dist is not None:
            self.post("LOITER_DIST_TO_POLY" + sfx, float(round(dist)) if dist > 10 else round(dist, 2))
            speed = self.cruise_speed()
            if speed > 0:
                self.post("LOITER_ETA_TO_POLY" + sfx, round(max(dist, 0.0) / speed, 2))
