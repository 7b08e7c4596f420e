"""What each field of a loaded message may hold, as data: for building forms (the web commander) and for
messages that name a field's bounds. Everything comes from the codec's layout, so it is what the codec enforces.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

from google.protobuf.descriptor import FieldDescriptor

from gateway.goby.dccl.codecs_numeric import NumericCodec
from gateway.goby.dccl.field_codec import NUMERIC_TYPES, FieldContext
from gateway.goby.dccl.layout import SUPPORTED_VERSION, FieldLayout, field_options
from gateway.goby.dccl.registry import CodecRegistry, default_registry

_TYPE_NAMES = {
    FieldDescriptor.TYPE_DOUBLE: "double", FieldDescriptor.TYPE_FLOAT: "float", FieldDescriptor.TYPE_INT64: "int64",
    FieldDescriptor.TYPE_UINT64: "uint64", FieldDescriptor.TYPE_INT32: "int32", FieldDescriptor.TYPE_FIXED64: "fixed64",
    FieldDescriptor.TYPE_FIXED32: "fixed32", FieldDescriptor.TYPE_BOOL: "bool", FieldDescriptor.TYPE_STRING: "string",
    FieldDescriptor.TYPE_MESSAGE: "message", FieldDescriptor.TYPE_BYTES: "bytes", FieldDescriptor.TYPE_UINT32: "uint32",
    FieldDescriptor.TYPE_ENUM: "enum", FieldDescriptor.TYPE_SFIXED32: "sfixed32",
    FieldDescriptor.TYPE_SFIXED64: "sfixed64", FieldDescriptor.TYPE_SINT32: "sint32",
    FieldDescriptor.TYPE_SINT64: "sint64",
}


@dataclass(frozen=True)
class FieldBounds:
    """One field: type, label, codec, bits on the wire, and the limits that apply to it.

    ``min``/``max``/``resolution`` (and ``precision`` when the .proto gives one) for numbers; ``enum`` as
    (name, number) pairs in declaration order; ``max_length`` for strings and bytes; ``min_repeat``/
    ``max_repeat`` for repeated fields; ``time`` for time codecs (``num_days`` window); ``fields`` for an
    embedded message. Values outside these are sent as "not present" (optional) or the minimum (required).
    """

    path: str
    name: str
    type: str
    label: str  # "required", "optional" or "repeated"
    part: str  # "head" or "body"
    codec: str
    min_bits: int
    max_bits: int
    min: float | None = None
    max: float | None = None
    resolution: float | None = None
    precision: int | None = None
    enum: tuple[tuple[str, int], ...] | None = None
    max_length: int | None = None
    min_repeat: int | None = None
    max_repeat: int | None = None
    time: bool = False
    num_days: int | None = None
    static_value: Any = None
    fields: tuple[FieldBounds, ...] = field(default_factory=tuple)

    def describe(self) -> str:
        """The limits in words, as error messages show them (e.g. ``[100, 2000], in steps of 10``)."""
        if self.enum is not None:
            return "{" + ", ".join(name for name, _ in self.enum) + "}"
        if self.time:
            return f"time of day within {self.num_days} day(s), in steps of {self.resolution:g} s"
        if self.max_length is not None:
            return f"at most {self.max_length} bytes"
        if self.min is None:
            return "no bounds"
        step = f", in steps of {self.resolution:g}" if self.resolution not in (None, 1) else ""
        return f"[{self.min:g}, {self.max:g}]{step}"


def field_bounds(layout: FieldLayout, part: str) -> FieldBounds:
    """The bounds of one laid-out field (recursively for embedded messages)."""
    fd = layout.descriptor
    label = "repeated" if fd.is_repeated else "required" if fd.is_required else "optional"
    known = {f.name for f in fields(FieldBounds)}
    described = layout.codec.describe() if layout.codec is not None else {}
    info: dict[str, Any] = {key: value for key, value in described.items() if key in known}
    if "enum" in info:
        info["enum"] = tuple(info["enum"])
    if layout.repeated:
        info.update(min_repeat=layout.min_repeat, max_repeat=layout.max_repeat)
    return FieldBounds(
        path=layout.context.path, name=fd.name, type=_TYPE_NAMES.get(fd.type, str(fd.type)), label=label, part=part,
        codec=layout.codec_name, min_bits=layout.min_size, max_bits=layout.max_size,
        fields=tuple(field_bounds(child, part) for child in layout.children), **info,
    )


def numeric_bounds(field: FieldDescriptor, registry: CodecRegistry | None = None) -> tuple[float, float, float] | None:
    """(min, max, step) the codec gives one numeric field on its own (no message to load: for forms), or None
    when the field is not numeric, has another codec than the bounded numeric one (time, static, ...) or lacks
    ``min``/``max``. The step is DCCL's resolution, which may be finer than 1 for an integer field."""
    options = field_options(field)
    if field.type not in NUMERIC_TYPES or not (options.HasField("min") and options.HasField("max")):
        return None
    name = options.codec if options.HasField("codec") else f"dccl.default{SUPPORTED_VERSION}"
    try:
        _, factory = (registry or default_registry()).find(field.type, name, SUPPORTED_VERSION)
    except LookupError:
        return None
    if factory is not NumericCodec:
        return None
    message = field.containing_type.full_name if field.containing_type is not None else ""
    codec = NumericCodec(FieldContext(descriptor=field, options=options, message=message,
                                      path=field.name, codec_version=SUPPORTED_VERSION, required=True, strict=False))
    return codec.lower(), codec.upper(), codec.resolution()
