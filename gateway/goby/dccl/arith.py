"""DCCL's integer and floating-point helpers (``binary.h``, ``common.h``) with C++'s exact semantics.

Why a module of its own: DCCL's bytes depend on C++ details that Python does differently: integer ``%`` and
``/`` truncate toward zero, ``round`` is ``floor(x + 0.5)``, casts wrap, ``float`` fields compute in single
precision. The compiler folds these into generated code where it can and calls these functions where it cannot.
"""

from __future__ import annotations

import math
import struct

DBL_EPSILON = 2.220446049250313e-16
_F32 = struct.Struct("<f")


def ceil_log2(value: int | float) -> int:
    """Bits needed for ``value`` distinct values: DCCL's ``ceil_log2`` (``ceil`` first, then integer log2)."""
    v = math.ceil(value) if isinstance(value, float) else value
    if v <= 0:
        return 0  # C++ would cast a negative to uint64; definitions that get here are refused at load
    return (v.bit_length() - 1) + (0 if v & (v - 1) == 0 else 1)


def bits2bytes(bits: int) -> int:
    """Whole bytes holding ``bits`` (DCCL's ``ceil_bits2bytes``)."""
    return (bits + 7) >> 3


def c_rem(a: int, b: int) -> int:
    """C++ ``a % b`` on integers: the remainder takes the sign of ``a`` (truncating division)."""
    r = abs(a) % abs(b)
    return r if a >= 0 else -r


def c_trunc(x: float) -> int:
    """C++ conversion of a double to an integer type: toward zero (callers wrap to the type's width)."""
    return int(x) if math.isfinite(x) else 0


def wrap(value: int, bits: int, signed: bool) -> int:
    """``value`` cast to a ``bits``-wide C++ integer (two's complement), as ``static_cast`` does."""
    value &= (1 << bits) - 1
    if signed and value >> (bits - 1):
        value -= 1 << bits
    return value


def f32(x: float) -> float:
    """``x`` rounded to single precision, as a C++ ``float`` holds it (overflow becomes infinity, as in C)."""
    try:
        return _F32.unpack(_F32.pack(x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)


def c_fmod(x: float, y: float) -> float:
    """C's ``fmod``: NaN (not an exception) for an infinite ``x``."""
    if math.isinf(x):
        return math.nan
    return math.fmod(x, y)


def round_places(x: float, places: int) -> float:
    """DCCL's ``round(value, precision)`` for floating types: ``floor(x * 10^p + 0.5) / 10^p``."""
    scale = math.pow(10.0, places)
    return ((x * scale + 0.5) // 1.0) / scale


def round_int_places(value: int, places: int) -> int:
    """DCCL's ``round(value, precision)`` for integer types: only a negative precision changes anything.

    The remainder truncates toward zero, so negative values round toward zero, as in C++.
    """
    if places >= 0:
        return value
    scale = int(math.pow(10.0, -places))
    rem = c_rem(value, scale)
    value -= rem
    if rem >= scale // 2:
        value += scale
    return value


def quantize_float(x: float, interval: float) -> float:
    """DCCL's ``quantize`` for floating types: to the nearest multiple of ``interval``, halves up."""
    if interval >= 1:
        return ((x / interval + 0.5) // 1.0) * interval
    inv = 1.0 / interval
    return ((x * inv + 0.5) // 1.0) / inv


def is_fractional(interval: float) -> bool:
    """True when DCCL leaves integers alone: an interval with a fractional part (``common.h``)."""
    return (interval - float(int(interval))) >= DBL_EPSILON


def quantize_int(value: int, interval: float) -> int:
    """DCCL's ``quantize`` for integer types: remainder toward zero, then up if at least half a step."""
    if is_fractional(interval):
        return value
    step = int(interval)
    rem = c_rem(value, step)
    value -= rem
    if rem >= interval / 2:
        value = c_trunc(float(value) + interval) if abs(value) >= 1 << 53 else value + step
    return value
