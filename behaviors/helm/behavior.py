"""``Behavior``: the parameters, flags, updates and duration every pHelmIvP behaviour shares (IvPBehavior).

A subclass declares its type name, the decision variables it needs, its own parameters
(:meth:`set_specific_param`) and :meth:`on_run_state`, which returns an objective function or None.
The per-iteration state machine that calls these hooks lives in :mod:`behaviors.helm.engine`.
"""

from __future__ import annotations

import logging
from abc import ABC, abstractmethod
from dataclasses import dataclass

from .errors import ParamError, UnknownParamError
from .flags import Flag
from .info_buffer import InfoBuffer, Value
from .ivp import IvPDomain, ObjectiveFunction
from .logic import LogicCondition, is_number

log = logging.getLogger(__name__)

FLAG_KINDS = ("runflag", "runxflag", "activeflag", "inactiveflag", "idleflag", "endflag", "configflag")
_NOT_SUPPORTED = {
    "templating": "behaviour templating (spawning) is not supported by this helm",
    "spawnflag": "spawnflag needs templating, which this helm does not support",
    "spawnxflag": "spawnxflag needs templating, which this helm does not support",
    "max_spawnings": "behaviour templating (spawning) is not supported by this helm",
    "nostarve": "nostarve is not supported by this helm",
    "no_starve": "nostarve is not supported by this helm",
}


def parse_bool(value: str, what: str) -> bool:
    lowered = value.strip().lower()
    if lowered in ("true", "yes", "on", "1"):
        return True
    if lowered in ("false", "no", "off", "0"):
        return False
    raise ParamError(f"{what} must be true or false, not '{value}'")


def parse_float(value: str, what: str, low: float | None = None, high: float | None = None) -> float:
    if not is_number(value):
        raise ParamError(f"{what} must be a number, not '{value}'")
    number = float(value)
    if (low is not None and number < low) or (high is not None and number > high):
        raise ParamError(f"{what} = {value} is out of range [{low}, {high}]")
    return number


@dataclass
class Posting:
    """A message a behaviour wants posted; ``repeatable`` ones bypass the helm's duplicate filter."""

    var: str
    value: Value
    repeatable: bool = False
    key: str = ""


