"""TECHNIQUE_PROTOBUF_TEXT_FORMAT: protobuf text format printed exactly as C++'s single-line ``TextFormat::Printer``.

Why our own printer: MOOS apps (and people reading pMarineViewer/uXMS) see what the C++ gateway writes:
``x: 550`` not ``x: 550.0``, doubles as ``SimpleDtoa``, floats as ``SimpleFtoa``, strings C-escaped with octal for
non-ASCII bytes, and every field followed by one space -- including the last (Goby keeps that trailing space).
Parsing uses Python's parser, which reads everything the printer writes.
"""

from __future__ import annotations

from typing import Any

from google.protobuf import message_factory, text_encoding, text_format
from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message

from translators.techniques.errors import TechniqueError
from translators.techniques.numbers import simple_dtoa, simple_ftoa
from util.descriptors import enum_type_of, message_type_of

CPP = FieldDescriptor


def to_text_format(msg: Message) -> str:
    """Single-line text format of ``msg`` as protobuf C++ prints it (fields by number, trailing space)."""
    parts: list[str] = []
    _print_message(msg, parts)
    return "".join(parts)


def from_text_format(text: str, msg: Message) -> Message:
    """Clear ``msg`` and parse ``text`` into it (as ``TextFormat::Parser::ParseFromString``); returns ``msg``.

    Raises TechniqueError naming the message type and the parser's complaint (C++ only logs it).
    """
    msg.Clear()
    try:
        text_format.Parse(text, msg)
    except text_format.ParseError as exc:
        raise TechniqueError(f"cannot parse text format as {msg.DESCRIPTOR.full_name}: {exc}") from exc
    return msg


def _print_message(msg: Message, parts: list[str]) -> None:
    for field, value in msg.ListFields():
        name = _field_name(field)
        if field.cpp_type == CPP.CPPTYPE_MESSAGE and message_type_of(field).GetOptions().map_entry:
            entry_type = message_type_of(field)
            for key in sorted(value):
                entry = message_factory.GetMessageClass(entry_type)(key=key, value=value[key])
                _print_value(name, field, entry, parts)
        elif field.is_repeated:
            for element in value:
                _print_value(name, field, element, parts)
        else:
            _print_value(name, field, value, parts)


def _field_name(field: FieldDescriptor) -> str:
    if field.is_extension:
        return f"[{field.full_name}]"
    if field.type == CPP.TYPE_GROUP:
        return message_type_of(field).name
    return field.name


def _print_value(name: str, field: FieldDescriptor, value: Any, parts: list[str]) -> None:
    if field.cpp_type == CPP.CPPTYPE_MESSAGE:
        parts.append(f"{name} {{ ")
        _print_message(value, parts)
        parts.append("} ")
        return
    parts.append(f"{name}: {scalar_text(field, value)} ")


def scalar_text(field: FieldDescriptor, value: Any) -> str:
    """One scalar value in C++ text-format spelling."""
    cpp = field.cpp_type
    if cpp == CPP.CPPTYPE_DOUBLE:
        return simple_dtoa(value)
    if cpp == CPP.CPPTYPE_FLOAT:
        return simple_ftoa(value)
    if cpp == CPP.CPPTYPE_BOOL:
        return "true" if value else "false"
    if cpp == CPP.CPPTYPE_STRING:
        raw = value if isinstance(value, bytes) else value.encode("utf-8")
        return '"' + text_encoding.CEscape(raw, as_utf8=False) + '"'
    if cpp == CPP.CPPTYPE_ENUM:
        enum_value = enum_type_of(field).values_by_number.get(value)
        return enum_value.name if enum_value is not None else str(value)
    return str(value)
