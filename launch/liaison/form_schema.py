"""The commander's form, as data: a protobuf descriptor with its DCCL bounds -> a JSON-able schema.

The page builds its inputs from this schema (number inputs with min/max/step, enum selects, required marks,
auto-filled DCCL time fields, sub-messages, repeated fields with a count), and ``form_values`` checks what comes
back against the same descriptor, so the page and the server refuse the same things.  Bounds come from the
message's own ``(dccl.field)`` options through the DCCL codec (``gateway.goby.dccl.numeric_bounds``), whose
strict encode is the check the command path itself applies.
"""

from __future__ import annotations

import math
from typing import Any

from google.protobuf.descriptor import Descriptor, FieldDescriptor

from gateway.goby.dccl import numeric_bounds
from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options
from util.descriptors import enum_type_of, message_type_of

MAX_DEPTH = 8  # nesting shown for (possibly recursive) sub-messages
DEFAULT_MAX_REPEAT = 100  # elements offered for a repeated field without (dccl.field).max_repeat
TIME_CODECS = frozenset({"dccl.time", "dccl.time2", "_time"})

_KINDS = {
    FieldDescriptor.TYPE_DOUBLE: "double",
    FieldDescriptor.TYPE_FLOAT: "float",
    FieldDescriptor.TYPE_INT32: "int",
    FieldDescriptor.TYPE_SINT32: "int",
    FieldDescriptor.TYPE_SFIXED32: "int",
    FieldDescriptor.TYPE_UINT32: "uint",
    FieldDescriptor.TYPE_FIXED32: "uint",
    FieldDescriptor.TYPE_INT64: "int64",
    FieldDescriptor.TYPE_SINT64: "int64",
    FieldDescriptor.TYPE_SFIXED64: "int64",
    FieldDescriptor.TYPE_UINT64: "uint64",
    FieldDescriptor.TYPE_FIXED64: "uint64",
    FieldDescriptor.TYPE_BOOL: "bool",
    FieldDescriptor.TYPE_STRING: "string",
    FieldDescriptor.TYPE_BYTES: "bytes",
    FieldDescriptor.TYPE_ENUM: "enum",
    FieldDescriptor.TYPE_MESSAGE: "message",
    FieldDescriptor.TYPE_GROUP: "message",
}
#: The range of each integer kind (64-bit kinds travel as text: JavaScript numbers lose precision past 2^53).
TYPE_RANGES = {
    "int": (-(2**31), 2**31 - 1),
    "uint": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
FLOAT_MAX = 3.4028234663852886e38


def field_kind(field: FieldDescriptor) -> str:
    return _KINDS[field.type]


def dccl_field_options(field: FieldDescriptor) -> dccl_options.DCCLFieldOptions:
    return field.GetOptions().Extensions[dccl_options.field]


def is_auto_time(field: FieldDescriptor) -> bool:
    """A DCCL time field: filled with the application clock's time when the command is sent (as Goby does)."""
    return field.type != FieldDescriptor.TYPE_MESSAGE and dccl_field_options(field).codec in TIME_CODECS


def dccl_bounds(field: FieldDescriptor) -> tuple[float, float, float] | None:
    """(min, max, step) that DCCL gives a numeric field, or None: the one place the liaison reads DCCL bounds
    (from the DCCL codec). An integer field's step is at least 1 (DCCL leaves integers alone below that)."""
    bounds = numeric_bounds(field)
    if bounds is None:
        return None
    low, high, step = bounds
    return low, high, step if field_kind(field) in ("float", "double") else max(step, 1.0)


def describe_bounds(low: float, high: float, step: float) -> str:
    """``[100, 2000], in steps of 10`` (the wording of the DCCL check's errors)."""
    return f"[{low:g}, {high:g}]" + (f", in steps of {step:g}" if step != 1 else "")


def numeric_limits(field: FieldDescriptor) -> tuple[float, float, float | None, bool]:
    """(min, max, step, from_dccl) for a numeric field: the DCCL bounds when it has them, else the type's range."""
    kind = field_kind(field)
    bounds = dccl_bounds(field)
    if bounds is not None:
        return *bounds, True
    if kind in TYPE_RANGES:
        low, high = TYPE_RANGES[kind]
        return low, high, 1, False
    if kind == "float":
        return -FLOAT_MAX, FLOAT_MAX, None, False
    return -float("inf"), float("inf"), None, False


def _default(field: FieldDescriptor) -> Any:
    if field.is_repeated or field.type == FieldDescriptor.TYPE_MESSAGE or not field.has_default_value:
        return None
    if field.type == FieldDescriptor.TYPE_ENUM:
        return enum_type_of(field).values_by_number[field.default_value].name
    if field.type == FieldDescriptor.TYPE_BYTES:
        return field.default_value.hex()
    if field_kind(field) in ("int64", "uint64"):
        return str(field.default_value)
    if isinstance(field.default_value, float) and not math.isfinite(field.default_value):
        return str(field.default_value)  # nan/inf: JSON has no such numbers
    return field.default_value


def _field_schema(field: FieldDescriptor, depth: int) -> dict[str, Any]:
    kind = field_kind(field)
    options = dccl_field_options(field)
    label = "repeated" if field.is_repeated else "required" if field.is_required else "optional"
    out: dict[str, Any] = {"name": field.name, "number": field.number, "label": label, "kind": kind,
                           "default": _default(field)}
    if field.containing_oneof is not None:
        out["oneof"] = field.containing_oneof.name
    if options.HasField("description"):
        out["description"] = options.description
    if kind in ("int", "uint", "int64", "uint64", "float", "double"):
        low, high, step, from_dccl = numeric_limits(field)
        if from_dccl or kind in ("int", "uint"):
            out.update(min=low, max=high)
        if step is not None:
            out["step"] = step
        out["dccl_bounds"] = from_dccl
    if kind == "enum":
        out["enum"] = [value.name for value in enum_type_of(field).values]
    if options.HasField("static_value") and options.codec == "dccl.static":
        out["static_value"] = options.static_value
    if options.HasField("max_length"):
        out["max_length"] = options.max_length
    if is_auto_time(field):
        out["auto_time"] = True
    if field.is_repeated:
        out["max_repeat"] = options.max_repeat if options.HasField("max_repeat") else DEFAULT_MAX_REPEAT
        out["min_repeat"] = options.min_repeat
    if kind == "message":
        sub = message_type_of(field)
        out["message"] = (message_schema(sub, depth + 1) if depth < MAX_DEPTH
                          else {"name": sub.full_name, "fields": [], "truncated": True})
    return out


def message_schema(descriptor: Descriptor, depth: int = 0) -> dict[str, Any]:
    """The form schema of a message type (fields in declaration order, sub-messages nested)."""
    return {"name": descriptor.full_name, "fields": [_field_schema(f, depth) for f in descriptor.fields]}
