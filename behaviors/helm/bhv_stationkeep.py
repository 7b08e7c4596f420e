"""BHV_StationKeep: hold a point, slowing down inside the outer ring and stopping inside the inner one."""

from __future__ import annotations

import math
from typing import Any

from .behavior import Behavior, parse_bool, parse_float
from .errors import ParamError
from .geometry import Point, fmt_num, rel_ang
from .ivp import ObjectiveFunction, zaic_piece
from .point_strings import parse_point


class StationKeepBehavior(Behavior):
    TYPE = "BHV_StationKeep"
    DEFAULT_NAME = "bhv_stationkeep"
    DOMAIN_VARS = ("course", "speed")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.station: Point | None = None
        self.center_activate = False
        self.inner_radius = 4.0
        self.outer_radius = 15.0
        self.outer_speed = 1.2
        self.transit_speed = 2.5
        self.swing_time = 0.0
        self._center_pending = False
        self._run_start: float | None = None
        self.mode = "DISABLED"

    def set_specific_param(self, param: str, value: str) -> bool:
        if param in ("station_pt", "point"):
            self.station = parse_point(value)
        elif param == "center_activate":
            self.center_activate = parse_bool(value, param)
        elif param in ("inner_radius", "outer_radius", "outer_speed"):
            setattr(self, param, parse_float(value, param, low=0.0))
        elif param in ("transit_speed", "extra_speed"):
            self.transit_speed = parse_float(value, param, low=0.0)
        elif param == "swing_time":
            self.swing_time = parse_float(value, param, low=0.0, high=60.0)
        elif param == "hibernation_radius":
            if value.lower() not in ("off", "-1"):
                raise ParamError("hibernation_radius is not supported by this helm (only off)")
        elif param == "visual_hints":
            pass
        else:
            return False
        if self.outer_radius < self.inner_radius:
            self.outer_radius = self.inner_radius
        return True

    def on_idle_state(self) -> None:
        if self.center_activate:
            self._center_pending = True
        self._run_start = None

    def on_run_state(self) -> ObjectiveFunction | None:
        nav = self.nav()
        if nav is None:
            return None
        osx, osy, osh, _ = nav
        if self._run_start is None:
            self._run_start = self.now
        swinging = self.center_activate and self.now - self._run_start < self.swing_time
        if self._center_pending or swinging or (self.center_activate and self.station is None):
            self.station = (osx, osy)
            self._center_pending = False
        if self.station is None:
            self.post("BHV_WARNING", "STATION_POINT_NOT_SET", key="nostation")
            return None
        sx, sy = self.station
        dist = math.hypot(osx - sx, osy - sy)
        if dist <= self.inner_radius:
            speed = 0.0
        elif dist >= self.outer_radius:
            speed = self.transit_speed
        else:
            speed = self.outer_speed * (dist - self.inner_radius) / (self.outer_radius - self.inner_radius)
        course = osh if swinging else rel_ang(osx, osy, sx, sy)
        self.mode = "SEEKING_STATION"
        self.post("DIST_TO_STATION", round(dist, 1))
        self.post("PSKEEP_MODE", self.mode)
        for label, radius in (("out", self.outer_radius), ("in", self.inner_radius)):
            self.post("VIEW_POLYGON", f"radial:: x={fmt_num(sx)},y={fmt_num(sy)},radius={fmt_num(radius)},pts=32,"
                                      f"label={self.ownship}:station-keep-{label}", key=label)
        dom_s, dom_c = self.domain.vars["speed"], self.domain.vars["course"]
        spd = zaic_piece(dom_s, min(speed, dom_s.high), 0, 0.4, 0, 0, 25)
        crs = zaic_piece(dom_c, course, 0, 180, 0, 0, 100, wrap=True)
        return ObjectiveFunction.coupled(self.pwt, "course", crs, 50, "speed", spd, 50)
