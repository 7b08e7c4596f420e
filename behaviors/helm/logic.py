"""Logic conditions as pHelmIvP writes them: ``(A = 1) and !(B < 2)``, ``MODE == LOITER``, ``X = $(Y)``.

Parsing follows lib_logic: the first relational or boolean connector at parenthesis depth 0 (scanning
from the left) splits the string; both operands of ``and``/``or`` must be parenthesised; the left side
of a relation is a variable, the right side a number, a literal or ``$(VAR)``. A relation on a variable
nobody has posted is false, ``!=`` included.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

from .errors import ConditionError

Value = float | str
Lookup = Callable[[str], Value | None]

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_RELATIONS = ("==", "=", "!=", ">=", "<=", ">", "<")
_FORBIDDEN_IN_NAME = set('"<>=!()')


def is_number(text: str) -> bool:
    """MBUtils' isNumber: an optionally signed decimal, blanks around it allowed."""
    return bool(_NUMBER.match(text.strip()))


def _strip_quotes(text: str) -> str:
    if len(text) >= 2 and text[0] == '"' and text[-1] == '"':
        return text[1:-1]
    return text


def _balanced(text: str) -> bool:
    depth = 0
    for ch in text:
        depth += ch == "("
        depth -= ch == ")"
        if depth < 0:
            return False
    return depth == 0


def _global_parens(text: str) -> bool:
    """True for ``(A=1)`` and ``((A=1) and (B=2))``, false for ``(A=1) and (B=2)``."""
    text = text.strip()
    return len(text) >= 2 and text[0] == "(" and text[-1] == ")" and _balanced(text) and _balanced(text[1:-1])


def _global_not_parens(text: str) -> bool:
    text = text.strip()
    return len(text) >= 3 and text[0] == "!" and _global_parens(text[1:])


def _prune_parens(text: str) -> str:
    text = text.strip()
    while _global_parens(text):
        text = text[1:-1].strip()
    return text


def field_match(a: str, b: str) -> bool:
    """lib_logic's ``==`` on strings: one side equals a run of ``:``-separated fields of the other."""
    if a not in b and b not in a:
        return False
    short, long = sorted(([f.strip() for f in a.split(":")], [f.strip() for f in b.split(":")]), key=len)
    for start in range(len(long) - len(short) + 1):
        if long[start : start + len(short)] == short:
            return True
    return False


@dataclass(frozen=True)
class _Relation:
    op: str
    var: str
    rhs: Value | None  # a literal (float or str), or None when the right side is a variable
    rhs_var: str | None

    def evaluate(self, lookup: Lookup) -> bool:
        left = lookup(self.var)
        right = lookup(self.rhs_var) if self.rhs_var is not None else self.rhs
        if left is None or right is None:
            return False
        if isinstance(left, str) and isinstance(right, str):
            return _compare_strings(self.op, _strip_quotes(left), _strip_quotes(right))
        if isinstance(left, str):
            left = _strip_quotes(left)
            if not is_number(left):
                return False
            left = float(left)
        if isinstance(right, str):
            right = _strip_quotes(right)
            if not is_number(right):
                return False
            right = float(right)
        return _compare_numbers(self.op, float(left), float(right))

    def variables(self) -> set[str]:
        return {self.var} | ({self.rhs_var} if self.rhs_var else set())


@dataclass(frozen=True)
class _Not:
    node: _Node

    def evaluate(self, lookup: Lookup) -> bool:
        return not self.node.evaluate(lookup)

    def variables(self) -> set[str]:
        return self.node.variables()


@dataclass(frozen=True)
class _Bool:
    op: str
    left: _Node
    right: _Node

    def evaluate(self, lookup: Lookup) -> bool:
        a, b = self.left.evaluate(lookup), self.right.evaluate(lookup)
        return (a and b) if self.op == "and" else (a or b)

    def variables(self) -> set[str]:
        return self.left.variables() | self.right.variables()


