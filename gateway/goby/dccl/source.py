"""Writing the Python source of a message type's encode/decode functions: lines, local names, bit cursors.

A DCCL message part is one little-endian integer, the first field in the lowest bits. The generated encoder
ORs each field's value into an accumulator at its bit position; the decoder shifts and masks. Positions are
compile-time constants until the first variable-size field; from there on a local variable carries them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

#: Emits the statement that stores a decoded value (given as an expression) where it belongs.
Sink = Callable[["Source", str], None]


class Source:
    """Lines of Python with indentation, unique local names, and the namespace the code runs in."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.namespace: dict[str, Any] = {}
        self._depth = 0
        self._count = 0

    def line(self, text: str) -> None:
        self.lines.append("    " * self._depth + text)

    @contextmanager
    def block(self, header: str) -> Iterator[None]:
        """An indented block under ``header`` (``pass`` if nothing was written in it)."""
        self.line(header + ":")
        self._depth += 1
        start = len(self.lines)
        try:
            yield
        finally:
            if len(self.lines) == start:
                self.line("pass")
            self._depth -= 1

    def tmp(self, hint: str) -> str:
        """A fresh local variable name."""
        self._count += 1
        return f"{hint}{self._count}"

    def bind(self, value: Any, hint: str) -> str:
        """A global name in the generated module for ``value`` (tables, codec objects, helpers)."""
        for name, existing in self.namespace.items():
            if existing is value and name.startswith(f"_{hint}"):
                return name
        self._count += 1
        name = f"_{hint}{self._count}"
        self.namespace[name] = value
        return name

    def text(self) -> str:
        return "\n".join(self.lines) + "\n"


def shifted(expr: str, pos: str) -> str:
    """``expr << pos`` without the no-op shift."""
    return expr if pos == "0" else f"({expr}) << {pos}"


class BitCursor:
    """Where the next field goes: a constant offset, or a local variable plus a constant once sizes vary.

    Code that branches on the data (optional parts, loops, lengths) goes in :meth:`block`: the position is
    put into the variable before the branch and brought up to date at the end of each path, so every path
    leaves the cursor in the same state.
    """

    def __init__(self, src: Source, var: str) -> None:
        self.src = src
        self.var = var  # local that holds the position once it is dynamic
        self.dynamic = False
        self.offset = 0

    def pos(self) -> str:
        if not self.dynamic:
            return str(self.offset)
        return self.var if self.offset == 0 else f"{self.var} + {self.offset}"

    def sync(self) -> None:
        """Put the position into the local variable."""
        if not self.dynamic:
            self.src.line(f"{self.var} = {self.offset}")
            self.dynamic = True
        elif self.offset:
            self.src.line(f"{self.var} += {self.offset}")
        self.offset = 0

    def advance(self, width: int | str) -> None:
        """Move past ``width`` bits (a constant is folded into the offset, an expression is added at run time)."""
        if isinstance(width, int):
            self.offset += width
            return
        self.sync()
        self.src.line(f"{self.var} += {width}")

    @contextmanager
    def block(self, header: str) -> Iterator[None]:
        """A branch (``if``/``else``/``for`` ...) whose paths move the cursor differently."""
        self.sync()
        with self.src.block(header):
            yield
            self.sync()


class BitWriter(BitCursor):
    """Encoder side: ORs values into the accumulator ``acc`` at the cursor."""

    def __init__(self, src: Source, acc: str, var: str) -> None:
        super().__init__(src, var)
        self.acc = acc

    def put(self, value: str, width: int | str) -> None:
        """Write ``value`` (already within ``width`` bits) and move past it."""
        if width != 0 and value != "0":
            self.src.line(f"{self.acc} |= {shifted(value, self.pos())}")
        self.advance(width)


class BitReader(BitCursor):
    """Decoder side: reads fields from the integer ``bits`` at the cursor."""

    def __init__(self, src: Source, bits: str, var: str) -> None:
        super().__init__(src, var)
        self.bits = bits

    def peek(self, width: int | str) -> str:
        """An expression for the next ``width`` bits (the cursor does not move)."""
        if width == 0:
            return "0"
        value = self.bits if self.pos() == "0" else f"({self.bits} >> {self.pos()})"
        mask = hex((1 << width) - 1) if isinstance(width, int) else f"((1 << ({width})) - 1)"
        return f"{value} & {mask}"

    def take(self, width: int | str, hint: str = "u") -> str:
        """Read the next ``width`` bits into a fresh local and move past them."""
        name = self.src.tmp(hint)
        self.src.line(f"{name} = {self.peek(width)}")
        self.advance(width)
        return name
