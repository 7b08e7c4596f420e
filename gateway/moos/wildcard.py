"""``MOOSWildCmp``: glob matching with ``*`` (any run) and ``?`` (one character), case-sensitive, anchored.

Unlike ``fnmatch`` there are no character classes: ``[`` matches itself, as in libMOOS.
"""

from __future__ import annotations

import re
from functools import lru_cache


@lru_cache(maxsize=4096)
def _compile(pattern: bytes) -> re.Pattern[bytes]:
    parts = []
    for byte in pattern:
        ch = bytes((byte,))
        if ch == b"*":
            parts.append(b".*")
        elif ch == b"?":
            parts.append(b".")
        else:
            parts.append(re.escape(ch))
    return re.compile(b"".join(parts), re.DOTALL)


def wild_match(pattern: bytes, text: bytes) -> bool:
    """True when ``text`` matches the MOOS wildcard ``pattern`` over its whole length."""
    if pattern == b"*":
        return True
    return _compile(pattern).fullmatch(text) is not None
