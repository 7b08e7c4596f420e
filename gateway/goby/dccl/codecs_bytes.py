"""Built-in codecs for strings and bytes, static values, ids as fields, and DCCL's presence-bit wrapper.

Strings and byte strings go on the wire as their bytes in order, each byte LSB first, above a length prefix
(v3: ``ceil(log2(max_length + 1))`` bits; v2: 8 bits). DCCL's fixed-size ``bytes`` codec pads to
``max_length``; ``dccl.var_bytes`` sends a prefix instead.
"""

from __future__ import annotations

import re
from typing import Any

from google.protobuf.descriptor import FieldDescriptor

from gateway.goby.dccl import arith, ids
from gateway.goby.dccl.errors import DecodeError, EncodeError, OutOfRangeError
from gateway.goby.dccl.field_codec import FieldContext, InlineCodec
from gateway.goby.dccl.source import BitReader, BitWriter, Sink, Source

V2_STRING_MAX = 255


def text_bytes(value: str, limit: int) -> bytes:
    """A string's UTF-8 bytes cut to ``limit`` on a character boundary (Python strings cannot hold half one)."""
    data = value.encode()
    if len(data) > limit:
        data = data[:limit].decode("utf-8", "ignore").encode()
    return data


def utf8(data: bytes, where: str) -> str:
    """Decoded text, or a ``DecodeError`` naming the field."""
    try:
        return data.decode()
    except UnicodeDecodeError as exc:
        raise DecodeError(f"{where}: the decoded bytes are not UTF-8 text ({exc.reason})") from None


class _ByteStringCodec(InlineCodec):
    """Shared by the string, bytes and var_bytes codecs: limits, truncation and text conversion."""

    is_text: bool

    def __init__(self, field: FieldContext) -> None:
        super().__init__(field)
        self.is_text = field.descriptor.type == FieldDescriptor.TYPE_STRING
        self.limit = field.options.max_length

    def validate(self) -> None:
        self.field.require(self.field.options.HasField("max_length"), "missing (dccl.field).max_length")

    def describe(self) -> dict[str, Any]:
        return {"max_length": self.limit}

    def emit_payload(self, src: Source, value: str) -> str:
        """Statements giving the bytes to send (truncated, or the strict error); return their local."""
        data = src.tmp("s")
        if self.is_text:
            src.line(f"{data} = {value}.encode()")
        else:
            src.line(f"{data} = {value}")
        with src.block(f"if len({data}) > {self.limit}"):
            if self.field.strict:
                error = src.bind(OutOfRangeError, "OutOfRange")
                src.line(f"raise {error}({self.field.where!r}, {value}, 'max_length {self.limit}')")
            elif self.is_text:
                src.line(f"{data} = {src.bind(text_bytes, 'cut')}({value}, {self.limit})")
            else:
                src.line(f"{data} = {data}[:{self.limit}]")
        return data

    def emit_value(self, src: Source, data: str) -> str:
        """The field value for the decoded bytes ``data``."""
        if not self.is_text:
            return data
        return f"{src.bind(utf8, 'utf8')}({data}, {self.field.where!r})"

    def emit_length_check(self, src: Source, length: str) -> None:
        """Refuse a length prefix above max_length: no DCCL encoder writes one."""
        with src.block(f"if {length} > {self.limit}"):
            error = src.bind(DecodeError, "DecodeError")
            src.line(f"raise {error}(f'{self.field.where}: length {{{length}}} exceeds max_length {self.limit}')")

    def emit_read_bytes(self, src: Source, bits: BitReader, length: str) -> str:
        """Read ``length`` bytes at the (synced) cursor; return the local holding them."""
        data = src.tmp("s")
        src.line(f"{data} = ({bits.peek(f'{length} * 8')}).to_bytes({length}, 'little')")
        bits.advance(f"{length} * 8")
        return data


