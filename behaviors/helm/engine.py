"""The behaviour set's iteration (BehaviorSet::produceOF + HelmEngine): states, flags, updates, decision.

One call to :meth:`HelmEngine.iterate` is one decision iteration. Behaviour postings are written into
the info buffer only after every behaviour has run, so a flag raised this iteration is seen by other
behaviours' conditions on the next one, as in pHelmIvP.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

from .behavior import Behavior, Posting
from .geometry import fmt_num
from .info_buffer import InfoBuffer, Value
from .ivp import IvPDomain, ObjectiveFunction, solve
from .logic import is_number
from .modes import ModeSet

log = logging.getLogger(__name__)


@dataclass
class EngineResult:
    """What one iteration decided and wants posted (postings already passed the duplicate filter)."""

    decisions: dict[str, float]
    function_count: int
    postings: list[Posting]
    states: dict[str, str] = field(default_factory=dict)
    removed: list[str] = field(default_factory=list)
    modes: dict[str, str] = field(default_factory=dict)
    halted: str = ""  # the BHV_ERROR that halted this iteration (no decision), "" if none


class HelmEngine:
    """Runs the behaviours in declaration order and solves the weighted sum of their functions."""

    def __init__(self, domain: IvPDomain, behaviors: list[Behavior], info: InfoBuffer,
                 modes: ModeSet | None = None) -> None:
        self.domain, self.behaviors, self.info = domain, list(behaviors), info
        self.modes = modes or ModeSet()
        self._posted_modes: dict[str, str] = {}
        self.iteration = 0
        self._last_posted: dict[str, Value] = {}
        self._configured: set[str] = set()
        self._last_halt = ""

    def clear_post_filter(self) -> None:
        """HELM_MAP_CLEAR: forget what was posted so everything is posted again."""
        self._last_posted.clear()

    def iterate(self, now: float) -> EngineResult:
        self.iteration += 1
        functions: list[ObjectiveFunction] = []
        extra: list[Posting] = []
        modes = self.modes.evaluate(self.info) if self.modes else {}
        for var, value in modes.items():
            typed: Value = float(value) if is_number(value) else value
            self.info.set(var, typed)
            if self._posted_modes.get(var) != value:
                self._posted_modes[var] = value
                extra.append(Posting(var, typed, key="mode_set"))
        states: dict[str, str] = {}
        halted = ""
        for bhv in self.behaviors:
            bhv.now = now
            bhv.state_ok = True
            extra.extend(self._apply_updates(bhv, now))
            fn = self._step(bhv, now)
            states[bhv.name] = bhv.state
            failed = bhv.conditions_hold() if bhv.state == "idle" else None
            good, total = bhv.update_counts
            bhv.post("BHV_STATUS", f"name={bhv.name},pc={failed.text if failed else ''},pwt={fmt_num(bhv.pwt)},"
                                   f"state={bhv.state},updates={good}/{total}", key="status")
            if fn is not None and bhv.pwt > 0:
                functions.append(fn)
            if not bhv.state_ok:  # pHelmIvP halts: the later behaviours are not run, nothing is decided
                errors = [p.value for p in bhv.outbox if p.var == "BHV_ERROR"]
                halted = str(errors[-1]) if errors else f"{bhv.name}: unknown error"
                break
        if halted != self._last_halt:  # log each new halt once, not every iteration it lasts
            if halted:
                log.warning("helm halted (no decision while this lasts): BHV_ERROR %s", halted)
            else:
                log.info("helm no longer halted")
            self._last_halt = halted
        decisions = {} if halted else solve(self.domain, functions)
        self.info.clear_deltas()
        postings = extra
        removed: list[str] = []
        for bhv in self.behaviors:
            postings.extend(self._filter(bhv, bhv.outbox, now))
            bhv.outbox = []
            if bhv.completed and not bhv.perpetual:
                removed.append(bhv.name)
                postings.append(Posting("IVPHELM_LIFE_EVENT",
                                        f"iter={self.iteration},time={fmt_num(now, 2)},bname={bhv.name},"
                                        f"btype={bhv.TYPE},event=death", repeatable=True))
        self.behaviors = [b for b in self.behaviors if b.name not in removed]
        return EngineResult(decisions, len(functions), postings, states, removed, modes, halted)

    def _apply_updates(self, bhv: Behavior, now: float) -> list[Posting]:
        results: list[Posting] = []
        if not bhv.updates_var:
            return results
        for value in self.info.deltas(bhv.updates_var):
            if not isinstance(value, str):
                continue
            result = bhv.apply_update(value)
            if result == "empty":
                continue
            results.append(Posting("IVPHELM_UPDATE_RESULT", f"bhv={bhv.name},var={bhv.updates_var},"
                                   f"time={fmt_num(now, 2)},result={result},val={value}", repeatable=True))
            if result == "success":
                bhv.post_flags("configflag", repeatable=False)
        return results

    def _step(self, bhv: Behavior, now: float) -> ObjectiveFunction | None:
        """One behaviour through idle / running / active / completed, posting its flags on transitions."""
        previous = bhv.state
        if bhv.name not in self._configured:
            self._configured.add(bhv.name)
            bhv.post_flags("configflag", repeatable=False)
        if bhv.completed:
            bhv.state = "completed"
            bhv.on_complete_state()
            return None
        failed = bhv.conditions_hold()
        bhv.tick_clock(now, failed is None)
        if bhv.completed:
            bhv.state = "completed"
            bhv.on_complete_state()
            return None
        fn: ObjectiveFunction | None = None
        if failed is not None:
            bhv.state = "idle"
            if previous != "idle":
                bhv.post_flags("idleflag")
                bhv.post_flags("inactiveflag")
            if previous in ("running", "active"):
                bhv.on_run_to_idle_state()
            bhv.on_idle_state()
        else:
            if previous == "idle":
                bhv.on_idle_to_run_state()
            fn = bhv.on_run_state()
            if previous in ("idle", ""):
                bhv.post_flags("runflag")
            bhv.post_flags("runxflag")
            if fn is not None and bhv.pwt > 0:
                bhv.state = "active"
                if previous != "active":
                    bhv.post_flags("activeflag")
            else:
                bhv.state = "running"
                if previous == "active":
                    bhv.post_flags("inactiveflag")
                bhv.on_inactive_state()
        if bhv.completed:
            bhv.state = "completed"
            return None
        return fn

    def _filter(self, bhv: Behavior, outbox: list[Posting], now: float) -> list[Posting]:
        """Write every posting into the info buffer; pass repeatable ones and changed values on."""
        passed = []
        for posting in outbox:
            self.info.set(posting.var, posting.value)
            key = f"{bhv.name}|{posting.var}|{posting.key}"
            if posting.repeatable or self._last_posted.get(key) != posting.value:
                self._last_posted[key] = posting.value
                passed.append(posting)
        return passed
