"""Progress lines of the benchmarks: on stderr, so the tables on stdout stay clean to paste."""

from __future__ import annotations

import sys


def progress(line: str) -> None:
    print(line, file=sys.stderr, flush=True)
