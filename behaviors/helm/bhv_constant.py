"""BHV_ConstantSpeed, BHV_ConstantHeading, BHV_ConstantDepth: one ZAIC_PEAK on one decision variable.

All three default to ``duration = 0`` as in pHelmIvP: without a duration they complete on their first
runnable iteration.
"""

from __future__ import annotations

from typing import Any

from .behavior import Behavior, parse_float
from .ivp import ObjectiveFunction, zaic_piece


class _ConstantBehavior(Behavior):
    VAR = ""
    NAV_VAR = ""
    PARAM = ""
    DEFAULT_DURATION = 0.0
    WRAP = False
    PEAK, BASE, SUMMIT_DELTA = 0.0, 0.0, 0.0

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.desired = 0.0
        self.peakwidth, self.basewidth, self.summitdelta = self.PEAK, self.BASE, self.SUMMIT_DELTA
        self.mismatch_var = ""

    def set_specific_param(self, param: str, value: str) -> bool:
        if param == self.PARAM:
            self.desired = parse_float(value, param)
        elif param in ("peakwidth", "basewidth", "summitdelta"):
            setattr(self, param, parse_float(value, param, low=0.0))
        elif param == f"{self.PARAM}_mismatch_var":
            self.mismatch_var = value
        else:
            return False
        return True

    def summit(self) -> float:
        return self.desired

    def on_run_state(self) -> ObjectiveFunction | None:
        var = self.domain.vars[self.VAR]
        if self.mismatch_var:
            actual = self.info.get_double(self.NAV_VAR)
            if actual is not None:
                error = abs(actual - self.desired)
                self.post(self.mismatch_var, round(min(error, 360 - error) if self.WRAP else error, 2))
        utilities = zaic_piece(var, self.summit(), self.peakwidth, self.basewidth, self.summitdelta,
                              0, 100, wrap=self.WRAP)
        return ObjectiveFunction.single(self.pwt, self.VAR, utilities)


class ConstantSpeedBehavior(_ConstantBehavior):
    TYPE, DEFAULT_NAME, DOMAIN_VARS = "BHV_ConstantSpeed", "bhv_constant_speed", ("speed",)
    VAR, NAV_VAR, PARAM = "speed", "NAV_SPEED", "speed"
    PEAK, BASE, SUMMIT_DELTA = 0.0, 0.2, 0.0


class ConstantHeadingBehavior(_ConstantBehavior):
    TYPE, DEFAULT_NAME, DOMAIN_VARS = "BHV_ConstantHeading", "bhv_constant_heading", ("course",)
    VAR, NAV_VAR, PARAM = "course", "NAV_HEADING", "heading"
    PEAK, BASE, SUMMIT_DELTA = 10.0, 170.0, 25.0
    WRAP = True

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.complete_thresh = -1.0

    def set_specific_param(self, param: str, value: str) -> bool:
        if param == "complete_thresh":
            self.complete_thresh = parse_float(value, param)
            return True
        return super().set_specific_param(param, value)

    def summit(self) -> float:
        return self.domain.vars["course"].snap(self.desired % 360.0, wrap=True)

    def on_run_state(self) -> ObjectiveFunction | None:
        heading = self.info.get_double("NAV_HEADING")
        if self.complete_thresh > 0 and heading is not None:
            error = abs((heading - self.desired + 180) % 360 - 180)
            if error < self.complete_thresh:
                self.set_complete()
                return None
        return super().on_run_state()


class ConstantDepthBehavior(_ConstantBehavior):
    TYPE, DEFAULT_NAME, DOMAIN_VARS = "BHV_ConstantDepth", "bhv_constant_depth", ("depth",)
    VAR, NAV_VAR, PARAM = "depth", "NAV_DEPTH", "depth"
    PEAK, BASE, SUMMIT_DELTA = 3.0, 100.0, 50.0

    def on_run_state(self) -> ObjectiveFunction | None:
        if self.info.get_double("NAV_DEPTH") is None:
            self.post("BHV_WARNING", f"{self.name}: no NAV_DEPTH", key="nodepth")
        return super().on_run_state()
