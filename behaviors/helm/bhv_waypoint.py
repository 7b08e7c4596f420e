"""BHV_Waypoint: visit a list of points in order, steering toward a lead point on the current leg."""

from __future__ import annotations

import math
from typing import Any

from .behavior import Behavior, parse_bool, parse_float
from .cruise_speed import CruiseSpeed
from .errors import ParamError
from .flags import Flag
from .geometry import Point, fmt_num, perp_on_segment, project, rel_ang
from .ivp import ObjectiveFunction, zaic_peak, zaic_piece
from .point_strings import parse_point, parse_seglist
from .waypoint_engine import WaypointEngine


class WaypointBehavior(CruiseSpeed, Behavior):
    TYPE = "BHV_Waypoint"
    DEFAULT_NAME = "bhv_waypoint"
    DOMAIN_VARS = ("course", "speed")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.engine = WaypointEngine()
        self.engine.capture_radius = 3.0
        self.engine.slip_radius = 15.0
        self._init_cruise_speed()
        self.lead = -1.0
        self.lead_damper = -1.0
        self.lead_to_start = False
        self.order_reversed = False
        self.crs_pct = 50.0
        self.reset_on_idle = False
        self.wpt_flags: list[Flag] = []
        self.cycle_flags: list[Flag] = []
        self.wptflag_on_start = False
        self.var_status, self.var_index, self.var_cycle, self.suffix = "WPT_STAT", "WPT_INDEX", "CYCLE_INDEX", ""
        self.points_raw: list[Point] = []
        self.points_pending_start = False
        self._prevpt: Point | None = None
        self._markpt: Point | None = None
        self._wpt_flag_published = False
        self._last_index: int | None = None
        self._last_cycles: int | None = None
        self._trackpt: Point | None = None

    # ---- parameters ----------------------------------------------------------------------------
    def set_specific_param(self, param: str, value: str) -> bool:
        eng = self.engine
        if param in ("points", "polygon", "point"):
            if value.lower() == "start":
                self.points_pending_start = True
                self._set_points([])
            elif value.lower() == "empty":
                self._set_points([])
            else:
                self._set_points([parse_point(value)] if param == "point" else parse_seglist(value))
        elif self._set_cruise_speed_param(param, value):
            pass
        elif param in ("capture_radius", "radius"):
            eng.capture_radius = parse_float(value, param, low=0.0)
            if eng.capture_radius <= 0:
                raise ParamError(f"{param} must be > 0")
        elif param in ("slip_radius", "nm_radius"):
            eng.slip_radius = parse_float(value, param, low=0.0)
        elif param == "capture_line":
            if value.lower() == "absolute":
                eng.capture_line, eng.capture_radius, eng.slip_radius = True, 1e-9, 0.0
            else:
                eng.capture_line = parse_bool(value, param)
        elif param == "lead":
            self.lead = parse_float(value, param)
            if self.lead <= 0:
                self.lead = -1.0
        elif param == "lead_damper":
            self.lead_damper = parse_float(value, param, low=0.0)
        elif param == "lead_to_start":
            self.lead_to_start = parse_bool(value, param)
        elif param == "order":
            lowered = value.lower()
            if lowered not in ("normal", "reverse", "reversed", "toggle"):
                raise ParamError(f"order must be normal, reverse or toggle, not '{value}'")
            wanted = (not self.order_reversed) if lowered == "toggle" else lowered != "normal"
            if wanted != self.order_reversed:
                self.order_reversed = wanted
                self._apply_order()
        elif param == "repeat":
            if value.lower() == "forever":
                eng.repeat_forever, self.perpetual = True, True
            else:
                eng.repeat = int(parse_float(value, param, low=0.0))
                eng.repeat_forever = False
                if eng.repeat > 0:
                    self.perpetual = True
        elif param == "cycleflag":
            self.cycle_flags.append(Flag.parse(value))
        elif param == "wptflag":
            self.wpt_flags.append(Flag.parse(value))
        elif param == "wptflag_on_start":
            self.wptflag_on_start = parse_bool(value, param)
        elif param == "reset_on_idle":
            self.reset_on_idle = parse_bool(value, param)
        elif param in ("crs_spd_zaic_ratio", "patience"):
            self.crs_pct = parse_float(value, param, low=1.0, high=99.0)
        elif param in ("wpt_status", "wpt_status_var"):
            self.var_status = value
        elif param in ("wpt_index", "wpt_index_var"):
            self.var_index = value
        elif param == "cycle_index_var":
            self.var_cycle = value
        elif param == "post_suffix":
            self.suffix = "" if not value else (value if value.startswith("_") else "_" + value).upper()
        elif param == "currix":
            self.engine.set_index(int(parse_float(value, param, low=0.0)))
        elif param in ("ipf_type", "ipf-type"):
            if value.lower() != "zaic":
                raise ParamError(f"ipf_type '{value}' is not supported by this helm (only zaic)")
        elif param in ("efficiency_measure", "visual_hints"):
            if param == "efficiency_measure" and value.lower() not in ("all", "off"):
                raise ParamError(f"efficiency_measure must be all or off, not '{value}'")
        else:
            return False
        return True

    def _set_points(self, points: list[Point]) -> None:
        self.points_raw = points
        self._apply_order()
        self._prevpt = None
        self._markpt = None

    def _apply_order(self) -> None:
        pts = list(reversed(self.points_raw)) if self.order_reversed else list(self.points_raw)
        perpetual_state = (self.engine.repeat, self.engine.repeat_forever)
        self.engine.set_points(pts)
        self.engine.repeat, self.engine.repeat_forever = perpetual_state

    def on_set_param_complete(self) -> None:
        pts = ":".join(f"{fmt_num(x)},{fmt_num(y)}" for x, y in self.engine.points)
        self.post("BHV_SETTINGS", f"type=BHV_Waypoint,name={self.name},points={pts},speed={fmt_num(self.speed, 1)}",
                  repeatable=True)

    # ---- flags ---------------------------------------------------------------------------------
    def _post_wpt_flags(self, reached: Point, nxt: Point) -> None:
        """pHelmIvP 19.8.1's ``postWptFlags(x, y)``: ``$(X)``/``$(Y)`` (or ``$[X]``/``$[Y]``) are the waypoint just
        reached, ``$(NX)``/``$(NY)`` (or bracketed) the next one, at most 2 decimals; nothing else is expanded
        (``$(PX)``, ``$(NI)``, ``$[OWNSHIP]``... post as written). Posted every time (repeatable)."""
        xs, ys, nxs, nys = (fmt_num(v, 2) for v in (*reached, *nxt))
        macros = {"$(X)": xs, "$(Y)": ys, "$[X]": xs, "$[Y]": ys,
                  "$(NX)": nxs, "$(NY)": nys, "$[NX]": nxs, "$[NY]": nys}
        for flag in self.wpt_flags:
            if flag.condition is None or flag.condition.evaluate(self.info.get):
                self.post(flag.var, flag.value(macros), repeatable=True)

    # ---- states --------------------------------------------------------------------------------
    def on_run_to_idle_state(self) -> None:
        if self.reset_on_idle:
            self.engine.reset_for_new_traversal()
        self.engine.reset_cpa()
        self.post("VIEW_POINT", f"x=0,y=0,active=false,label={self.ownship}_wpt", key="wpt")

    def on_run_state(self) -> ObjectiveFunction | None:
        nav = self.nav()
        if self.points_pending_start and nav is not None:
            self.points_pending_start = False
            self._set_points([(nav[0], nav[1])])
        eng = self.engine
        if not eng.points or nav is None:
            return None
        osx, osy, osh, _ = nav
        eng.perpetual = self.perpetual
        this_pt = eng.target
        if self._prevpt is None:
            self._prevpt = (osx, osy)
        eng.prevpt = self._prevpt
        result = eng.step(osx, osy)
        hit = result in ("advanced", "cycled", "completed")
        if result in ("completed", "cycled"):
            self.post(self.var_status + self.suffix, f"behavior-name={self.name},{result}")
            for flag in self.cycle_flags:  # 19.8.1's postCycleFlags: posted as written, no macro expanded
                if flag.condition is None or flag.condition.evaluate(self.info.get):
                    self.post(flag.var, flag.value({}), repeatable=True)
        if result == "completed":
            # 19.8.1 posts twice on completion: setNextWaypoint with the engine's point after its reset (the
            # first waypoint) and the next point left as it was (the last one), then onRunState with the
            # waypoint just reached, because the engine's point moved.
            self._post_wpt_flags(eng.target, this_pt)
            if eng.target != this_pt:
                self._prevpt = this_pt
                self._post_wpt_flags(this_pt, this_pt)
            self._wpt_flag_published = True
        elif eng.target != this_pt or hit or (self.wptflag_on_start and not self._wpt_flag_published):
            self._prevpt = this_pt
            self._post_wpt_flags(this_pt, eng.target)
            self._wpt_flag_published = True
        if eng.cycle_count != self._last_cycles and self.var_cycle.lower() != "silent":
            self.post(self.var_cycle + self.suffix, float(eng.cycle_count))
            self._last_cycles = eng.cycle_count
        if result == "completed":
            self.set_complete()
            if self.perpetual:
                eng.reset_for_new_traversal()
            return None
        if eng.index != self._last_index and self.var_index.lower() != "silent":
            self.post(self.var_index + self.suffix, float(eng.index))
            self._last_index = eng.index
        track = self._track_point(osx, osy)
        self._trackpt = track
        self._post_status(osx, osy)
        self.post("VIEW_POINT", f"x={fmt_num(eng.target[0], 1)},y={fmt_num(eng.target[1], 1)},"
                                f"label={self.ownship}_wpt", key="wpt")
        return self._build_of(rel_ang(osx, osy, track[0], track[1]), osh)

    def _track_point(self, osx: float, osy: float) -> Point:
        eng = self.engine
        nxt = eng.target
        if self.lead < 0:
            return nxt
        anchor: Point | None = None
        if eng.index > 0:
            anchor = eng.points[eng.index - 1]
        elif eng.cycle_count > 0:
            anchor = eng.points[-1]
        elif self.lead_to_start:
            if self._markpt is None:
                self._markpt = (osx, osy)
            anchor = self._markpt
        if anchor is None:
            return nxt
        perp = perp_on_segment(osx, osy, anchor, nxt)
        damper = 1.0
        if self.lead_damper > 0:
            off = math.hypot(perp[0] - osx, perp[1] - osy)
            if off < self.lead_damper:
                damper += 2 * (1 - off / self.lead_damper)
        dist = min(math.hypot(nxt[0] - perp[0], nxt[1] - perp[1]), self.lead * damper)
        return project(perp[0], perp[1], rel_ang(anchor[0], anchor[1], nxt[0], nxt[1]), dist)

    def _post_status(self, osx: float, osy: float) -> None:
        if self.var_status.lower() == "silent":
            return
        eng = self.engine
        dist = math.hypot(osx - eng.target[0], osy - eng.target[1])
        speed = self.cruise_speed()
        eta = f"{dist / speed:.0f}" if speed > 0 else "inf"
        self.post(self.var_status + self.suffix,
                  f"vname={self.ownship},behavior-name={self.name},index={eng.index},"
                  f"hits={eng.capture_hits}/{eng.total_hits},cycles={eng.cycle_count},dist={dist:.0f},eta={eta}")

    def _build_of(self, bearing: float, heading: float) -> ObjectiveFunction:
        course, speed = self.domain.vars["course"], self.domain.vars["speed"]
        cruise = self.cruise_speed()
        spd = zaic_piece(speed, cruise, cruise / 2, 1.6, 20, 0, 100)
        to_target = zaic_peak(course, bearing, 0, 180, 0, 0, 100, wrap=True)
        keep_heading = zaic_peak(course, heading, 30, 180, 5, 0, 20, wrap=True)
        crs = [a + b for a, b in zip(to_target, keep_heading, strict=True)]
        return ObjectiveFunction.coupled(self.pwt, "course", crs, self.crs_pct, "speed", spd, 100 - self.crs_pct)