class StringCodec(_ByteStringCodec):
    """Strings: a length prefix, then the bytes; an empty string decodes as unset (DCCL v3, and v2's 8-bit
    prefix with ``v2=True``)."""

    variable = True

    def __init__(self, field: FieldContext, *, v2: bool = False) -> None:
        super().__init__(field)
        self.v2 = v2
        self.prefix = arith.ceil_log2(V2_STRING_MAX + 1) if v2 else arith.ceil_log2(self.limit + 1)

    def validate(self) -> None:
        super().validate()
        if self.v2:
            self.field.require(self.limit <= V2_STRING_MAX, f"(dccl.field).max_length must be <= {V2_STRING_MAX}")

    @property
    def min_size(self) -> int:
        return self.prefix

    @property
    def max_size(self) -> int:
        return self.prefix + 8 * self.limit

    def emit_encode(self, src: Source, out: BitWriter, value: str) -> None:
        data = self.emit_payload(src, value)
        length = src.tmp("n")
        src.line(f"{length} = len({data})")
        out.put(f"{length} | (int.from_bytes({data}, 'little') << {self.prefix})", f"{self.prefix} + 8 * {length}")

    def emit_decode(self, src: Source, bits: BitReader, sink: Sink) -> None:
        length = bits.take(self.prefix, "n")
        with bits.block(f"if {length}"):
            self.emit_length_check(src, length)
            sink(src, self.emit_value(src, self.emit_read_bytes(src, bits, length)))


class BytesCodec(_ByteStringCodec):
    """``bytes`` fields: always ``max_length`` bytes (zero-padded); optional ones get a presence bit first."""

    @property
    def variable(self) -> bool:  # type: ignore[override]
        return not self.field.required

    @property
    def min_size(self) -> int:
        return 8 * self.limit if self.field.required else 1

    @property
    def max_size(self) -> int:
        return 8 * self.limit + (0 if self.field.required else 1)

    def emit_encode_value(self, src: Source, value: str) -> str:
        return f"int.from_bytes({self.emit_payload(src, value)}, 'little')"

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        sink(src, f"{bits}.to_bytes({self.limit}, 'little')")

    def emit_encode(self, src: Source, out: BitWriter, value: str) -> None:
        data = self.emit_payload(src, value)
        out.put(f"1 | (int.from_bytes({data}, 'little') << 1)", 1 + 8 * self.limit)

    def emit_decode(self, src: Source, bits: BitReader, sink: Sink) -> None:
        present = bits.take(1, "h")
        with bits.block(f"if {present}"):
            data = bits.take(8 * self.limit, "s")
            sink(src, f"{data}.to_bytes({self.limit}, 'little')")


class VarBytesCodec(_ByteStringCodec):
    """``dccl.var_bytes``: [presence bit if optional][length prefix][bytes]."""

    variable = True

    def __init__(self, field: FieldContext) -> None:
        super().__init__(field)
        self.prefix = arith.ceil_log2(self.limit + 1)
        self.presence = 0 if field.required else 1

    @property
    def min_size(self) -> int:
        return self.prefix if self.field.required else self.presence

    @property
    def max_size(self) -> int:
        return self.presence + self.prefix + 8 * self.limit

    def emit_encode(self, src: Source, out: BitWriter, value: str) -> None:
        data = self.emit_payload(src, value)
        length = src.tmp("n")
        src.line(f"{length} = len({data})")
        head = f"({length} << 1) | 1" if self.presence else length
        out.put(f"{head} | (int.from_bytes({data}, 'little') << {self.presence + self.prefix})",
                f"{self.presence + self.prefix} + 8 * {length}")

    def emit_decode(self, src: Source, bits: BitReader, sink: Sink) -> None:
        if self.presence:
            present = bits.take(1, "h")
            with bits.block(f"if {present}"):
                self._emit_body(src, bits, sink)
        else:
            self._emit_body(src, bits, sink)

    def _emit_body(self, src: Source, bits: BitReader, sink: Sink) -> None:
        length = bits.take(self.prefix, "n")
        self.emit_length_check(src, length)
        sink(src, self.emit_value(src, self.emit_read_bytes(src, bits, length)))


_INT_RE = re.compile(r"\s*([+-]?\d+)")
_FLOAT_RE = re.compile(r"\s*([+-]?(?:\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|inf|nan))", re.I)