_Node = _Relation | _Not | _Bool


def _compare_strings(op: str, a: str, b: str) -> bool:
    if op == "=":
        return a == b
    if op == "==":
        return field_match(a, b)
    return _compare_numbers(op, a, b)  # type: ignore[arg-type]  # lexicographic, as std::string


def _compare_numbers(op: str, a: float, b: float) -> bool:
    return {
        "=": a == b,
        "==": a == b,
        "!=": a != b,
        "<": a < b,
        "<=": a <= b,
        ">": a > b,
        ">=": a >= b,
    }[op]


def _split(text: str) -> tuple[str, str, str] | None:
    """The first connector at depth 0 scanning left to right: (connector, left, right), or None."""
    depth = 0
    for i, ch in enumerate(text):
        depth += ch == "("
        depth -= ch == ")"
        if depth != 0:
            continue
        lower = text[i - 1 : i + 4].lower() if i > 0 else ""
        if lower.startswith(" or "):
            return "or", text[:i].strip(), text[i + 3 :].strip()
        if lower.startswith(" and "):
            return "and", text[:i].strip(), text[i + 4 :].strip()
        for rel in _RELATIONS:
            if text.startswith(rel, i):
                return rel, text[:i].strip(), text[i + len(rel) :].strip()
    return None


class LogicCondition:
    """One parsed condition; :meth:`evaluate` looks variables up through a callable (the info buffer)."""

    def __init__(self, text: str) -> None:
        self.text = text.strip()
        self._root = self._parse(self.text, self.text)

    def __repr__(self) -> str:
        return f"LogicCondition({self.text!r})"

    def evaluate(self, lookup: Lookup) -> bool:
        return self._root.evaluate(lookup)

    def variables(self) -> set[str]:
        """Every MOOS variable the condition reads (the helm registers for them)."""
        return self._root.variables()

    def _parse(self, text: str, whole: str) -> _Node:
        original = text.strip()
        text = text.replace("\t", " ").replace(")", ") ").replace("(", " (").replace("$ (", "$(").strip()
        if not text:
            raise ConditionError(whole, text, "empty condition")
        if not _balanced(text):
            raise ConditionError(whole, original, "unbalanced parentheses")
        text = _prune_parens(text)
        if text.startswith("!") and _global_parens(text[1:]):
            return _Not(self._parse(text[1:], whole))
        split = _split(text)
        if split is None:
            raise ConditionError(whole, text, "no relation (=, ==, !=, <, <=, >, >=) found")
        op, left, right = split
        if op in ("and", "or"):
            for side in (left, right):
                if not (_global_parens(side) or _global_not_parens(side)):
                    raise ConditionError(whole, side, f"each operand of '{op}' must be in parentheses")
            return _Bool(op, self._parse(left, whole), self._parse(right, whole))
        return self._relation(op, left, right, whole)

    @staticmethod
    def _relation(op: str, left: str, right: str, whole: str) -> _Relation:
        nested = _split(right)
        if nested and nested[0] in ("and", "or"):
            raise ConditionError(whole, f"{left} {op} {nested[1]}", f"each operand of '{nested[0]}' must be in parentheses")
        if not left or set(left) & _FORBIDDEN_IN_NAME or left.lower() in ("and", "or"):
            raise ConditionError(whole, left or op, "the left side must be a MOOS variable name")
        if right.startswith("$(") and right.endswith(")"):
            name = right[2:-1].strip()
            if not name or set(name) & _FORBIDDEN_IN_NAME:
                raise ConditionError(whole, right, "bad variable reference on the right side")
            return _Relation(op, left, None, name)
        if is_number(right):
            return _Relation(op, left, float(right), None)
        inner = _strip_quotes(right)
        if not right or right.lower() in ("and", "or") or set(inner) & _FORBIDDEN_IN_NAME:
            raise ConditionError(whole, right or op, "the right side must be a number, a literal or $(VAR)")
        return _Relation(op, left, right, None)
