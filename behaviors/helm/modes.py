"""Hierarchical modes (``set MODE = VALUE { conditions } ELSE``), as pHelmIvP's ModeSet evaluates them.

Entries are evaluated in file order every iteration, before the behaviours. A value set by one entry is
seen by the conditions of every later entry in the same iteration. A condition ``MODE = X`` on the
entry's own variable makes ``X`` a prefix (``ACTIVE:LOITERING``); the else-value applies only while that
prefix condition holds.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .errors import ParamError
from .info_buffer import InfoBuffer, Value
from .logic import LogicCondition


@dataclass
class ModeEntry:
    var: str
    value: str
    line: int = 0
    conditions: list[LogicCondition] = field(default_factory=list)
    prefix_conditions: list[bool] = field(default_factory=list)
    prefix: str = ""
    else_value: str = ""

    def add_condition(self, text: str) -> None:
        """One condition line; ``==`` is not allowed in modes (lib_logic's setAllowDoubleEquals(false))."""
        if "==" in text:
            raise ParamError(f"mode condition '{text}': '==' is not allowed in a set block")
        cond = LogicCondition(text)
        left, sep, right = text.partition("=")
        is_prefix = bool(sep) and left.strip() == self.var and bool(right.strip()) and not self.prefix
        if is_prefix:
            self.prefix = right.strip()
        self.conditions.append(cond)
        self.prefix_conditions.append(is_prefix)

    def set_else(self, text: str) -> None:
        if len(text.split()) != 1:
            raise ParamError(f"mode else-value '{text}' must be one word")
        self.else_value = text.strip()


class ModeSet:
    """The mode entries of the behaviour files, in order."""

    def __init__(self, entries: list[ModeEntry] | None = None) -> None:
        self.entries = list(entries or [])

    def __bool__(self) -> bool:
        return bool(self.entries)

    def variables(self) -> set[str]:
        names: set[str] = set()
        for entry in self.entries:
            for cond in entry.conditions:
                names |= cond.variables()
        return names

    def evaluate(self, info: InfoBuffer) -> dict[str, str]:
        """This iteration's mode values by variable name (sorted, as pHelmIvP's map)."""
        assigned: dict[str, str] = {}

        def lookup(name: str) -> Value | None:
            return assigned[name] if name in assigned else info.get(name)

        for entry in self.entries:
            results = [cond.evaluate(lookup) for cond in entry.conditions]
            if all(results):
                value = entry.value
            elif all(r for r, is_prefix in zip(results, entry.prefix_conditions, strict=True) if is_prefix):
                value = entry.else_value
            else:
                value = ""
            if value:
                assigned[entry.var] = f"{entry.prefix}:{value}" if entry.prefix else value
        return dict(sorted(assigned.items()))