class Behavior(ABC):
    """Common behaviour state. Subclasses set ``TYPE``, ``DEFAULT_NAME`` and ``DOMAIN_VARS``, and implement
    :meth:`set_specific_param` and :meth:`on_run_state`; the other ``on_*`` hooks are optional."""

    TYPE = "BHV_Base"
    DEFAULT_NAME = "bhv_base"
    DOMAIN_VARS: tuple[str, ...] = ()
    DEFAULT_DURATION = -1.0

    def __init__(self, domain: IvPDomain, info: InfoBuffer, ownship: str = "") -> None:
        self.domain, self.info, self.ownship = domain, info, ownship
        self.name = self.DEFAULT_NAME
        self.pwt = 100.0
        self.conditions: list[LogicCondition] = []
        self.flags: dict[str, list[Flag]] = {kind: [] for kind in FLAG_KINDS}
        self.updates_var = ""
        self.duration = self.DEFAULT_DURATION
        self.duration_status = ""
        self.duration_reset: tuple[str, str] | None = None
        self.duration_idle_decay = True
        self.perpetual = False
        self.post_mapping: dict[str, str] = {}
        self.now = 0.0
        self.completed = False
        self.state_ok = True  # False once the behaviour posts BHV_ERROR this iteration: the helm halts
        self.state = ""
        self.outbox: list[Posting] = []
        self.last_update = ""
        self.update_counts = [0, 0]
        self._duration_start: float | None = None
        self._duration_reset_pending = False
        self._run_time = 0.0
        self._idle_time = 0.0
        self._last_state_time: float | None = None

    # ---- configuration -------------------------------------------------------------------------
    def set_param(self, param: str, value: str) -> None:
        """Apply one ``param = value`` line; raises ParamError for an unknown parameter or a bad value."""
        param = param.strip().lower().lstrip("_")
        value = value.strip()
        if self._set_common_param(param, value):
            return
        if self.set_specific_param(param, value):
            return
        if param in _NOT_SUPPORTED:
            raise ParamError(_NOT_SUPPORTED[param])
        raise UnknownParamError(f"unknown parameter '{param}' for {self.TYPE}")

    @abstractmethod
    def set_specific_param(self, param: str, value: str) -> bool:
        """Behaviour-specific parameters; return False if ``param`` is not one of them."""

    def _set_common_param(self, param: str, value: str) -> bool:
        flag_kind = param.replace("_flag", "flag")
        if param in ("name", "descriptor"):
            if not value or any(not (c.isalnum() or c in "_-[]()#@+") for c in value):
                raise ParamError(f"bad behaviour name '{value}'")
            self.name = value
        elif param in ("pwt", "priority", "priwt"):
            self.pwt = parse_float(value, param, low=0.0)
        elif param == "condition":
            self.conditions.append(LogicCondition(value.replace(",", "=")))
        elif flag_kind in FLAG_KINDS:
            if value.lower() == "clearall":
                self.flags[flag_kind].clear()
            else:
                self.flags[flag_kind].append(Flag.parse(value))
        elif param == "updates":
            if not value or any(c.isspace() for c in value):
                raise ParamError(f"updates must name one MOOS variable, not '{value}'")
            self.updates_var = value
        elif param == "duration":
            if value.lower() in ("no-time-limit", "-1"):
                self.duration = -1.0
            else:
                self.duration = parse_float(value, "duration", low=0.0)
        elif param == "duration_status":
            self.duration_status = value
        elif param == "duration_reset":
            var, _, val = value.partition("=")
            if not var.strip():
                raise ParamError(f"duration_reset must be VAR=VALUE, not '{value}'")
            self.duration_reset = (var.strip(), val.strip())
        elif param == "duration_idle_decay":
            self.duration_idle_decay = parse_bool(value, param)
        elif param == "perpetual":
            self.perpetual = parse_bool(value, param)
        elif param == "post_mapping":
            old, sep, new = value.partition(",")
            if not sep or not old.strip() or not new.strip():
                raise ParamError(f"post_mapping must be VAR,NEWVAR, not '{value}'")
            self.post_mapping[old.strip()] = new.strip()
        elif param in ("build_info", "precision", "comms_policy"):
            pass  # IvP build hints and multi-vehicle comms policy: accepted, no effect here (docs/helm.md)
        else:
            return False
        return True

    def on_set_param_complete(self) -> None:  # noqa: B027 (optional hook)
        """Called after configuration and after each successful update."""

    def check_config(self) -> None:
        """Raise ParamError if the behaviour cannot run with this domain/configuration."""
        for var in self.DOMAIN_VARS:
            if not self.domain.has(var):
                raise ParamError(f"{self.TYPE} needs the '{var}' decision variable in the helm's domain")

    def info_vars(self) -> set[str]:
        """MOOS variables the helm must register for on this behaviour's behalf."""
        names: set[str] = {"NAV_X", "NAV_Y", "NAV_HEADING", "NAV_SPEED"}
        for cond in self.conditions:
            names |= cond.variables()
        for flags in self.flags.values():
            for flag in flags:
                if flag.condition is not None:
                    names |= flag.condition.variables()
        if self.updates_var:
            names.add(self.updates_var)
        if self.duration_reset:
            names.add(self.duration_reset[0])
        return names

    # ---- runtime updates -----------------------------------------------------------------------
    def apply_update(self, text: str) -> str:
        """One post to the ``updates`` variable; returns success, param_error, duplicate or name_mismatch."""
        text = text.strip()
        if not text:
            return "empty"
        if text == self.last_update and not any(w in text for w in ("toggle", "engage", "mod")):
            return "duplicate"
        pairs = [p.strip() for p in text.split("#") if p.strip()]
        for pair in pairs:
            key, _, val = pair.partition("=")
            if key.strip().lower() == "name" and val.strip() != self.name:
                return "name_mismatch"
        self.update_counts[1] += 1
        for pair in pairs:
            key, sep, val = pair.partition("=")
            if key.strip().lower() == "name":
                continue
            try:
                if not sep:
                    raise ParamError(f"'{pair}' is not param=value")
                self.set_param(key, val)
            except Exception as exc:  # a bad update is reported, never fatal
                self.post("BHV_WARNING", f"Faulty update for behavior: {self.name}. {exc}", repeatable=True)
                log.warning("%s: faulty update '%s': %s", self.name, text, exc)
                return "param_error"
        self.update_counts[0] += 1
        self.last_update = text
        self.on_set_param_complete()
        return "success"

    # ---- postings ------------------------------------------------------------------------------
    def post(self, var: str, value: Value, repeatable: bool = False, key: str = "") -> None:
        mapped = self.post_mapping.get(var, var)
        if mapped.lower() == "silent":
            return
        if isinstance(value, bool):
            value = "true" if value else "false"
        elif isinstance(value, int):
            value = float(value)
        self.outbox.append(Posting(mapped, value, repeatable, key))

    def post_warning(self, text: str) -> None:
        """pHelmIvP's postWMessage: ``BHV_WARNING = <name>: <text>``, every time."""
        self.post("BHV_WARNING", f"{self.name}: {text}", repeatable=True)

    def post_error(self, text: str) -> None:
        """pHelmIvP's postEMessage: ``BHV_ERROR = <name>: <text>``; the helm halts this iteration (BehaviorError)."""
        self.post("BHV_ERROR", f"{self.name}: {text}", repeatable=True)
        self.state_ok = False

    def post_flags(self, kind: str, repeatable: bool = True) -> None:
        if not self.flags[kind]:
            return
        macros = self.flag_macros()
        for flag in self.flags[kind]:
            if flag.condition is None or flag.condition.evaluate(self.info.get):
                self.post(flag.var, flag.value(macros), repeatable=repeatable)

    def flag_macros(self) -> dict[str, str]:
        """The macros of pHelmIvP 19.8.1's ``IvPBehavior::postFlags``: these four, bracket form only (``$[CONTACT]``
        is empty outside contact behaviours); every other macro in a run/idle/active/inactive/end flag posts as
        written, as 19.8.1 posts it."""
        return {"$[OWNSHIP]": self.ownship, "$[BHVNAME]": self.name, "$[BHVTYPE]": self.TYPE,
                "$[CONTACT]": str(getattr(self, "contact", ""))}

    def set_complete(self) -> None:
        """Post the endflags; a non-perpetual behaviour is then completed (and removed by the engine)."""
        self.post_flags("endflag")
        if self.perpetual:
            self._duration_reset_pending = True
        else:
            self.completed = True

    # ---- used by the engine --------------------------------------------------------------------
    def nav(self) -> tuple[float, float, float, float] | None:
        """(x, y, heading, speed) from the info buffer, or None with a BHV_ERROR if any is missing."""
        values = [self.info.get_double(v) for v in ("NAV_X", "NAV_Y", "NAV_HEADING", "NAV_SPEED")]
        if any(v is None for v in values):
            self.post_error("ownship x,y,heading, or speed info not found.")
            return None
        return values[0], values[1], values[2], values[3]  # type: ignore[return-value]

    def conditions_hold(self) -> LogicCondition | None:
        """The first failing condition, or None when all hold."""
        for cond in self.conditions:
            if not cond.evaluate(self.info.get):
                return cond
        return None

    def tick_clock(self, now: float, runnable: bool) -> None:
        """Advance run/idle time and check the duration; may call :meth:`set_complete`."""
        previous = self._last_state_time if self._last_state_time is not None else now
        self._last_state_time = now
        if self.duration_reset and self.info.deltas(self.duration_reset[0]):
            wanted = self.duration_reset[1]
            if not wanted or any(str(v) == wanted or (isinstance(v, float) and is_number(wanted)
                                                      and v == float(wanted))
                                 for v in self.info.deltas(self.duration_reset[0])):
                self._duration_start = now if runnable else None
        if self._duration_reset_pending and runnable:
            self._duration_reset_pending = False
            self._duration_start = None
        if self._duration_start is None:
            if not runnable:
                return
            self._duration_start = now
        elapsed_step = now - previous
        if runnable:
            self._run_time += elapsed_step
        else:
            self._idle_time += elapsed_step
        if self.duration < 0:
            return
        elapsed = now - self._duration_start
        if not self.duration_idle_decay:
            elapsed = self._run_time
        remaining = max(0.0, self.duration - elapsed)
        if self.duration_status:
            self.post(self.duration_status, round(remaining, 2))
        if elapsed >= self.duration and not self._duration_reset_pending:
            self.set_complete()

    # ---- hooks ---------------------------------------------------------------------------------
    @abstractmethod
    def on_run_state(self) -> ObjectiveFunction | None:
        """The objective function for this iteration (None: no opinion); may :meth:`post`."""

    def on_idle_state(self) -> None:  # noqa: B027 (optional hook: doing nothing is the default)
        pass

    def on_idle_to_run_state(self) -> None:  # noqa: B027 (optional hook: doing nothing is the default)
        pass

    def on_run_to_idle_state(self) -> None:  # noqa: B027 (optional hook: doing nothing is the default)
        pass

    def on_inactive_state(self) -> None:  # noqa: B027 (optional hook: doing nothing is the default)
        pass

    def on_complete_state(self) -> None:  # noqa: B027 (optional hook: doing nothing is the default)
        pass
