"""Field values to and from the MOOS spelling used by the key=value and %N% format techniques.

Why one module: both techniques share Goby's per-type rules (ints decimal, bools ``true``/``false``, strings raw,
bytes and embedded messages as lowercase hex, floats ``%.6g``, doubles ``%.15g``, enums by name, optionally
without the ``FIELDNAME_`` prefix) and the Boost-style conversions back.
"""

from __future__ import annotations

import re
from typing import Any

from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import DecodeError, Message

from translators.techniques.errors import TechniqueError
from translators.techniques.numbers import (
    INT_LIMITS,
    hex_decode,
    hex_encode,
    lexical_bool,
    lexical_integer,
    lexical_real,
    stream_double,
    stream_float,
)
from util.descriptors import enum_type_of

CPP = FieldDescriptor


def strip_name_from_enum(enum_name: str, field_name: str) -> str:
    """Remove the first ``<field_name>_`` (any case) from an enum value name (Goby's short enums)."""
    return re.sub(re.escape(field_name + "_"), "", enum_name, count=1, flags=re.IGNORECASE)


def value_to_moos(field: FieldDescriptor, value: Any, use_short_enum: bool = False) -> str:
    """One value of ``field`` (an element, for repeated fields) as Goby writes it into a MOOS string."""
    cpp = field.cpp_type
    if cpp == CPP.CPPTYPE_MESSAGE:
        return hex_encode(value.SerializeToString())
    if cpp == CPP.CPPTYPE_BOOL:
        return "true" if value else "false"
    if cpp == CPP.CPPTYPE_STRING:
        return hex_encode(value) if field.type == CPP.TYPE_BYTES else value
    if cpp == CPP.CPPTYPE_FLOAT:
        return stream_float(value)
    if cpp == CPP.CPPTYPE_DOUBLE:
        return stream_double(value)
    if cpp == CPP.CPPTYPE_ENUM:
        enum_value = enum_type_of(field).values_by_number.get(value)
        name = enum_value.name if enum_value is not None else str(value)
        return strip_name_from_enum(name, field.name) if use_short_enum else name
    return str(value)


def default_to_moos(field: FieldDescriptor, use_short_enum: bool = False) -> str:
    """The placeholder Goby prints for a missing element of an indexed repeated field (``%N.i%`` past the end)."""
    cpp = field.cpp_type
    if cpp in INT_LIMITS:
        return str(INT_LIMITS[cpp][1])
    if cpp in (CPP.CPPTYPE_FLOAT, CPP.CPPTYPE_DOUBLE):
        return "nan"
    if cpp == CPP.CPPTYPE_MESSAGE:
        return ""
    return value_to_moos(field, element_zero(field), use_short_enum)


def element_zero(field: FieldDescriptor) -> Any:
    """The default of one element of a repeated scalar field (repeated fields carry no declared default)."""
    cpp = field.cpp_type
    if cpp == CPP.CPPTYPE_ENUM:
        return enum_type_of(field).values[0].number
    if cpp == CPP.CPPTYPE_BOOL:
        return False
    if cpp == CPP.CPPTYPE_STRING:
        return b"" if field.type == CPP.TYPE_BYTES else ""
    if cpp in (CPP.CPPTYPE_FLOAT, CPP.CPPTYPE_DOUBLE):
        return 0.0
    return 0


def value_from_moos(field: FieldDescriptor, text: str, use_short_enum: bool = False) -> Any:
    """Convert ``text`` for ``field``; ``None`` means "leave unset" (an enum name that is not in the enum).

    Embedded messages are returned as their binary serialization (the caller merges them).
    """
    cpp = field.cpp_type
    if cpp in INT_LIMITS:
        return lexical_integer(text, cpp)
    if cpp in (CPP.CPPTYPE_FLOAT, CPP.CPPTYPE_DOUBLE):
        return lexical_real(text)
    if cpp == CPP.CPPTYPE_BOOL:
        return lexical_bool(text)
    if cpp == CPP.CPPTYPE_STRING:
        return _unhex(text, field) if field.type == CPP.TYPE_BYTES else text
    if cpp == CPP.CPPTYPE_MESSAGE:
        return _unhex(text, field)
    if cpp == CPP.CPPTYPE_ENUM:
        name = field.name.upper() + "_" + text if use_short_enum else text
        values = enum_type_of(field).values_by_name
        for candidate in (name, name.upper(), name.lower()):
            if candidate in values:
                return values[candidate].number
        return None
    raise TechniqueError(f"unsupported field type for {field.full_name}")


def _unhex(text: str, field: FieldDescriptor) -> bytes:
    try:
        return hex_decode(text)
    except ValueError as exc:
        raise TechniqueError(f"field {field.full_name}: {text!r} is not hex") from exc


def set_value(msg: Message, field: FieldDescriptor, value: Any) -> None:
    """Set a singular field (embedded messages: parse the binary ``value`` into it, as ``ParseFromString``)."""
    if value is None:
        return
    if field.cpp_type == CPP.CPPTYPE_MESSAGE:
        sub = getattr(msg, field.name)
        _parse_binary(sub, value)
        sub.SetInParent()
    else:
        setattr(msg, field.name, value)


def add_value(msg: Message, field: FieldDescriptor, value: Any) -> None:
    """Append to a repeated field."""
    if value is None:
        return
    container = getattr(msg, field.name)
    if field.cpp_type == CPP.CPPTYPE_MESSAGE:
        _parse_binary(container.add(), value)
    else:
        container.append(value)


def set_element(msg: Message, field: FieldDescriptor, index: int, value: Any) -> None:
    """Set element ``index`` of a repeated field, growing it with defaults as Goby does."""
    container = getattr(msg, field.name)
    while len(container) <= index:
        if field.cpp_type == CPP.CPPTYPE_MESSAGE:
            container.add()
        else:
            container.append(element_zero(field))
    if value is None:
        return
    if field.cpp_type == CPP.CPPTYPE_MESSAGE:
        _parse_binary(container[index], value)
    else:
        container[index] = value


def _parse_binary(msg: Message, data: bytes) -> None:
    try:
        msg.ParseFromString(data)
    except DecodeError as exc:
        raise TechniqueError(f"embedded {msg.DESCRIPTOR.full_name}: not a valid encoding") from exc
