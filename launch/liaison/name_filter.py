"""Whole-name regular expressions for the scope's filters, on a linear-time engine with a cost budget.

Why not Python's ``re``: a filter typed in a page (``(?:.|.)*!``) backtracks exponentially and freezes the web
thread.  RE2 (``google-re2``) matches in time linear in the name, with its program bounded by ``max_mem``; a
filter is also refused when one match of a long name costs more than :data:`PROBE_LIMIT_S` of CPU.  RE2 has no
backreferences or lookaround: such a filter is refused with RE2's reason.  Matching stays Goby's ``regex_match``:
the whole name must match.  Pure functions and values: callable from any thread.
"""

from __future__ import annotations

import time

import re2

MAX_FILTER_CHARS = 256  # characters of one expression
MAX_PROGRAM_BYTES = 64 * 1024  # RE2's max_mem: bounds the compiled program, hence the cost per character
PROBE_LIMIT_S = 200e-6  # CPU one match of a PROBE_CHARS name may cost (plain filters: ~5 us)
PROBE_CHARS = 256
_PROBES = ("goby3_course::usv/node_status;" * 9)[:PROBE_CHARS], "a" * PROBE_CHARS
MATCH_ALL = frozenset({"", ".*"})


def _options() -> re2.Options:
    options = re2.Options()
    options.max_mem = MAX_PROGRAM_BYTES
    options.log_errors = False  # the reason goes to the page, not to stderr
    return options


class NameFilter:
    """One compiled filter; ``NameFilter(expression, "group")`` raises ValueError naming the expression."""

    __slots__ = ("pattern", "_regex")

    def __init__(self, expression: str, what: str) -> None:
        self.pattern = expression
        self._regex: re2._Regexp | None = None
        if expression in MATCH_ALL:
            return
        if len(expression) > MAX_FILTER_CHARS:
            raise ValueError(f"{what} filter {expression[:40]!r}... is {len(expression)} characters long "
                             f"(at most {MAX_FILTER_CHARS})")
        try:
            self._regex = re2.compile(expression, _options())
        except re2.error as exc:
            reason = exc.args[0].decode(errors="replace") if exc.args and isinstance(exc.args[0], bytes) else exc
            raise ValueError(f"{what} filter {expression!r} is not a valid regular expression: {reason} "
                             "(RE2 syntax: no backreferences or lookaround; at most "
                             f"{MAX_PROGRAM_BYTES // 1024} KiB compiled)") from None
        cost = self._probe_cost()
        if cost > PROBE_LIMIT_S:
            raise ValueError(f"{what} filter {expression!r} is too costly to match: {cost * 1e6:.0f} us of CPU "
                             f"for a {PROBE_CHARS}-character name (limit {PROBE_LIMIT_S * 1e6:.0f} us): simplify it")

    def _probe_cost(self) -> float:
        """CPU (thread time: not inflated by a busy machine) of the dearest probe, best of up to three runs; a
        probe is passed at its first run under the limit, and the first probe over it is the answer."""
        assert self._regex is not None
        worst = 0.0
        for probe in _PROBES:
            best = float("inf")
            for _ in range(3):
                start = time.thread_time()
                self._regex.fullmatch(probe)
                best = min(best, time.thread_time() - start)
                if best <= PROBE_LIMIT_S:
                    break
            worst = max(worst, best)
            if worst > PROBE_LIMIT_S:
                break
        return worst

    def fullmatch(self, name: str) -> bool:
        """Whether the whole ``name`` matches (Goby's ``regex_match``)."""
        return self._regex is None or self._regex.fullmatch(name) is not None


def compile_filter(expression: str, what: str) -> NameFilter:
    """A scope filter; ValueError names the expression and why it is refused."""
    return NameFilter(expression, what)