class StaticCodec(InlineCodec):
    """``dccl.static``: no bits; decoding yields ``static_value`` (read as C++'s ``operator>>`` reads it)."""

    def __init__(self, field: FieldContext) -> None:
        super().__init__(field)
        self.value: Any = None

    min_size = 0
    max_size = 0

    def validate(self) -> None:
        options, ftype = self.field.options, self.field.descriptor.type
        self.field.require(options.HasField("static_value"), "missing (dccl.field).static_value")
        text = options.static_value
        if ftype in (FieldDescriptor.TYPE_STRING, FieldDescriptor.TYPE_BYTES):
            words = text.split()
            self.field.require(bool(words), "invalid static_value for this type.")
            self.value = words[0] if ftype == FieldDescriptor.TYPE_STRING else words[0].encode()
            return
        is_float = ftype in (FieldDescriptor.TYPE_DOUBLE, FieldDescriptor.TYPE_FLOAT)
        match = (_FLOAT_RE if is_float else _INT_RE).match(text)
        self.field.require(match is not None, "invalid static_value for this type.")
        assert match is not None
        self.value = float(match.group(1)) if is_float else int(match.group(1))

    def describe(self) -> dict[str, Any]:
        return {"static_value": self.value}

    def emit_encode_value(self, src: Source, value: str) -> str:
        return "0"

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        sink(src, src.bind(self.value, "static"))


class IdFieldCodec(InlineCodec):
    """``dccl.default.id`` on a uint32 field: the id codec's 1 or 2 bytes. An unset field arrives as 0."""

    variable = True
    min_size = ids.ID_MIN_BITS
    max_size = ids.ID_MAX_BITS

    def describe(self) -> dict[str, Any]:
        return {"min": 0, "max": ids.TWO_BYTE_MAX_ID}

    def emit_encode(self, src: Source, out: BitWriter, value: str) -> None:
        with src.block(f"if {value} > {ids.TWO_BYTE_MAX_ID}"):
            error = src.bind(EncodeError, "EncodeError")
            src.line(f"raise {error}(f'{self.field.where}={{{value}}} exceeds the largest DCCL id "
                     f"{ids.TWO_BYTE_MAX_ID}')")
        with out.block(f"if {value} <= {ids.ONE_BYTE_MAX_ID}"):
            out.put(f"{value} << 1", 8)
        with out.block("else"):
            out.put(f"({value} << 1) | 1", 16)

    def emit_decode(self, src: Source, bits: BitReader, sink: Sink) -> None:
        low = bits.take(8, "i")
        with bits.block(f"if {low} & 1"):
            high = bits.take(8, "i")
            src.line(f"{low} |= {high} << 8")
        sink(src, f"{low} >> 1")


class PresenceCodec(InlineCodec):
    """``dccl.presence3``: an optional field gets one presence bit, then the inner codec's required form
    (so an out-of-range value arrives as the minimum, not unset). Required fields are the inner codec."""

    def __init__(self, field: FieldContext, inner: InlineCodec) -> None:
        super().__init__(field)
        self.inner = inner  # built with required=True

    @property
    def variable(self) -> bool:  # type: ignore[override]
        return self.inner.variable or not self.field.required

    @property
    def min_size(self) -> int:
        return self.inner.min_size if self.field.required else 1

    @property
    def max_size(self) -> int:
        return self.inner.max_size + (0 if self.field.required else 1)

    @property
    def empty_size(self) -> int:
        return 1  # DCCL's PresenceBitCodec::encode() is one zero bit, required or not

    def validate(self) -> None:
        self.inner.validate()

    def describe(self) -> dict[str, Any]:
        return self.inner.describe()

    def emit_encode_value(self, src: Source, value: str) -> str:
        return self.inner.emit_encode_value(src, value)

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        self.inner.emit_decode_value(src, bits, sink)

    def emit_encode(self, src: Source, out: BitWriter, value: str) -> None:
        if not self.field.required:
            out.put("1", 1)
        if self.inner.variable:
            self.inner.emit_encode(src, out, value)
        else:
            out.put(self.inner.emit_encode_value(src, value), self.inner.max_size)

    def emit_decode(self, src: Source, bits: BitReader, sink: Sink) -> None:
        if self.field.required:
            self._emit_inner(src, bits, sink)
            return
        present = bits.take(1, "h")
        with bits.block(f"if {present}"):
            self._emit_inner(src, bits, sink)

    def _emit_inner(self, src: Source, bits: BitReader, sink: Sink) -> None:
        if self.inner.variable:
            self.inner.emit_decode(src, bits, sink)
        else:
            self.inner.emit_decode_value(src, bits.take(self.inner.max_size), sink)
