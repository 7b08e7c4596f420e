"""Summary statistics shared by the benchmarks, so every table reports p99 the same way."""

from __future__ import annotations

import statistics
from collections.abc import Sequence


def percentile(values: Sequence[float], q: float) -> float:
    """The nearest-rank ``q`` quantile (0..1) of ``values``."""
    if not values:
        raise ValueError("percentile of no values")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def median_p99(values: Sequence[float]) -> tuple[float, float]:
    """(median, p99) of ``values``."""
    return statistics.median(values), percentile(values, 0.99)


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown table (pasteable into docs), columns padded to their widest cell."""
    widths = [max(len(str(c)) for c in column) for column in zip(header, *rows, strict=True)]
    lines = [header, ["-" * w for w in widths], *rows]
    return "\n".join("| " + " | ".join(f"{str(c):<{w}}" for c, w in zip(line, widths, strict=True)) + " |" for line in lines)
