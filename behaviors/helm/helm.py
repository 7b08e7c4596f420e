"""``Helm``: pHelmIvP's app logic without MOOS: states, mail handling, nav wait, all-stop and DESIRED_*.

Feed it mail with :meth:`Helm.handle_mail` and call :meth:`Helm.iterate` at AppTick; both return the
postings for the MOOSDB. Time is whatever clock the caller passes (MOOS time in the app, a number in tests).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from translators.node_report_codec import NodeReportError
from util.geodesy import UTMGeodesy

from .behavior import Behavior
from .bhv_file import Initialize, build_behaviors, read_bhv_file
from .config import HelmConfig
from .contacts import NODE_REPORT_VARS, ContactTable
from .engine import EngineResult, HelmEngine
from .errors import BehaviorFileError
from .geometry import fmt_num
from .info_buffer import InfoBuffer, Value
from .modes import ModeEntry, ModeSet

log = logging.getLogger(__name__)

OVERRIDE_VARS = ("MOOS_MANUAL_OVERIDE", "MOOS_MANUAL_OVERRIDE")
NAV_VARS = ("NAV_X", "NAV_Y", "NAV_HEADING", "NAV_SPEED")
FIXED_REGISTRATIONS = (*OVERRIDE_VARS, *NAV_VARS, "NAV_DEPTH", "IVPHELM_STATE", "HELM_MAP_CLEAR", "DB_CLIENTS",
                       *NODE_REPORT_VARS)
GRACE_ALLSTOPS = ("NothingToDo", "MissingDecVars", "NoGoalBehavior")


@dataclass
class Post:
    """One posting for the MOOSDB; ``aux`` is pHelmIvP's source-aux tag (informational)."""

    var: str
    value: Value
    aux: str = ""


