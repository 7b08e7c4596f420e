"""TECHNIQUE_COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS: ``Name=unicorn,x=550,repeat={1,-1,2},sub_val=3``.

Why these exact rules: they are what MOOS apps and pTranslator configurations expect from Goby.  Fields go in
declaration order; repeated fields as ``key={a,b}``; an embedded message ``f`` as ``f_<sub>=<value>`` for every
sub-field (defaults included), and repeated ones as ``f_<sub>={v0,v1}``.  Parsing lowercases the whole input
first (so string values come back in lower case), as Goby does.
"""

from __future__ import annotations

from typing import Any

from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message

from translators.techniques.fields import add_value, set_value, value_from_moos, value_to_moos
from util.descriptors import descriptor_of, message_type_of

CPP = FieldDescriptor


def to_key_values(msg: Message, use_short_enum: bool = False) -> str:
    """``msg`` as comma-separated ``key=value`` pairs (unset singular and empty repeated fields left out)."""
    entries: list[str] = []
    for field in descriptor_of(msg).fields:
        repeated = field.is_repeated
        value = getattr(msg, field.name)
        if (repeated and len(value) == 0) or (not repeated and not msg.HasField(field.name)):
            continue
        if field.cpp_type == CPP.CPPTYPE_MESSAGE:
            entries.extend(_embedded(field, value, repeated, use_short_enum))
        elif repeated:
            entries.append(field.name + "={" + ",".join(value_to_moos(field, v, use_short_enum) for v in value) + "}")
        else:
            entries.append(f"{field.name}={value_to_moos(field, value, use_short_enum)}")
    return ",".join(entries)


def _embedded(field: FieldDescriptor, value: Any, repeated: bool, use_short_enum: bool) -> list[str]:
    out: list[str] = []
    elements = list(value) if repeated else [value]
    for sub in message_type_of(field).fields:
        shown = ",".join(_sub_value(element, sub, use_short_enum) for element in elements)
        out.append(f"{field.name}_{sub.name}=" + ("{" + shown + "}" if repeated else shown))
    return out


def _sub_value(element: Message, sub: FieldDescriptor, use_short_enum: bool) -> str:
    value = getattr(element, sub.name)
    if sub.is_repeated:
        return ",".join(value_to_moos(sub, v, use_short_enum) for v in value)
    return value_to_moos(sub, value, use_short_enum)


def value_for_key(text: str, key: str) -> str | None:
    """The value of ``key`` in ``text`` (case-insensitive key), or None.

    As Goby's ``val_from_string``: the key must start the string or follow a comma; a value starting with
    ``{`` runs to the next ``}``, any other to the next comma.
    """
    lower, needle = text.lower(), key.lower() + "="
    start = lower.find(needle)
    while start > 0 and text[start - 1] != ",":
        start = lower.find(needle, start + 1)
    if start < 0:
        return None
    rest = text[start + len(needle) :]
    if rest.startswith("{"):
        close = rest.find("}")
        return rest[1:close] if close >= 0 else rest[1:]
    comma = rest.find(",")
    return rest if comma < 0 else rest[:comma]


def from_key_values(text: str, msg: Message, use_short_enum: bool = False) -> Message:
    """Merge the ``key=value`` pairs of ``text`` into ``msg`` (fields not named are left alone); returns ``msg``."""
    text = text.lower()
    for field in descriptor_of(msg).fields:
        if field.cpp_type == CPP.CPPTYPE_MESSAGE:
            _parse_embedded(text, msg, field, use_short_enum)
            continue
        found = value_for_key(text, field.name)
        if found is not None:
            _store(msg, field, found.split(","), 0, use_short_enum)
    return msg


def _parse_embedded(text: str, msg: Message, field: FieldDescriptor, use_short_enum: bool) -> None:
    repeated = field.is_repeated
    for sub in message_type_of(field).fields:
        found = value_for_key(text, f"{field.name}_{sub.name}")
        if found is None:
            continue
        pieces = found.split(",")
        if not repeated:
            element = getattr(msg, field.name)
            element.SetInParent()
            _store(element, sub, pieces, 0, use_short_enum)
            continue
        container = getattr(msg, field.name)
        for j in range(len(pieces)):
            element = container.add() if len(container) < j + 1 else container[j]
            _store(element, sub, pieces, j, use_short_enum)


def _store(msg: Message, field: FieldDescriptor, pieces: list[str], index: int, use_short_enum: bool) -> None:
    """Repeated fields take every piece; singular ones take ``pieces[index]`` (Goby's rule)."""
    if field.is_repeated:
        for piece in pieces:
            add_value(msg, field, value_from_moos(field, piece, use_short_enum))
    else:
        set_value(msg, field, value_from_moos(field, pieces[index], use_short_enum))
