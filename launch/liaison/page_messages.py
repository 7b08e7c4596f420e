"""The JSON of the page's WebSocket: decoding what a page sends (bounded, checked) and encoding what it is sent.

Why here and not in the handlers: a page message is untrusted input.  Its nesting is checked before
``json.loads`` (50,000 nested arrays would raise RecursionError inside it), ``NaN``/``Infinity`` are refused,
and the fields a handler uses as an id or a name are checked for type and range (``1e400`` is a float, not an
id).  The other direction must never fail: :func:`encode` turns a non-finite number into ``null`` instead of
raising ``Out of range float values are not JSON compliant``.  Pure functions: any thread.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

MAX_DEPTH = 32  # nesting of arrays/objects in one page message (a command form nests a few levels)
MAX_ID = 2**31 - 1
MAX_NAME_CHARS = 256  # a type name, a view name, an op
_STRUCTURE = re.compile(r'[\[\]{}"\\]')


class PageMessageError(ValueError):
    """A page message that is refused; the text names the cause (and the field)."""


def _too_deep(text: str, limit: int) -> bool:
    """Whether arrays/objects nest deeper than ``limit`` (brackets inside strings do not count)."""
    if text.count("[") + text.count("{") <= limit:
        return False  # cannot nest deeper than it has brackets
    depth = 0
    in_string = False
    escaped_at = -1
    for match in _STRUCTURE.finditer(text):
        char, at = match.group(), match.start()
        if in_string:
            if char == "\\" and at != escaped_at:
                escaped_at = at + 1  # the next character is escaped
            elif char == '"' and at != escaped_at:
                in_string = False
        elif char == '"':
            in_string = True
        elif char in "[{":
            depth += 1
            if depth > limit:
                return True
        elif char in "]}":
            depth -= 1
    return False


def _refuse_constant(name: str) -> Any:
    raise PageMessageError(f"{name} is not a number this page accepts")


def parse(text: str) -> dict[str, Any]:
    """One page message as a dict with an ``op`` string; PageMessageError names what is wrong."""
    if _too_deep(text, MAX_DEPTH):
        raise PageMessageError(f"message nests arrays/objects deeper than {MAX_DEPTH} levels")
    try:
        request = json.loads(text, parse_constant=_refuse_constant)
    except PageMessageError:
        raise
    except (ValueError, RecursionError) as exc:
        raise PageMessageError(f"message is not JSON: {exc}") from None
    if not isinstance(request, dict) or not isinstance(request.get("op"), str):
        raise PageMessageError('message must be a JSON object with an "op" string')
    if len(request["op"]) > MAX_NAME_CHARS:
        raise PageMessageError(f'"op" is longer than {MAX_NAME_CHARS} characters')
    return request


def int_field(request: dict[str, Any], name: str, low: int = 0, high: int = MAX_ID) -> int:
    """A required integer field in ``[low, high]`` (not a bool, not a float such as ``1e400``)."""
    if name not in request:
        raise PageMessageError(f'"{name}" is missing')
    value = request[name]
    if not isinstance(value, int) or isinstance(value, bool):
        raise PageMessageError(f'"{name}" must be an integer, not {_shown(value)}')
    if not low <= value <= high:
        raise PageMessageError(f'"{name}" {_shown(value)} is outside [{low}, {high}]')
    return value


def float_field(request: dict[str, Any], name: str, low: float, high: float) -> float:
    """A required finite number in ``[low, high]`` (an integer is accepted, a bool is not)."""
    if name not in request:
        raise PageMessageError(f'"{name}" is missing')
    value = request[name]
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise PageMessageError(f'"{name}" must be a number, not {_shown(value)}')
    if not (math.isfinite(value) and low <= value <= high):
        raise PageMessageError(f'"{name}" {_shown(value)} is outside [{low:g}, {high:g}]')
    return float(value)


def str_field(request: dict[str, Any], name: str, default: str, max_chars: int = MAX_NAME_CHARS) -> str:
    """An optional string field of at most ``max_chars`` characters."""
    value = request.get(name, default)
    if not isinstance(value, str):
        raise PageMessageError(f'"{name}" must be a string, not {_shown(value)}')
    if len(value) > max_chars:
        raise PageMessageError(f'"{name}" is {len(value)} characters long (at most {max_chars})')
    return value


def _shown(value: Any) -> str:
    text = json.dumps(value, default=str) if not isinstance(value, float) or math.isfinite(value) else str(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _finite(obj: Any) -> Any:
    """``obj`` with every non-finite float replaced by None (the slow path of :func:`encode`)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {str(k): _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    return obj


def encode(obj: Any) -> tuple[str, bool]:
    """Compact JSON that never fails on a number: (text, whether non-finite values were replaced by null)."""
    try:
        return json.dumps(obj, separators=(",", ":"), allow_nan=False, default=str), False
    except ValueError:
        return json.dumps(_finite(obj), separators=(",", ":"), allow_nan=False, default=str), True