class Helm:
    """The helm's state machine around a :class:`HelmEngine`."""

    def __init__(self, config: HelmConfig, app_name: str = "pHelmIvP", ownship: str = "") -> None:
        self.config, self.app_name, self.ownship = config, app_name, ownship
        self.info = InfoBuffer()
        self.problems = list(config.problems)
        geodesy = None
        if config.lat_origin is not None and config.long_origin is not None:
            try:
                geodesy = UTMGeodesy(config.lat_origin, config.long_origin)
            except ValueError as exc:
                self.problems.append(f"LatOrigin/LongOrigin: {exc}")
        self.contacts = ContactTable(self.info, geodesy, config.node_skews)
        self.initializes: list[Initialize] = []
        behaviors: list[Behavior] = []
        modes: list[ModeEntry] = []
        if not self.problems:
            try:
                for path in sorted(config.behavior_files):
                    bfile = read_bhv_file(path)
                    self.initializes.extend(bfile.initializes)
                    modes.extend(bfile.modes)
                    behaviors.extend(build_behaviors(bfile, config.domain, self.info, ownship))
            except BehaviorFileError as exc:
                self.problems.append(str(exc))
        for problem in self.problems:
            log.error("MALCONFIG: %s", problem)
        self.engine = HelmEngine(config.domain, [] if self.problems else behaviors, self.info, ModeSet(modes))
        self.has_control = config.start_engaged
        self.state = "MALCONFIG" if self.problems else ("DRIVE" if self.has_control else "PARK")
        self.start_time: float | None = None
        self.registered_at: float | None = None  # when the app last registered (on each connection)
        self.last_decisions: dict[str, float] = {}
        self._allstop = ""
        self._posted_state = ""
        self._seen_own_state = False
        self._deferred_done = False
        self._nav_warned = False
        self._bhv_lists: dict[str, str] = {}
        self._report_warned: dict[str, float] = {}  # "var|source|reason" -> helm time of the last warning
        self._outbox: list[Post] = []

    # ---- interface to the MOOS app --------------------------------------------------------------
    def registrations(self) -> set[str]:
        """Every variable the helm must subscribe to."""
        names = set(FIXED_REGISTRATIONS)
        if self.config.other_override_var:
            names.add(self.config.other_override_var)
        for bhv in self.engine.behaviors:
            names |= bhv.info_vars()
        names |= self.engine.modes.variables()
        names |= {init.var for init in self.initializes if init.deferred}
        return names

    def startup(self, now: float) -> list[Post]:
        """What pHelmIvP posts in OnStartUp: initialize values, the domain, the behaviour counts."""
        self.start_time = now
        out = [Post("IVPHELM_DOMAIN", self.config.domain.summary())]
        if self.config.helm_alias:
            out.append(Post("IVPHELM_ALIAS", self.config.helm_alias))
        for problem in self.problems:
            out.append(Post("IVPHELM_CONFIG_WARNING", problem))
        if self.problems:
            return out
        for init in self.initializes:
            if not init.deferred:
                out.append(Post(init.var, init.value, "HELM_VAR_INIT"))
                self.info.set(init.var, init.value)
        for kind in ("ACTIVE", "RUNNING", "IDLE", "DISABLED"):
            out.append(Post(f"IVPHELM_BHV_{kind}_CNT", 0.0))
        for bhv in self.engine.behaviors:
            out.append(Post("IVPHELM_LIFE_EVENT", f"iter=0,time={fmt_num(now, 2)},bname={bhv.name},"
                                                  f"btype={bhv.TYPE},event=spawn,seed=helm_startup"))
        return out

    def handle_mail(self, var: str, value: Value, msg_time: float, source: str, now: float) -> list[Post]:
        """One incoming message (in arrival order); returns anything it makes the helm post at once."""
        out: list[Post] = []
        skew = abs(now - msg_time)
        if self.registered_at is not None:  # a value the DB held from before we registered is not stale
            skew = min(skew, abs(now - self.registered_at))
        if source != self.app_name and self.config.ok_skew is not None and skew > self.config.ok_skew:
            out.append(Post("IVPHELM_SKEW", f"var={var},skew={fmt_num(now - msg_time, 2)},src={source}"))
            return out
        if var in OVERRIDE_VARS or (var and var == self.config.other_override_var):
            if isinstance(value, str):
                if value.strip().upper() == "FALSE":
                    self.has_control = True
                elif value.strip().upper() == "TRUE" and self.config.allow_park:
                    self.has_control = False
        elif var == "IVPHELM_STATE":
            if source == self.app_name:
                self._seen_own_state = True
            elif value != "STANDBY" and self.state in ("PARK", "DRIVE"):
                out.extend(self._all_stop("DisabledByStandbyHelm"))
                self.state = "DISABLED"
        elif var == "HELM_MAP_CLEAR":
            self.engine.clear_post_filter()
        elif var in NODE_REPORT_VARS:
            self._handle_node_report(var, value, source, now)
        self.info.set(var, value)
        return out

    def iterate(self, now: float) -> list[Post]:
        """One AppTick; returns the postings in pHelmIvP's order."""
        if self.start_time is None:
            self.start_time = now
        out: list[Post] = []
        if self.state in ("PARK", "DRIVE"):
            self.state = "DRIVE" if self.has_control else "PARK"
        if self.state != self._posted_state:
            log.info("IVPHELM_STATE %s -> %s", self._posted_state or "(start)", self.state)
        if self.state != "DISABLED" or self._posted_state != "DISABLED":
            out.append(Post("IVPHELM_STATE", self.state))
            self._posted_state = self.state
        if self.state not in ("PARK", "DRIVE"):
            return out
        needed = NAV_VARS + (("NAV_DEPTH",) if self.config.domain.has("depth") else ())
        if not all(self.info.is_known(v) for v in needed):
            if not self._nav_warned and now - self.start_time > self.config.nav_grace:
                self._nav_warned = True
                missing = ", ".join(v for v in needed if not self.info.is_known(v))
                log.warning("Waiting for Helm Nav Solution (no %s after %.0f s)", missing, now - self.start_time)
            return out
        out.extend(self._deferred_initializes(now))
        if self.state == "PARK":
            out.extend(self._all_stop("ManualOverride"))
            return out
        if now - self.start_time < 1.0:
            return out
        result = self.engine.iterate(now)
        out.extend(Post(p.var, p.value) for p in result.postings)
        out.extend(self._behavior_lists(result.states))
        self.last_decisions = result.decisions
        undecided = [v.name for v in self.config.domain.vars.values()
                     if v.name not in result.decisions and not v.optional]
        if result.halted:
            message = "BehaviorError"
        elif result.function_count == 0:
            message = "NothingToDo"
        elif undecided:
            message = "MissingDecVars:" + ",".join(undecided)
        else:
            message = "clear"
        out.append(Post("IVPHELM_SUMMARY", self._summary(result)))
        out.extend(self._all_stop(message))
        if message == "clear":
            for var, value in result.decisions.items():
                out.append(Post(self.config.helm_prefix + _desired_name(var), value))
        return out

    # ---- internals ------------------------------------------------------------------------------
    def _handle_node_report(self, var: str, value: Value, source: str, now: float) -> None:
        """pHelmIvP's processNodeReport: ``<NAME>_NAV_*`` into the info buffer; a bad report is logged, unused.

        The same fault from the same sender is logged at most once a minute (helm time); repeats go to debug.
        """
        try:
            if not isinstance(value, str):
                raise NodeReportError("a node report must be a string, not a number")
            self.contacts.handle_report(value)
        except NodeReportError as exc:
            key = f"{var}|{source}|{exc}"
            last = self._report_warned.get(key)
            level = logging.DEBUG if last is not None and now - last < 60.0 else logging.WARNING
            if level == logging.WARNING:
                self._report_warned[key] = now
            log.log(level, "unhandled %s from %s: %s (report '%s')", var, source, exc, value)
    def _deferred_initializes(self, now: float) -> list[Post]:
        if self._deferred_done or not self._seen_own_state:
            return []
        self._deferred_done = True
        out = []
        for init in self.initializes:
            if init.deferred and not self.info.is_known(init.var):
                out.append(Post(init.var, init.value, "HELM_VAR_INIT"))
                self.info.set(init.var, init.value)
        return out

    def _all_stop(self, message: str) -> list[Post]:
        """pHelmIvP's postAllStop: on change only, with one iteration of grace for empty decisions."""
        if self.state not in ("PARK", "DRIVE") or message == self._allstop:
            return []
        out = [Post("IVPHELM_ALLSTOP", message)]
        log.info("IVPHELM_ALLSTOP=%s", message)
        if message == "clear":
            self._allstop = message
            return out
        if message.startswith(GRACE_ALLSTOPS) and self._allstop != "IncompleteOrEmptyDecision":
            self._allstop = "IncompleteOrEmptyDecision"
            return out
        self._allstop = message
        out.extend(Post(_desired_name(var), 0.0) for var in self.config.domain.vars)
        if self.config.park_on_allstop:
            self.has_control = False
        return out

    def _behavior_lists(self, states: dict[str, str]) -> list[Post]:
        out = []
        for kind in ("active", "running", "idle"):
            names = ",".join(name for name, state in states.items() if state == kind)
            if self._bhv_lists.get(kind) != names:
                self._bhv_lists[kind] = names
                out.append(Post(f"IVPHELM_BHV_{kind.upper()}", names))
                out.append(Post(f"IVPHELM_BHV_{kind.upper()}_CNT", float(len(names.split(",")) if names else 0)))
        return out

    def _summary(self, result: EngineResult) -> str:
        def listed(kind: str) -> str:
            return ":".join(n for n, s in result.states.items() if s == kind) or "none"

        parts = [f"iter={self.engine.iteration}"]
        parts += [f"var={var}:{fmt_num(value)}" for var, value in result.decisions.items()]
        parts.append(f"halted={'true' if result.halted else 'false'}")
        mode_text = "#".join(f"{var}@{value}" for var, value in result.modes.items()) or "none"
        parts += [f"modes={mode_text}", f"active_bhvs={listed('active')}", f"running_bhvs={listed('running')}",
                  f"idle_bhvs={listed('idle')}", f"completed_bhvs={listed('completed')}"]
        if result.halted:
            parts.append(f'halt_msg="BHV_ERROR: {result.halted}"')
        return ",".join(parts)


def _desired_name(var: str) -> str:
    return "DESIRED_HEADING" if var == "course" else "DESIRED_" + var.upper()
