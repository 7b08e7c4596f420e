"""BHV_Trail (pHelmIvP 19.8.1): keep station at ``trail_range`` metres and ``trail_angle`` degrees from a contact.

The trail point is the (extrapolated) contact position projected ``trail_range`` metres along ``trail_angle``,
relative to the contact's heading (``trail_angle_type = relative``) or absolute. Then, by ownship's distance ``d``
to the trail point:

- ``d > nm_radius``: "Outside nm_radius": close on the moving trail point (AOF_CutRangeCPA, coupled course/speed);
- ``radius < d <= nm_radius``: "Inside nm_radius": steer for the point ``nm_radius`` ahead of the trail point and
  match the contact's speed, less when ahead of the trail point and more when behind;
- ``d <= radius``: "Inside radius": the contact's heading and speed.

No function when the contact is unknown (BHV_ERROR with ``on_no_contact_ok = false``) or, with ``extrapolate``, when
its last report is older than the decay end.
"""

from __future__ import annotations

import math
from typing import Any

from .aof_cut_range import cut_range_table
from .behavior import parse_bool, parse_float
from .bhv_contact import ContactBehavior
from .errors import ParamError
from .geometry import angle180, fmt_num, project, rel_ang
from .ivp import ObjectiveFunction, zaic_piece


def _int_value(value: float) -> float:
    """pHelmIvP's postIntMessage rounding: ``(int)(value + 0.5)``, posted as a double."""
    return float(int(value + 0.5))


def _snap(value: float, step: float) -> float:
    """MBUtils' snapToStep: to the nearest multiple of ``step``, halves away from zero."""
    scaled = value / step
    return float(int(scaled - 0.5) if scaled < 0 else int(scaled + 0.5)) * step


