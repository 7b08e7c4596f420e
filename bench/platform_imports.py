"""Read ``python -X importtime`` output (``PYTHONPROFILEIMPORTTIME=1``): which modules cost the most import time
in a process, and which chain of imports pulled each one in.

CPython prints one line per module when its import ends, children before their parent
(``import time: <self us> | <cumulative us> | <two spaces per nesting level><module>``), so a line's parent is the
next line one level up. A module imported at run time (a lazy import inside a function) is a top-level line.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field

PREFIX = "import time:"


@dataclass
class ImportRecord:
    """One imported module: its own and cumulative import time (µs), nesting level (0 = top) and importer."""

    name: str
    self_us: int
    cumulative_us: int
    level: int
    parent: ImportRecord | None = field(default=None, repr=False)

    def chain(self) -> list[str]:
        """The importers from the top-level import down to this module."""
        names: list[str] = []
        record: ImportRecord | None = self
        while record is not None:
            names.append(record.name)
            record = record.parent
        return names[::-1]


def parse_importtime(lines: Iterable[str]) -> list[ImportRecord]:
    """The records of every ``import time:`` line, parents linked; other lines (the program's log) are skipped."""
    records: list[ImportRecord] = []
    pending: list[ImportRecord] = []  # imported, importer not seen yet
    for line in lines:
        if not line.startswith(PREFIX):
            continue
        parts = line[len(PREFIX):].split("|", 2)
        if len(parts) != 3:
            continue
        try:
            self_us, cumulative_us = int(parts[0]), int(parts[1])
        except ValueError:  # the header line
            continue
        text = parts[2].rstrip("\n")
        name = text.strip()
        level = max(0, (len(text) - len(text.lstrip(" ")) - 1) // 2)
        record = ImportRecord(name, self_us, cumulative_us, level)
        while pending and pending[-1].level == level + 1:
            pending.pop().parent = record
        pending.append(record)
        records.append(record)
    return records


def top_by_self(records: Iterable[ImportRecord], n: int) -> list[ImportRecord]:
    """The ``n`` modules with the most import time of their own."""
    return sorted(records, key=lambda r: -r.self_us)[:n]


def self_time_by_package(records: Iterable[ImportRecord]) -> Counter[str]:
    """Own import time (µs) summed per top-level package (``google``, ``zmq``, ``gateway``, ...)."""
    totals: Counter[str] = Counter()
    for record in records:
        totals[record.name.split(".", 1)[0]] += record.self_us
    return totals


def total_us(records: Iterable[ImportRecord]) -> int:
    """The whole import time: the cumulative times of the top-level imports."""
    return sum(r.cumulative_us for r in records if r.level == 0)


def describe(record: ImportRecord, max_chain: int = 5) -> str:
    """``module  self ms (cumulative ms)  <- importer <- ... <- top-level import``, the chain cut to ``max_chain``."""
    importers = record.chain()[:-1][::-1]
    if len(importers) > max_chain:
        importers = [*importers[: max_chain - 1], "...", importers[-1]]
    via = " <- ".join(importers) if importers else "(top level: imported by the program or at run time)"
    return f"{record.name}  {record.self_us / 1000:.1f} ms ({record.cumulative_us / 1000:.1f} ms)  <- {via}"
