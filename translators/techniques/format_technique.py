"""TECHNIQUE_FORMAT: ``NAME=%1%,X=%202%,REPEAT={%10%}`` -- a template of ``%N%`` field-number directives.

Directives: ``%N%`` (field N; repeated fields joined by the delimiter), ``%N.i%`` (element i of repeated field N),
``%A:B:...:N%`` (a path through embedded messages, ``F.i`` for element i of a repeated message), and ``%%`` for a
literal ``%``.  Parsing walks the template as Goby does: a literal character skips the input up to and including
its first occurrence, and a directive takes the input up to the template character that follows it.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message

from translators.techniques.errors import TechniqueError
from translators.techniques.fields import (
    add_value,
    default_to_moos,
    set_element,
    set_value,
    value_from_moos,
    value_to_moos,
)
from util.descriptors import descriptor_of

CPP = FieldDescriptor
_PATH = re.compile(r"%([0-9.]+:)+[0-9.]+%")
_INDEXED = re.compile(r"%[0-9]+\.[0-9]+%")
_DIRECTIVE = re.compile(r"%(\d*)%")


def format_message(msg: Message, fmt: str, repeated_delimiter: str = ",", use_short_enum: bool = False) -> str:
    """Render ``fmt`` with the fields of ``msg``; a number that is no field renders ``unknown``.

    Raises TechniqueError for a bad path (``%3:1%`` where 3 is no message) or a malformed template.
    """
    desc = descriptor_of(msg)
    # Goby's quirk: the first declared field is left out of the maximum (1 is the floor).
    highest = max([1] + [f.number for f in desc.fields[1:]])
    virtual: dict[int, str] = {}
    rewritten = fmt
    for match in _PATH.finditer(fmt):
        spec = match.group(0).strip("%")
        highest += 1
        *path, last = spec.split(":")
        sub = _descend(msg, path, spec, create=False)
        virtual[highest] = format_message(sub, f"%{last}%", repeated_delimiter, use_short_enum)
        rewritten = rewritten.replace(f"%{spec}%", f"%{highest}%")
    indexed: dict[int, tuple[int, int]] = {}
    for match in _INDEXED.finditer(rewritten):
        spec = match.group(0).strip("%")
        highest += 1
        number, index = spec.split(".")
        indexed[highest] = (int(number), int(index))
        rewritten = rewritten.replace(f"%{spec}%", f"%{highest}%")

    def argument(n: int) -> str:
        if n > highest:
            return ""
        number, index = indexed.get(n, (n, None))
        field = desc.fields_by_number.get(number)
        if field is not None:
            return _field_text(msg, field, index, repeated_delimiter, use_short_enum)
        return virtual.get(n, "unknown")

    return _render(rewritten, argument, fmt)


def _field_text(msg: Message, field: FieldDescriptor, index: int | None, delimiter: str, short: bool) -> str:
    value = getattr(msg, field.name)
    if not field.is_repeated:
        return value_to_moos(field, value, short)
    if index is None:
        return delimiter.join(value_to_moos(field, v, short) for v in value)
    return value_to_moos(field, value[index], short) if index < len(value) else default_to_moos(field, short)


def _render(template: str, argument: Callable[[int], str], original: str) -> str:
    out: list[str] = []
    pos = 0
    for match in _DIRECTIVE.finditer(template):
        out.append(_literal(template[pos : match.start()], original))
        digits = match.group(1)
        if digits == "":
            out.append("%")
        elif int(digits) == 0:
            raise TechniqueError(f"bad format {original!r}: directives count from %1%")
        else:
            out.append(argument(int(digits)))
        pos = match.end()
    out.append(_literal(template[pos:], original))
    return "".join(out)


def _literal(text: str, original: str) -> str:
    if "%" in text:
        raise TechniqueError(f"bad format {original!r}: only %N%, %N.i%, %A:B% and %% directives are supported")
    return text


def _descend(msg: Message, path: list[str], spec: str, create: bool) -> Message:
    """Follow ``F`` / ``F.i`` steps through embedded messages (growing repeated ones when ``create``)."""
    sub = msg
    for step in path:
        number, _, index_text = step.partition(".")
        field = descriptor_of(sub).fields_by_number.get(int(number)) if number.isdigit() else None
        if field is None or field.cpp_type != CPP.CPPTYPE_MESSAGE:
            raise TechniqueError(
                f"Invalid ':' syntax given for format: {spec}. All field indices except the last must be embedded messages"
            )
        if not field.is_repeated:
            sub = getattr(sub, field.name)
            continue
        if not index_text.isdigit():
            raise TechniqueError(
                f"Invalid '.' syntax given for format: {spec}. Repeated message, but no valid index given. "
                "E.g., use '3.4' for index 4 of field 3."
            )
        container, index = getattr(sub, field.name), int(index_text)
        if create:
            while len(container) <= index:
                container.add()
        elif index >= len(container):
            raise TechniqueError(f"format {spec}: element {index} of {field.full_name} does not exist")
        sub = container[index]
    return sub


def parse_format(
    text: str, msg: Message, fmt: str, repeated_delimiter: str = ",", use_short_enum: bool = False
) -> Message:
    """Merge the values ``text`` holds at the places ``fmt`` marks into ``msg``; returns ``msg``.

    The template is matched case-insensitively; values keep their case.  Raises TechniqueError for a
    directive that names no field (``Bad field``) or is not a number (``Bad specifier``).
    """
    fmt = fmt.lower()
    rest, lower = text, text.lower()
    i = 0
    while i < len(fmt):
        char = fmt[i]
        if char != "%":
            cut = lower.find(char) + 1  # not found: cut nothing, as Goby
            rest, lower = rest[cut:], lower[cut:]
            i += 1
            continue
        close = fmt.find("%", i + 1)
        if close < 0:
            raise TechniqueError(f"bad format {fmt!r}: unterminated directive")
        spec = fmt[i + 1 : close]
        i = close + 1
        end = lower.find(fmt[i]) if i < len(fmt) else -1
        extract = rest if end < 0 else rest[:end]
        if ":" in spec:
            *path, last = spec.split(":")
            sub = _descend(msg, path, spec, create=True)
            sub.SetInParent()
            parse_format(extract, sub, f"%{last}%", repeated_delimiter, use_short_enum)
        else:
            _parse_field(extract, msg, spec, repeated_delimiter, use_short_enum)
    return msg


def _parse_field(extract: str, msg: Message, spec: str, delimiter: str, short: bool) -> None:
    desc = descriptor_of(msg)
    number, dot, index_text = spec.partition(".")
    if not _is_int(number) or (dot and not _is_int(index_text)):
        raise TechniqueError(f"Bad specifier: {spec}, must be an integer. For message: {desc.full_name}")
    field = desc.fields_by_number.get(int(number))
    if field is None:
        raise TechniqueError(f"Bad field: {spec} not in message {desc.full_name}")
    repeated = field.is_repeated
    if dot:
        index = int(index_text)
        if repeated:
            set_element(msg, field, index, value_from_moos(field, extract, short))
        else:
            set_value(msg, field, value_from_moos(field, extract, short))
    elif repeated:
        # boost::is_any_of: every character of the delimiter splits
        for part in re.split("[" + re.escape(delimiter) + "]", extract) if delimiter else [extract]:
            add_value(msg, field, value_from_moos(field, part, short))
    else:
        set_value(msg, field, value_from_moos(field, extract, short))


def _is_int(text: str) -> bool:
    return re.fullmatch(r"[+-]?\d+", text) is not None
