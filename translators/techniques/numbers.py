"""Number and value spelling shared by the techniques: C++ stream/``printf`` formatting and Boost-style casts.

Why: MOOS apps parse what the C++ gateway writes, so ``550.0`` must print as ``550`` (``%.15g``), and strings
coming back from MOOS must convert with ``boost::lexical_cast``'s strictness (no whitespace, no ``1_000``),
falling back the way ``goby::util::as`` does (NaN for reals, the type's maximum for integers).
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Callable

from google.protobuf.descriptor import FieldDescriptor

_REAL = re.compile(
    r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan(?:\([0-9A-Za-z_]*\))?)\Z", re.IGNORECASE
)
_INTEGER = re.compile(r"[+-]?\d+\Z")

INT_LIMITS = {
    FieldDescriptor.CPPTYPE_INT32: (-(2**31), 2**31 - 1),
    FieldDescriptor.CPPTYPE_INT64: (-(2**63), 2**63 - 1),
    FieldDescriptor.CPPTYPE_UINT32: (0, 2**32 - 1),
    FieldDescriptor.CPPTYPE_UINT64: (0, 2**64 - 1),
}


def stream_double(value: float) -> str:
    """A double as ``std::ostream`` with ``setprecision(15)`` writes it (``%.15g``)."""
    return _g(value, 15)


def stream_float(value: float) -> str:
    """A float as ``std::ostream`` with ``setprecision(6)`` writes it (``%.6g``)."""
    return _g(value, 6)


def _g(value: float, precision: int) -> str:
    if math.isnan(value):
        return "-nan" if math.copysign(1.0, value) < 0 else "nan"
    return f"{value:.{precision}g}"


def simple_dtoa(value: float) -> str:
    """Protobuf C++ ``SimpleDtoa`` (text format doubles): ``%.15g``, or ``%.17g`` if that does not round-trip."""
    return _round_trip(value, 15, 17, float)


def simple_ftoa(value: float) -> str:
    """Protobuf C++ ``SimpleFtoa`` (text format floats): ``%.6g``, or ``%.9g`` if that does not round-trip."""
    return _round_trip(value, 6, 9, _as_float32)


def _round_trip(value: float, short_digits: int, long_digits: int, stored: Callable[[float], float]) -> str:
    """``%.<short>g`` if it reads back as the same ``stored`` value, else ``%.<long>g``; nan/inf as protobuf."""
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    short = f"{value:.{short_digits}g}"
    return short if stored(float(short)) == stored(value) else f"{value:.{long_digits}g}"


def _as_float32(value: float) -> float:
    try:
        return struct.unpack("<f", struct.pack("<f", value))[0]
    except OverflowError:
        return math.copysign(math.inf, value)


def lexical_real(text: str) -> float:
    """``goby::util::as<double>``: the whole string must be a number, else NaN."""
    return float(text) if _REAL.match(text) else math.nan


def lexical_integer(text: str, cpp_type: int) -> int:
    """``goby::util::as<intN>``: the whole string must be an integer in range, else the type's maximum.

    As ``boost::lexical_cast``, a leading ``-`` on an unsigned type wraps around (``-1`` -> max).
    """
    low, high = INT_LIMITS[cpp_type]
    if not _INTEGER.match(text):
        return high
    value = int(text)
    if low == 0 and value < 0 and -value <= high:
        return value % (high + 1)
    return value if low <= value <= high else high


def lexical_bool(text: str) -> bool:
    """``goby::util::as<bool>``: true for ``true`` (any case) or ``1``."""
    return text.lower() in ("true", "1")


def hex_encode(data: bytes) -> str:
    """``goby::util::hex_encode``: lowercase, two characters per byte."""
    return data.hex()


def hex_decode(text: str) -> bytes:
    """``goby::util::hex_decode``: either case; an odd length reads as if it had a leading ``0``."""
    if len(text) % 2:
        text = "0" + text
    return bytes.fromhex(text)
