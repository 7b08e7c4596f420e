"""Flags (``endflag = RETURN = true``) and the ``$[MACRO]`` / ``$(MACRO)`` expansion done when they post."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from .errors import ParamError
from .geometry import fmt_num
from .logic import LogicCondition, is_number

_MACRO = re.compile(r"\$[\[(]([A-Za-z0-9_]+)[\])]")
Value = float | str


@dataclass(frozen=True)
class Flag:
    """``VAR = value [if] condition``; the value keeps its text so macros can be expanded at posting time."""

    var: str
    text: str
    condition: LogicCondition | None = None

    @classmethod
    def parse(cls, spec: str) -> Flag:
        spec = spec.strip()
        if spec.startswith("#"):
            raise ParamError(f"flag '{spec}': inter-vehicle destinations (#group, #all) are not supported")
        if spec.startswith("@"):
            raise ParamError(f"flag '{spec}': post tags (@tag) are for contact behaviours, not supported")
        condition = None
        if "[if]" in spec:
            spec, cond_text = (part.strip() for part in spec.split("[if]", 1))
            condition = LogicCondition(cond_text)
        var, sep, value = spec.partition("=")
        var = var.strip()
        if not sep or not var or not value.strip() or any(c.isspace() for c in var):
            raise ParamError(f"flag '{spec}': expected VAR = value")
        return cls(var, value.strip(), condition)

    def value(self, macros: Mapping[str, Value]) -> Value:
        """The value to post: macros expanded; a number (or a lone macro that is one) posts as a double."""
        text = self.text
        lone = _MACRO.fullmatch(text)
        if lone and isinstance(macros.get(lone.group(1)), float):
            return float(macros[lone.group(1)])  # type: ignore[arg-type]
        expanded = expand(text, macros)
        if len(expanded) >= 2 and expanded[0] == '"' and expanded[-1] == '"':
            return expanded[1:-1]
        return float(expanded) if is_number(expanded) else expanded


def expand(text: str, macros: Mapping[str, Value]) -> str:
    """Replace every known ``$[X]`` / ``$(X)``; doubles print with up to 3 decimals; unknown ones stay."""

    def one(match: re.Match[str]) -> str:
        value = macros.get(match.group(1))
        if value is None:
            return match.group(0)
        return fmt_num(value) if isinstance(value, float) else str(value)

    return _MACRO.sub(one, text)
