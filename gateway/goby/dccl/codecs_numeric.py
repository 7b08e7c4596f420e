"""Built-in fixed-size codecs: bounded numeric (DCCL's ``DefaultNumericFieldCodec``), enum, bool and time.

Each writes straight-line Python for its field, with the bounds, step and null offset folded into constants.
The arithmetic follows DCCL's C++ operation by operation (round half up as ``floor(x + 0.5)``, rounding before
the bounds check, integer division truncating toward zero, single precision for ``float`` fields), so the bits
are DCCL's. Values outside the bounds become zero bits (strict mode: ``OutOfRangeError``).
"""

from __future__ import annotations

import logging
import math
from typing import Any

from google.protobuf.descriptor import FieldDescriptor

from gateway.goby.dccl import arith
from gateway.goby.dccl.field_codec import INTEGER_TYPES, FieldContext, InlineCodec, int_width
from gateway.goby.dccl.source import Sink, Source
from util.descriptors import enum_type_of

log = logging.getLogger(__name__)

SECONDS_IN_DAY = 86400
FLT_MAX = 3.4028234663852886e38
_DOUBLE_DIGITS = 53


def describe_bounds(lo: float, hi: float, res: float) -> str:
    """``[min, max]`` with the step when it is not 1, as error messages show bounds."""
    step = f", in steps of {res:g}" if res != 1 else ""
    return f"[{lo:g}, {hi:g}]{step}"


# ------------------------------------------------------------------------------------ run-time helpers
# Used by generated code where folding the arithmetic into the source is not worth it (rare types and steps).


def int_encode(value: int, lo: float, hi: float, res: float, bits: int, signed: bool) -> int | None:
    """The unsigned code of an integer value (without the null offset), ``None`` when out of range."""
    w = arith.quantize_int(value, res)
    if not lo <= w <= hi:
        return None
    w = arith.wrap(w - arith.quantize_int(arith.wrap(arith.c_trunc(lo), bits, signed), res), bits, signed)
    w = arith.c_trunc(w / res) if res >= 1 else arith.c_trunc(w * (1.0 / res))
    return arith.wrap(w, 64, False)


def int_decode(code: int, lo: float, res: float, bits: int, signed: bool) -> int:
    """The integer value of an unsigned code (null offset already removed)."""
    w = arith.wrap(code, bits, signed)
    w = arith.c_trunc(w * res) if res >= 1 else arith.c_trunc(w / (1.0 / res))
    qmin = arith.quantize_int(arith.wrap(arith.c_trunc(lo), bits, signed), res)
    return arith.quantize_int(arith.wrap(w + qmin, bits, signed), res)


