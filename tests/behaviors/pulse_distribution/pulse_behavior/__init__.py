"""BHV_Pulse: wants one speed and counts its runs in ``PULSE_COUNT`` (a third-party behaviour for the tests)."""

from __future__ import annotations

from behaviors.helm.behavior import Behavior, parse_float
from behaviors.helm.ivp import ObjectiveFunction, zaic_peak


class PulseBehavior(Behavior):
    """A ZAIC peak on ``speed`` at ``speed = ...``; posts ``PULSE_COUNT`` (1, 2, ...) on every run."""

    TYPE, DEFAULT_NAME, DOMAIN_VARS = "BHV_Pulse", "bhv_pulse", ("speed",)

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.speed = 0.0
        self.runs = 0

    def set_specific_param(self, param: str, value: str) -> bool:
        if param != "speed":
            return False
        self.speed = parse_float(value, param, low=0.0)
        return True

    def on_run_state(self) -> ObjectiveFunction | None:
        self.runs += 1
        self.post("PULSE_COUNT", self.runs, repeatable=True)
        utilities = zaic_peak(self.domain.vars["speed"], self.speed, 0.0, 0.5, 0.0, 0, 100)
        return ObjectiveFunction.single(self.pwt, "speed", utilities)
