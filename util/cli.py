"""argparse ``type=`` validators for numbers: finite, within bounds, one clear message naming the value.

Console scripts use these so ``--timeout -1`` or ``--warp nan`` stop at parse time (argparse exits 2 with the
option's name) instead of misbehaving later.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TypeVar

N = TypeVar("N", int, float)


def bounded_number(kind: type[N], low: float = -math.inf, high: float = math.inf,
                   low_inclusive: bool = True) -> Callable[[str], N]:
    """A validator: ``kind(text)`` (int or float), finite and within [low, high] (or (low, high])."""

    def parse(text: str) -> N:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a {'whole ' if kind is int else ''}number") from None
        above = value >= low if low_inclusive else value > low
        if not (math.isfinite(value) and above and value <= high):
            left = "[" if low_inclusive else "("
            raise argparse.ArgumentTypeError(f"{text!r} is not a finite number in {left}{low:g}, {high:g}]")
        return value

    parse.__name__ = kind.__name__  # argparse names the type in its messages
    return parse


positive_number = bounded_number(float, 0.0, math.inf, low_inclusive=False)
"""A finite number > 0 (timeouts, periods, time warps)."""