def f32_encode(value: float, lo: float, hi: float, res: float) -> int | None:
    """The code of a ``float`` field's value, computed in single precision as C++ does; ``None`` out of range."""
    w = arith.f32(arith.quantize_float(value, res))
    if not lo <= w <= hi:
        return None
    w = arith.f32(w - arith.f32(arith.quantize_float(arith.f32(lo), res)))
    w = arith.f32(w / res) if res >= 1 else arith.f32(w * (1.0 / res))
    return arith.c_trunc(arith.f32((w + 0.5) // 1.0))


def f32_decode(code: int, lo: float, res: float) -> float:
    """A ``float`` field's value from its code, in single precision."""
    w = arith.f32(float(code))
    w = arith.f32(w * res) if res >= 1 else arith.f32(w / (1.0 / res))
    qmin = arith.f32(arith.quantize_float(arith.f32(lo), res))
    return arith.f32(arith.quantize_float(arith.f32(w + qmin), res))


def time_post_decode(seconds: float, now: int, max_secs: int, factor: int, places: int, as_int: bool,
                     signed: bool) -> Any:
    """DCCL's time ``post_decode``: the time of day placed within half the window of the receiver's clock."""
    daystart = now - arith.c_rem(now, max_secs)
    today = now - daystart
    if seconds - today > max_secs // 2:
        daystart -= max_secs
    elif today - seconds > max_secs // 2:
        daystart += max_secs
    value = float(factor) * (daystart + seconds)
    if not as_int:
        return arith.round_places(value, places)
    return arith.round_int_places(arith.wrap(arith.c_trunc(value), 64, signed), places)


# ---------------------------------------------------------------------------------------------- codecs


class NumericCodec(InlineCodec):
    """Bounded numeric codec: ``ceil(log2((max - min)/step + 1 [+ 1 if optional]))`` bits."""

    def __init__(self, field: FieldContext) -> None:
        super().__init__(field)
        ftype = field.descriptor.type
        self.kind = "double" if ftype == FieldDescriptor.TYPE_DOUBLE else "float" if (
            ftype == FieldDescriptor.TYPE_FLOAT) else "int"
        self.int_bits, self.signed = int_width(ftype) if ftype in INTEGER_TYPES else (64, True)

    # DCCL's virtual bounds (the time and enum codecs override them)
    def lower(self) -> float:
        return self.field.options.min

    def upper(self) -> float:
        return self.field.options.max

    def precision(self) -> float:
        return float(self.field.options.precision)

    def resolution(self) -> float:
        options = self.field.options
        if options.HasField("precision"):
            return math.pow(10.0, -self.precision())
        return options.resolution

    @property
    def null(self) -> int:
        return 0 if self.field.required else 1

    @property
    def size(self) -> int:
        return arith.ceil_log2((self.upper() - self.lower()) / self.resolution() + 1 + self.null)

    @property
    def min_size(self) -> int:
        return self.size

    @property
    def max_size(self) -> int:
        return self.size

    def validate(self) -> None:
        options, require = self.field.options, self.field.require
        require(options.HasField("min"), "missing (dccl.field).min")
        require(options.HasField("max"), "missing (dccl.field).max")
        require(options.resolution > 0, "(dccl.field).resolution must be greater than 0")
        require(not (options.HasField("precision") and options.HasField("resolution")),
                "at most one of either (dccl.field).precision or (dccl.field).resolution can be set")
        self.validate_numeric_bounds()

    def validate_numeric_bounds(self) -> None:
        lo, hi, res, require = self.lower(), self.upper(), self.resolution(), self.field.require
        low: float
        high: float
        if self.kind == "int":
            low, high = (-(1 << (self.int_bits - 1)), (1 << (self.int_bits - 1)) - 1) if self.signed else (
                0, (1 << self.int_bits) - 1)
        else:
            low, high = (-FLT_MAX, FLT_MAX) if self.kind == "float" else (-math.inf, math.inf)
        require(lo >= low, "(dccl.field).min must be >= minimum of this field type.")
        require(hi <= high, "(dccl.field).max must be <= maximum of this field type.")
        require(hi >= lo, f"(dccl.field).max ({hi:g}) must not be less than (dccl.field).min ({lo:g})")
        on_grid = [abs(arith.quantize_float(b, res) - b) < 1e-10 for b in (lo, hi)]
        if self.field.options.HasField("resolution"):
            require(on_grid[0], "(dccl.field).min must be an exact multiple of (dccl.field).resolution")
            require(on_grid[1], "(dccl.field).max must be an exact multiple of (dccl.field).resolution")
        elif not all(on_grid):
            log.warning("%s: (dccl.field).min and max should be exact multiples of 10^(-precision), i.e. %g",
                        self.field.where, res)
        require(hi == lo or math.log2(hi - lo) - math.log2(res) <= _DOUBLE_DIGITS,
                "[(dccl.field).max-(dccl.field).min]/(dccl.field).resolution must fit in a double-precision "
                "floating point value. Please increase min, decrease max, or decrease precision.")

    def describe(self) -> dict[str, Any]:
        out: dict[str, Any] = {"min": self.lower(), "max": self.upper(), "resolution": self.resolution()}
        if self.field.options.HasField("precision"):
            out["precision"] = self.field.options.precision
        return out

    def bounds_text(self) -> str:
        return describe_bounds(self.lower(), self.upper(), self.resolution())

    # ------------------------------------------------------------------------------------ source
    def emit_pre(self, src: Source, value: str) -> str:
        """Convert the field value to the wire type (DCCL's ``pre_encode``); identity here."""
        return value

    def emit_post(self, src: Source, value: str, sink: Sink) -> None:
        """Convert the wire value back to the field (DCCL's ``post_decode``); identity here."""
        sink(src, value)

    def _qmin(self) -> float:
        if self.kind == "int":
            return arith.quantize_int(arith.wrap(arith.c_trunc(self.lower()), self.int_bits, self.signed),
                                      self.resolution())
        return arith.quantize_float(self.lower(), self.resolution())

    def emit_encode_value(self, src: Source, value: str) -> str:
        wire = self.emit_pre(src, value)
        if wire != value and not wire.isidentifier():
            name = src.tmp("x")
            src.line(f"{name} = {wire}")
            wire = name
        lo, hi, res, null = self.lower(), self.upper(), self.resolution(), self.null
        if self.kind == "double":
            w = src.tmp("w")
            src.line(f"{w} = {_quantize_source(wire, res)}")
            check = f"{lo!r} <= {w} <= {hi!r}"
            floor = src.bind(math.floor, "floor")
            good = f"{floor}({_code_source(w, self._qmin(), res)} + 0.5)" + (" + 1" if null else "")
            if _max_code(self) >= 1 << self.size:
                good = f"({good}) & {hex((1 << self.size) - 1)}"
        else:
            helper = "f32e" if self.kind == "float" else None
            if self.kind == "int" and res == 1:
                qmin = self._qmin()
                check = f"{lo!r} <= {wire} <= {hi!r}"
                shift = qmin - null
                good = f"{wire} - {shift}" if shift > 0 else f"{wire} + {-shift}" if shift < 0 else wire
                if _max_code(self) >= 1 << self.size:
                    good = f"({good}) & {hex((1 << self.size) - 1)}"
            elif self.kind == "int" and _integral_step(self):
                # DCCL's integer quantize (remainder toward zero, up from half a step), exact below 2^52
                step, qmin, w, rem = int(res), self._qmin(), src.tmp("w"), src.tmp("r")
                src.line(f"{rem} = {wire} % {step} if {wire} >= 0 else -(-{wire} % {step})")
                src.line(f"{w} = {wire} - {rem} + {step} if {rem} >= {res / 2!r} else {wire} - {rem}")
                check = f"{lo!r} <= {w} <= {hi!r}"
                good = f"int(({w} - {qmin}) / {step})" + (f" + {null}" if null else "")
                if _max_code(self) >= 1 << self.size:
                    good = f"({good}) & {hex((1 << self.size) - 1)}"
            else:
                helper = helper or "inte"
                fn = src.bind(f32_encode if self.kind == "float" else int_encode, helper)
                extra = "" if self.kind == "float" else f", {self.int_bits}, {self.signed}"
                c = src.tmp("c")
                src.line(f"{c} = {fn}({wire}, {lo!r}, {hi!r}, {res!r}{extra})")
                check = f"{c} is not None"
                good = f"({c} + {null}) & {hex((1 << self.size) - 1)}"
        return self.emit_checked(src, value, check, good)

    def emit_checked(self, src: Source, value: str, check: str, good: str) -> str:
        """A local holding ``good`` when ``check`` holds, else zero bits (strict mode: the error)."""
        code = src.tmp("u")
        if self.field.strict:
            with src.block(f"if not ({check})"):
                src.line(self.out_of_range(src, value, self.bounds_text()))
            src.line(f"{code} = {good}")
        else:
            src.line(f"{code} = {good} if {check} else 0")
        return code

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        res, null = self.resolution(), self.null
        if null:
            with src.block(f"if {bits}"):
                self._emit_decode_code(src, f"({bits} - 1)", res, sink)
        else:
            self._emit_decode_code(src, bits, res, sink)

    def _emit_decode_code(self, src: Source, code: str, res: float, sink: Sink) -> None:
        qmin = self._qmin()
        if self.kind == "double":
            if res == 1 and qmin == int(qmin) and abs(qmin) + (1 << self.size) < 1 << 52:
                expr = f"{code} + {qmin!r}"
            else:
                wire = code if res == 1 else f"{code} * {res!r}" if res >= 1 else f"{code} / {1.0 / res!r}"
                expr = _quantize_source(f"({wire} + {qmin!r})", res)
        elif self.kind == "float":
            fn = src.bind(f32_decode, "f32d")
            expr = f"{fn}({code}, {self.lower()!r}, {res!r})"
        elif (res == 1 or _integral_step(self)) and _decoded_int_fits(self, qmin, int(res)):
            scaled = code if res == 1 else f"{code} * {int(res)}"
            expr = f"{scaled} + {qmin}" if qmin else scaled
        else:
            fn = src.bind(int_decode, "intd")
            expr = f"{fn}({code}, {self.lower()!r}, {res!r}, {self.int_bits}, {self.signed})"
        self.emit_post(src, expr, sink)


def _quantize_source(value: str, res: float) -> str:
    """Source of DCCL's floating ``quantize(value, res)`` (``//`` keeps NaN and infinities exception-free)."""
    if res == 1:
        return f"({value} + 0.5) // 1.0"
    if res >= 1:
        return f"(({value} / {res!r} + 0.5) // 1.0) * {res!r}"
    inv = 1.0 / res
    return f"(({value} * {inv!r} + 0.5) // 1.0) / {inv!r}"


def _code_source(w: str, qmin: float, res: float) -> str:
    """Source of ``(w - quantize(min)) / res`` (or ``* 1/res``), before the final rounding."""
    shifted = w if qmin == 0 else f"({w} - {qmin!r})"
    if res >= 1:
        return shifted if res == 1 else f"{shifted} / {res!r}"
    return f"{shifted} * {1.0 / res!r}"


def _max_code(codec: NumericCodec) -> int:
    """The largest code an in-range value can produce (to decide whether a mask is needed)."""
    hi, res, qmin = codec.upper(), codec.resolution(), codec._qmin()
    if codec.kind == "int":
        span = (arith.c_trunc(hi) - qmin) / res if res >= 1 else (arith.c_trunc(hi) - qmin) * (1.0 / res)
    else:
        span = (hi - qmin) / res if res >= 1 else (hi - qmin) * (1.0 / res)
    return math.floor(span + 0.5) + codec.null


def _integral_step(codec: NumericCodec) -> bool:
    """An integer field with a whole step > 1 and bounds well inside a double's exact integers."""
    res = codec.resolution()
    return (res > 1 and not arith.is_fractional(res) and max(abs(codec.lower()), abs(codec.upper())) < 2.0 ** 52
            and res < 2.0 ** 52)


def _decoded_int_fits(codec: NumericCodec, qmin: float, step: int = 1) -> bool:
    """True when every code decodes without overflowing the field's integer type (no wrapping needed)."""
    codes = (1 << codec.size) - 1
    low, high = (-(1 << (codec.int_bits - 1)), (1 << (codec.int_bits - 1)) - 1) if codec.signed else (
        0, (1 << codec.int_bits) - 1)
    return low <= qmin and codes * step <= high and codes * step + qmin <= high and codes * step < 1 << 52


class EnumCodec(NumericCodec):
    """Enums as the numeric codec over their declaration index (``packed_enum``, the default) or number."""

    def __init__(self, field: FieldContext) -> None:
        super().__init__(field)
        self.kind, self.int_bits, self.signed = "int", 32, True
        self.numbers = [v.number for v in enum_type_of(field.descriptor).values]
        self.packed = field.options.packed_enum

    def lower(self) -> float:
        return 0.0 if self.packed else float(min(self.numbers))

    def upper(self) -> float:
        return float(len(self.numbers) - 1) if self.packed else float(max(self.numbers))

    def validate(self) -> None:
        """DCCL validates nothing for enums."""

    def describe(self) -> dict[str, Any]:
        values = enum_type_of(self.field.descriptor).values
        return {"enum": [(v.name, v.number) for v in values]}

    def bounds_text(self) -> str:
        return "{" + ", ".join(v.name for v in enum_type_of(self.field.descriptor).values) + "}"

    def _simple(self) -> bool:
        return self.packed and self.resolution() == 1

    def emit_encode_value(self, src: Source, value: str) -> str:
        if not self._simple():
            return super().emit_encode_value(src, value)
        # number -> code in one lookup; an unknown number has no entry (zero bits, or the strict error)
        table = src.bind({n: i + self.null for i, n in enumerate(self.numbers)}, "enc")
        if not self.field.strict:
            return f"{table}.get({value}, 0)"
        return self.emit_checked(src, value, f"{value} in {table}", f"{table}[{value}]")

    def emit_pre(self, src: Source, value: str) -> str:
        if not self.packed:
            return value
        table = src.bind({n: i for i, n in enumerate(self.numbers)}, "idx")
        return f"{table}.get({value}, -1)"

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        if not self._simple():
            super().emit_decode_value(src, bits, sink)
            return
        table = src.bind(tuple([None] * self.null + self.numbers), "num")
        if len(self.numbers) + self.null == 1 << self.size:  # every code is a value (or the null)
            if self.null:
                with src.block(f"if {bits}"):
                    sink(src, f"{table}[{bits}]")
            else:
                sink(src, f"{table}[{bits}]")
            return
        with src.block(f"if {'0 < ' if self.null else ''}{bits} < {len(self.numbers) + self.null}"):
            sink(src, f"{table}[{bits}]")

    def emit_post(self, src: Source, value: str, sink: Sink) -> None:
        wire = src.tmp("e")
        src.line(f"{wire} = {value}")
        if self.packed:
            table = src.bind(tuple(self.numbers), "num")
            with src.block(f"if 0 <= {wire} < {len(self.numbers)}"):
                sink(src, f"{table}[{wire}]")
        else:
            known = src.bind(frozenset(self.numbers), "known")
            with src.block(f"if {wire} in {known}"):
                sink(src, wire)


class BoolCodec(InlineCodec):
    """Bools: 1 bit when required; 2 bits when optional (0 unset, 1 false, 2 true)."""

    @property
    def min_size(self) -> int:
        return arith.ceil_log2(2 + (0 if self.field.required else 1))

    max_size = min_size

    def emit_encode_value(self, src: Source, value: str) -> str:
        return f"(2 if {value} else 1)" if not self.field.required else f"(1 if {value} else 0)"

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        if self.field.required:
            sink(src, f"{bits} != 0")
        else:
            with src.block(f"if {bits}"):
                sink(src, f"{bits} != 1")


class TimeCodec(NumericCodec):
    """``dccl.time2``/``dccl.time3``: the time of day (within ``num_days``) as a bounded number of seconds.

    ``double`` fields hold seconds since 1970, ``int64``/``uint64`` microseconds. Decoding places the time of
    day within half the window (12 h by default) of the receiver's clock.
    """

    needs_clock = True

    def __init__(self, field: FieldContext) -> None:
        super().__init__(field)
        self.as_int = field.descriptor.type != FieldDescriptor.TYPE_DOUBLE
        self.time_signed = field.descriptor.type in {FieldDescriptor.TYPE_INT64, FieldDescriptor.TYPE_SINT64,
                                                     FieldDescriptor.TYPE_SFIXED64}
        self.factor = 1000000 if self.as_int else 1
        self.kind = "double"  # DCCL's wire type for time is double whatever the field type

    def lower(self) -> float:
        return 0.0

    def upper(self) -> float:
        return float(self.field.options.num_days * SECONDS_IN_DAY)

    def precision(self) -> float:
        options = self.field.options
        if not options.HasField("precision"):
            return 0.0
        return options.precision + math.log10(float(self.factor))

    def validate(self) -> None:
        self.field.require(self.field.options.num_days >= 1, "(dccl.field).num_days must be at least 1")
        self.validate_numeric_bounds()

    def describe(self) -> dict[str, Any]:
        return {"time": True, "num_days": self.field.options.num_days, "resolution": self.resolution()}

    def emit_pre(self, src: Source, value: str) -> str:
        period = self.upper()
        seconds = f"{value} / {float(self.factor)!r}" if self.as_int else value
        t = src.tmp("t")
        fmod = src.bind(arith.c_fmod, "fmod")
        # for a non-negative finite number Python's % is C's fmod; anything else takes the exact path
        if self.as_int:
            src.line(f"{t} = {seconds}")
            seconds = t
        src.line(f"{t} = {seconds} % {period!r} if {seconds} >= 0.0 else {fmod}({seconds}, {period!r})")
        return t

    def emit_post(self, src: Source, value: str, sink: Sink) -> None:
        places = int(self.precision() - math.log10(float(self.factor)))
        period = int(self.upper())
        if not self.as_int and places == 0:
            ds, today = src.tmp("ds"), src.tmp("td")
            w = src.tmp("w")
            src.line(f"{w} = {value}")
            src.line(f"{ds} = now - now % {period}")  # now >= 0: Python's % is C's here
            src.line(f"{today} = now - {ds}")
            with src.block(f"if {w} - {today} > {period // 2}"):
                src.line(f"{ds} -= {period}")
            with src.block(f"elif {today} - {w} > {period // 2}"):
                src.line(f"{ds} += {period}")
            sink(src, f"({ds} + {w} + 0.5) // 1.0")
            return
        fn = src.bind(time_post_decode, "tpost")
        sink(src, f"{fn}({value}, now, {period}, {self.factor}, {places}, {self.as_int}, {self.time_signed})")
