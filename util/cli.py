"""Command-line helpers for the console scripts: ``type=`` validators for numbers (finite, within bounds, one clear
message naming the value, so ``--timeout -1`` or ``--warp nan`` stop at parse time) and the help formatter every
parser uses.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
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


class HelpFormatter(argparse.HelpFormatter):
    """argparse's help formatter, sized to the terminal without importing ``shutil``: argparse imports it (with bz2
    and lzma, 0.5 MiB of private memory) for every parser it builds, in every long-running process."""

    def __init__(self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
                 width: int | None = None) -> None:
        super().__init__(prog, indent_increment, max_help_position,
                         width if width is not None else terminal_columns() - 2)


def terminal_columns(fallback: int = 80) -> int:
    """``shutil.get_terminal_size().columns``: ``$COLUMNS``, else the terminal on stdout, else ``fallback``."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            columns = 0
    return columns if columns > 0 else fallback
