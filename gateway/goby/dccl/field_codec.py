"""Field codecs: what one field needs to know (``FieldContext``), the base class for codecs a user registers by
name (``FieldCodec``, DCCL's ``FieldCodecBase``), and the base of the built-in codecs, which write Python source
instead of being called per message (``InlineCodec``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

from google.protobuf.descriptor import FieldDescriptor

from gateway.goby.dccl.errors import DefinitionError, OutOfRangeError
from gateway.goby.dccl.source import BitReader, BitWriter, Sink, Source
from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options

T = FieldDescriptor
INT32_TYPES = frozenset({T.TYPE_INT32, T.TYPE_SINT32, T.TYPE_SFIXED32})
INT64_TYPES = frozenset({T.TYPE_INT64, T.TYPE_SINT64, T.TYPE_SFIXED64})
UINT32_TYPES = frozenset({T.TYPE_UINT32, T.TYPE_FIXED32})
UINT64_TYPES = frozenset({T.TYPE_UINT64, T.TYPE_FIXED64})
INTEGER_TYPES = INT32_TYPES | INT64_TYPES | UINT32_TYPES | UINT64_TYPES
NUMERIC_TYPES = INTEGER_TYPES | {T.TYPE_DOUBLE, T.TYPE_FLOAT}
STRING_TYPES = frozenset({T.TYPE_STRING, T.TYPE_BYTES})


def int_width(field_type: int) -> tuple[int, bool]:
    """(bits, signed) of an integer protobuf type."""
    if field_type in INT32_TYPES:
        return 32, True
    if field_type in INT64_TYPES:
        return 64, True
    if field_type in UINT32_TYPES:
        return 32, False
    return 64, False


@dataclass(frozen=True)
class FieldContext:
    """One field as its codec sees it."""

    descriptor: FieldDescriptor
    options: dccl_options.DCCLFieldOptions
    message: str  # full name of the root message (for errors)
    path: str  # the field's dotted path inside the root message
    codec_version: int
    required: bool  # DCCL's use_required(): no "not present" value (required fields, v3 repeated elements)
    strict: bool

    def fail(self, reason: str) -> DefinitionError:
        """The error for a definition this field's codec cannot use."""
        return DefinitionError(self.message, self.path, reason)

    def require(self, condition: bool, reason: str) -> None:
        if not condition:
            raise self.fail(reason)

    @property
    def where(self) -> str:
        """``Message.path``, as errors name the field."""
        return f"{self.message.rsplit('.', 1)[-1]}.{self.path}"


class CodecBase:
    """What every field codec offers the compiler: a name, sizes in bits, validation and a description."""

    name = ""

    def __init__(self, field: FieldContext) -> None:
        self.field = field

    def validate(self) -> None:
        """Raise ``DefinitionError`` (``self.field.fail(...)``) for options this codec cannot use."""

    @property
    @abstractmethod
    def min_size(self) -> int:
        """Fewest bits a value (or an unset field) takes."""

    @property
    @abstractmethod
    def max_size(self) -> int:
        """Most bits a value takes."""

    @property
    def empty_size(self) -> int:
        """Bits of an unset field, all zero (DCCL's ``encode()`` without a value)."""
        return self.min_size

    def describe(self) -> dict[str, Any]:
        """Bounds and limits for form building (see ``bounds.py``); empty when the codec has none."""
        return {}


class FieldCodec(CodecBase, ABC):
    """Base class of a codec a user registers by name (``Codec.registry.add``), like a DCCL ``FieldCodecBase``.

    The compiled message calls ``encode``/``decode`` once per value; repeated fields get DCCL's count prefix
    around them. ``self.field.required`` says whether the field has a "not present" value to reserve.
    """

    @abstractmethod
    def encode(self, value: Any | None) -> tuple[int, int]:
        """(bits, count) for ``value`` (``None`` for an unset field); bit 0 is sent first."""

    @abstractmethod
    def decode(self, bits: Bits) -> Any | None:
        """The value read from ``bits`` (call ``bits.read(n)``), or ``None`` for "not present"."""


class Bits:
    """The bits of a message part from a field's position on: what ``FieldCodec.decode`` reads."""

    __slots__ = ("pos", "value")

    def __init__(self, value: int, pos: int) -> None:
        self.value = value
        self.pos = pos

    def read(self, count: int) -> int:
        """The next ``count`` bits as an unsigned integer."""
        out = (self.value >> self.pos) & ((1 << count) - 1)
        self.pos += count
        return out


class InlineCodec(CodecBase):
    """A built-in codec: writes the Python source that encodes and decodes its field in the compiled functions.

    Fixed-size codecs (``variable = False``) produce one integer of ``max_size`` bits from a value and back;
    variable-size codecs drive the bit cursor themselves (``put``/``take``, and ``block`` around code that
    branches on the data). Unset fields never reach them: they are ``empty_size`` zero bits.
    """

    variable = False

    def emit_encode_value(self, src: Source, value: str) -> str:
        """Fixed size: statements computing the bits for the local ``value``; return their expression."""
        raise NotImplementedError

    def emit_decode_value(self, src: Source, bits: str, sink: Sink) -> None:
        """Fixed size: statements turning the local ``bits`` into a value, passed to ``sink`` unless absent."""
        raise NotImplementedError

    def emit_encode(self, src: Source, out: BitWriter, value: str) -> None:
        """Variable size: write the local ``value`` at ``out`` (synced)."""
        raise NotImplementedError

    def emit_decode(self, src: Source, bits: BitReader, sink: Sink) -> None:
        """Variable size: read a value at ``bits`` (synced) and pass it to ``sink`` unless absent."""
        raise NotImplementedError

    def out_of_range(self, src: Source, value: str, bounds: str) -> str:
        """The statement for a value outside the bounds: an error in strict mode, else nothing (zero bits)."""
        error = src.bind(OutOfRangeError, "OutOfRange")
        return f"raise {error}({self.field.where!r}, {value}, {bounds!r})"
