"""Protobuf messages on one line as C++ ``Message::ShortDebugString`` prints them (Goby's DEBUG_TEXT values).

Python's ``text_format`` differs in float digits (``3.0`` where C++ prints ``3``); this printer follows the C++
rules: fields in number order, extensions as ``[full.name]``, doubles with 15 significant digits unless 17 are
needed to round-trip (floats: 6, else 9), strings C-escaped with UTF-8 kept, bytes octal-escaped.
"""

from __future__ import annotations

import math
import struct
from typing import Any

from google.protobuf import text_encoding
from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message

_FD = FieldDescriptor
_F32 = struct.Struct("<f")


def format_double(value: float) -> str:
    """C++ ``SimpleDtoa``."""
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    text = f"{value:.15g}"
    return text if float(text) == value else f"{value:.17g}"


def format_float(value: float) -> str:
    """C++ ``SimpleFtoa`` (the value is a float32 held in a double)."""
    if math.isnan(value) or math.isinf(value):
        return format_double(value)
    text = f"{value:.6g}"
    try:
        same = _F32.pack(float(text)) == _F32.pack(value)
    except OverflowError:
        same = False
    return text if same else f"{value:.9g}"


def _scalar(field: FieldDescriptor, value: Any) -> str:
    kind = field.type
    if kind == _FD.TYPE_STRING:
        return '"' + text_encoding.CEscape(value, as_utf8=True) + '"'
    if kind == _FD.TYPE_BYTES:
        return '"' + text_encoding.CEscape(value, as_utf8=False) + '"'
    if kind == _FD.TYPE_ENUM:
        enum_value = field.enum_type.values_by_number.get(value) if field.enum_type is not None else None
        return enum_value.name if enum_value is not None else str(value)
    if kind == _FD.TYPE_BOOL:
        return "true" if value else "false"
    if kind == _FD.TYPE_DOUBLE:
        return format_double(value)
    if kind == _FD.TYPE_FLOAT:
        return format_float(value)
    return str(value)


def _print(msg: Message, parts: list[str]) -> None:
    for field, value in msg.ListFields():
        name = f"[{field.full_name}]" if field.is_extension else field.name
        if field.message_type is not None and field.message_type.GetOptions().map_entry:
            entry_type = field.message_type
            key_field, value_field = entry_type.fields_by_name["key"], entry_type.fields_by_name["value"]
            for key in sorted(value):
                parts.append(f"{name} {{")
                parts.append(f"key: {_scalar(key_field, key)}")
                item = value[key]
                if value_field.message_type is not None:
                    parts.append("value {")
                    _print(item, parts)
                    parts.append("}")
                else:
                    parts.append(f"value: {_scalar(value_field, item)}")
                parts.append("}")
            continue
        values = value if field.is_repeated else (value,)
        for item in values:
            if field.message_type is not None:
                parts.append(f"{name} {{")
                _print(item, parts)
                parts.append("}")
            else:
                parts.append(f"{name}: {_scalar(field, item)}")


def short_debug_string(msg: Message) -> str:
    """``msg`` on one line, as C++ ``ShortDebugString``."""
    parts: list[str] = []
    _print(msg, parts)
    return " ".join(parts)