class TrailBehavior(ContactBehavior):
    TYPE = "BHV_Trail"
    DEFAULT_NAME = "(d)trail"
    DOMAIN_VARS = ("course", "speed")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.trail_range = 50.0
        self.trail_angle = 180.0
        self.radius = 5.0
        self.nm_radius = 20.0
        self.pwt_outer_dist = 0.0
        self.angle_relative = True
        self.post_trail_dist_on_idle = True
        self.no_alert_request = False  # read but unused, as in 19.8.1 (its alert request is compiled out)
        self.trail_x = self.trail_y = 0.0

    def set_specific_param(self, param: str, value: str) -> bool:
        if super().set_specific_param(param, value):
            return True
        if param in ("nm_radius", "radius", "trail_range"):
            setattr(self, param, parse_float(value, param, low=0.0))
        elif param == "no_alert_request":
            self.no_alert_request = parse_bool(value, param)
        elif param in ("post_trail_dist_on_idle", "post_trail_distance_on_idle"):
            self.post_trail_dist_on_idle = parse_bool(value, param)
        elif param in ("pwt_outer_dist", "max_range"):  # max_range: the deprecated name
            self.pwt_outer_dist = parse_float(value, param, low=0.0)
        elif param == "trail_angle":
            self.trail_angle = angle180(parse_float(value, param))
        elif param == "trail_angle_type":
            if value.lower() not in ("absolute", "relative"):
                raise ParamError(f"trail_angle_type must be relative or absolute, not '{value}'")
            self.angle_relative = value.lower() == "relative"
        else:
            return False
        return True

    # ---- states --------------------------------------------------------------------------------
    def on_run_state(self) -> ObjectiveFunction | None:
        if not self.update_platform_info():
            return None
        if self.extrapolate and self.extrapolator.decay_maxed:
            return None
        self._calculate_trail_point()
        self._post_trail_point(active=True)
        relevance = self._relevance()
        self.post("TRAIL_RELEVANCE", relevance, repeatable=True)
        self.cnh %= 360.0
        self.post("TRAIL_CTR", 1.0, repeatable=True)
        if relevance <= 0:
            self.post("PURSUIT", 0.0)
            return None
        self.post("PURSUIT", 1.0)
        distance = self._update_trail_distance()
        pwt = relevance * self.pwt
        if distance > self.radius and distance > self.nm_radius:
            self.post("REGION", "Outside nm_radius")
            rows = cut_range_table(self.domain, self.osx, self.osy, self.trail_x, self.trail_y, self.cnh, self.cnv,
                                   self.time_on_leg)
            if rows is None:
                self.post_warning("Error in initializing AOF_CutRangeCPA.")
                return None
            return ObjectiveFunction.table(pwt, "course", "speed", rows)
        if distance > self.radius:
            self.post("REGION", "Inside nm_radius")
            return self._inside_nm_radius(pwt)
        self.post("REGION", "Inside radius")
        speed = self.cnv if self.cnv >= 0 and self.extrapolate else 0.0
        self.post("TRAIL_SPEED", speed)
        return self._course_speed(pwt, self.cnh, speed)

    def on_run_to_idle_state(self) -> None:
        self.post("PURSUIT", 0.0)
        self._post_trail_point(active=False)

    def on_idle_state(self) -> None:
        self.update_platform_info()
        self._calculate_trail_point()
        if self.post_trail_dist_on_idle:
            self._update_trail_distance()

    # ---- internals -----------------------------------------------------------------------------
    def _inside_nm_radius(self, pwt: float) -> ObjectiveFunction:
        """Head for the point nm_radius ahead of the trail point; slow down when ahead of it, speed up behind."""
        head_x, head_y = math.sin(math.radians(self.cnh)), math.cos(math.radians(self.cnh))
        ahead_by = head_x * (self.osx - self.trail_x) + head_y * (self.osy - self.trail_y)
        aim_x, aim_y = self.trail_x + head_x * self.nm_radius, self.trail_y + head_y * self.nm_radius
        heading = rel_ang(self.osx, self.osy, aim_x, aim_y)
        self.post("TRAIL_HEADING", _int_value(heading))
        speed = self.cnv * (1 - 0.5 * ahead_by / self.nm_radius)
        if speed < 0 or not self.extrapolate:
            speed = 0.0
        self.post("TRAIL_SPEED", _snap(speed, 0.1))
        return self._course_speed(pwt, heading, speed)

    def _course_speed(self, pwt: float, heading: float, speed: float) -> ObjectiveFunction:
        """ZAIC_PEAK on course (peak 30, base 150, summit delta 50) and on speed (0.1, 2.0, 50), coupled 50/50."""
        course = zaic_piece(self.domain.vars["course"], heading, 30, 150, 50, 0, 100, wrap=True)
        speeds = zaic_piece(self.domain.vars["speed"], speed, 0.1, 2.0, 50, 0, 100)
        return ObjectiveFunction.coupled(pwt, "course", course, 50, "speed", speeds, 50)

    def _calculate_trail_point(self) -> None:
        angle = (self.cnh + self.trail_angle) % 360.0 if self.angle_relative else self.trail_angle
        self.trail_x, self.trail_y = project(self.cnx, self.cny, angle, self.trail_range)

    def _relevance(self) -> float:
        if self.pwt_outer_dist == 0:
            return 1.0
        self.post("TRAIL_RANGE", _int_value(self.contact_range))
        self.post("MAX_RANGE", _int_value(self.pwt_outer_dist))
        return 1.0 if self.contact_range < self.pwt_outer_dist else 0.0

    def _update_trail_distance(self) -> float:
        distance = math.hypot(self.osx - self.trail_x, self.osy - self.trail_y)
        self.post("TRAIL_DISTANCE", _int_value(distance))
        return distance

    def _post_trail_point(self, active: bool) -> None:
        """VIEW_POINT as XYPoint::get_spec writes it (2 decimals; ``active=false`` only when erasing)."""
        state = "" if active else "active=false,"
        self.post("VIEW_POINT", f"x={fmt_num(self.trail_x, 2)},y={fmt_num(self.trail_y, 2)},{state}"
                                f"label={self.ownship}_trailpoint")
