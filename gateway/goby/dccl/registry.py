"""Field codecs by name, as DCCL's ``FieldCodecManager`` keeps them: (protobuf field type, codec name) -> codec.

Lookup follows DCCL: a name that does not end in a digit is first tried with the message's codec_version
appended (``dccl.time`` -> ``dccl.time3``), and a codec registered for one message type
(``name[pkg.Type]``) wins over the general one. Each ``Codec`` has its own registry, filled with DCCL's
defaults; users add theirs with :meth:`CodecRegistry.add`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace

from google.protobuf.descriptor import FieldDescriptor

from gateway.goby.dccl.codecs_bytes import (
    BytesCodec,
    IdFieldCodec,
    PresenceCodec,
    StaticCodec,
    StringCodec,
    VarBytesCodec,
)
from gateway.goby.dccl.codecs_numeric import BoolCodec, EnumCodec, NumericCodec, TimeCodec
from gateway.goby.dccl.field_codec import (
    INT64_TYPES,
    NUMERIC_TYPES,
    STRING_TYPES,
    UINT32_TYPES,
    UINT64_TYPES,
    CodecBase,
    FieldContext,
    InlineCodec,
)

T = FieldDescriptor
CodecFactory = Callable[[FieldContext], CodecBase]
ALL_TYPES = frozenset(range(1, 19))
TYPE_NAMES = {getattr(T, n): n for n in dir(T) if n.startswith("TYPE_")}


@dataclass(frozen=True)
class MessageCodec:
    """Marker for DCCL's default message codec (v3): the compiler lays embedded messages out itself."""

    name: str


def _presence(field: FieldContext) -> CodecBase:
    inner = DEFAULT3[field.descriptor.type](replace(field, required=True))
    assert isinstance(inner, InlineCodec)
    return PresenceCodec(field, inner)


def _v2_string(field: FieldContext) -> CodecBase:
    return StringCodec(field, v2=True)


def _v2_enum(field: FieldContext) -> CodecBase:
    codec = EnumCodec(field)
    codec.packed = True  # DCCL v2's enum codec knows no packed_enum option
    return codec


DEFAULT3: dict[int, CodecFactory] = {
    T.TYPE_BOOL: BoolCodec,
    T.TYPE_STRING: StringCodec,
    T.TYPE_BYTES: BytesCodec,
    T.TYPE_ENUM: EnumCodec,
    **dict.fromkeys(NUMERIC_TYPES, NumericCodec),
}


class CodecRegistry:
    """Field codecs by (field type, name); one per ``Codec`` (DCCL 4's ``codec.manager()``)."""

    def __init__(self) -> None:
        self._codecs: dict[int, dict[str, CodecFactory | MessageCodec]] = {}

    def add(self, name: str, factory: CodecFactory, types: Iterable[int], message_type: str = "") -> None:
        """Register ``factory`` (usually a ``FieldCodec`` subclass) as codec ``name`` for protobuf field
        ``types`` (``FieldDescriptor.TYPE_*``); ``message_type`` restricts a message codec to one type.
        A name already taken for a type keeps its first codec, as in DCCL."""
        key = f"{name}[{message_type}]" if message_type else name
        for field_type in types:
            self._codecs.setdefault(field_type, {}).setdefault(key, factory)

    def remove(self, name: str, types: Iterable[int] = ALL_TYPES) -> None:
        """Forget codec ``name`` for ``types``."""
        for field_type in types:
            self._codecs.get(field_type, {}).pop(name, None)

    def names(self) -> list[str]:
        """Every registered codec name."""
        return sorted({name for codecs in self._codecs.values() for name in codecs})

    def find(self, field_type: int, name: str, codec_version: int,
             message_type: str = "") -> tuple[str, CodecFactory | MessageCodec]:
        """(registered name, codec) for a field; ``LookupError`` naming the tried names when there is none."""
        tried = ([name + str(codec_version)] if name and not name[-1].isdigit() else []) + [name]
        codecs = self._codecs.get(field_type, {})
        for candidate in tried:
            for key in ([f"{candidate}[{message_type}]"] if message_type else []) + [candidate]:
                if key in codecs:
                    return candidate, codecs[key]
        names = " ".join(f"`{c}`" for c in tried)
        raise LookupError(f"No codec by the name `{name}` found for type: {TYPE_NAMES.get(field_type, field_type)} "
                          f"(tried names: {names})")


def default_registry() -> CodecRegistry:
    """A registry with DCCL's built-in codecs (those the 4.x library loads for codec versions 2 and 3)."""
    registry = CodecRegistry()
    scalar = [T.TYPE_BOOL, T.TYPE_BYTES, *sorted(NUMERIC_TYPES)]
    for field_type in scalar:
        registry.add("dccl.default3", DEFAULT3[field_type], [field_type])
        registry.add("dccl.default2", DEFAULT3[field_type], [field_type])
    registry.add("dccl.default3", StringCodec, [T.TYPE_STRING])
    registry.add("dccl.default3", EnumCodec, [T.TYPE_ENUM])
    registry.add("dccl.default3", MessageCodec("dccl.default3"), [T.TYPE_MESSAGE])  # type: ignore[arg-type]
    registry.add("dccl.default2", _v2_string, [T.TYPE_STRING])
    registry.add("dccl.default2", _v2_enum, [T.TYPE_ENUM])
    time_types = [T.TYPE_DOUBLE, *sorted(INT64_TYPES), *sorted(UINT64_TYPES)]
    static_types = [*sorted(STRING_TYPES), *sorted(NUMERIC_TYPES)]
    for name in ("dccl.time2", "dccl.time3", "_time"):
        registry.add(name, TimeCodec, time_types)
    for name in ("dccl.static2", "dccl.static3", "_static"):
        registry.add(name, StaticCodec, static_types)
    registry.add("dccl.presence3", _presence, [T.TYPE_BOOL, T.TYPE_ENUM, *sorted(STRING_TYPES),
                                               *sorted(NUMERIC_TYPES)])
    registry.add("dccl.presence3", MessageCodec("dccl.presence3"), [T.TYPE_MESSAGE])  # type: ignore[arg-type]
    registry.add("dccl.var_bytes3", VarBytesCodec, sorted(STRING_TYPES))
    registry.add("dccl.default.id", IdFieldCodec, sorted(UINT32_TYPES))
    return registry
