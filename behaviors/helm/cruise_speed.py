"""The cruise-speed parameters BHV_Waypoint and BHV_Loiter share (``speed``, ``speed_alt``, ``use_alt_speed``)."""

from __future__ import annotations

from .behavior import parse_bool, parse_float
from .ivp import IvPDomain


class CruiseSpeed:
    """Mixin for a behaviour that travels at a set speed, with MOOS-IvP's alternate speed switch."""

    domain: IvPDomain

    def _init_cruise_speed(self) -> None:
        self.speed = 0.0
        self.speed_alt = -1.0
        self.use_alt_speed = False

    def _set_cruise_speed_param(self, param: str, value: str) -> bool:
        """Handle ``speed``/``speed_alt``/``use_alt_speed``; False for any other parameter."""
        if param == "speed":
            self.speed = parse_float(value, param, low=0.0)
        elif param == "speed_alt":
            self.speed_alt = parse_float(value, param)
        elif param == "use_alt_speed":
            self.use_alt_speed = parse_bool(value, param)
        else:
            return False
        return True

    def cruise_speed(self) -> float:
        """``speed_alt`` when switched on and set, else ``speed``; never above the speed domain's top."""
        speed = self.speed_alt if self.use_alt_speed and self.speed_alt >= 0 else self.speed
        return min(speed, self.domain.vars["speed"].high) if self.domain.has("speed") else speed
