"""Flags (``endflag = RETURN = true``) and the macro replacement done when they post (pHelmIvP 19.8.1's rules)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from .errors import ParamError
from .logic import LogicCondition, is_number

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

    def value(self, macros: Mapping[str, str]) -> Value:
        """The value to post, as pHelmIvP 19.8.1's ``VarDataPair(var, value, "auto")``: a number posts as a double
        (nothing expanded), a quoted text without its quotes, and text has exactly the ``macros`` tokens replaced
        (MBUtils' findReplace, in order); any other ``$[..]``/``$(..)`` posts as written, as 19.8.1 does."""
        text = self.text
        if is_number(text):
            return float(text)
        if len(text) >= 2 and text[0] == '"' and text[-1] == '"':
            text = text[1:-1]
        return expand(text, macros)


def expand(text: str, macros: Mapping[str, str]) -> str:
    """Replace each literal token (``"$[OWNSHIP]"``) by its text, in order; nothing else is touched."""
    for token, replacement in macros.items():
        text = text.replace(token, replacement)
    return text
