"""MOOS <-> protobuf string techniques (Goby's ``TranslatorEntry.ParserSerializerTechnique``).

Translators call ``serialize``/``parse`` with a ``Technique``; each technique also has its own module
(``text_format``, ``native``, ``prefixed``, ``key_value``, ``format_technique``) for direct use.
Output matches what the C++ gateway writes, because MOOS apps parse it.  Errors raise ``TechniqueError``.
"""

from __future__ import annotations

from enum import IntEnum

from google.protobuf import descriptor_pool as _descriptor_pool
from google.protobuf.message import Message

from gateway.moos_gateway.protobuf.translator_pb2 import TranslatorEntry
from translators.techniques.errors import TechniqueError
from translators.techniques.format_technique import format_message, parse_format
from translators.techniques.key_value import from_key_values, to_key_values, value_for_key
from translators.techniques.native import from_native, from_native_hex, to_native, to_native_hex
from translators.techniques.prefixed import (
    MAGIC_PROTOBUF_HEADER,
    new_message,
    parse_prefixed,
    prefix_for,
    split_prefix,
)
from translators.techniques.text_format import from_text_format, to_text_format

__all__ = [
    "MAGIC_PROTOBUF_HEADER",
    "Technique",
    "TechniqueError",
    "dynamic_parse",
    "format_message",
    "from_key_values",
    "from_native",
    "from_native_hex",
    "from_text_format",
    "is_binary",
    "parse",
    "parse_format",
    "serialize",
    "to_key_values",
    "to_native",
    "to_native_hex",
    "to_text_format",
    "value_for_key",
]


class Technique(IntEnum):
    """The techniques, numbered as ``goby.moos.protobuf.TranslatorEntry.ParserSerializerTechnique``."""

    PROTOBUF_TEXT_FORMAT = TranslatorEntry.TECHNIQUE_PROTOBUF_TEXT_FORMAT
    PROTOBUF_NATIVE_ENCODED = TranslatorEntry.TECHNIQUE_PROTOBUF_NATIVE_ENCODED
    COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS = TranslatorEntry.TECHNIQUE_COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS
    FORMAT = TranslatorEntry.TECHNIQUE_FORMAT
    PREFIXED_PROTOBUF_TEXT_FORMAT = TranslatorEntry.TECHNIQUE_PREFIXED_PROTOBUF_TEXT_FORMAT
    PROTOBUF_NATIVE_HEX = TranslatorEntry.TECHNIQUE_PROTOBUF_NATIVE_HEX
    PREFIXED_PROTOBUF_NATIVE_HEX = TranslatorEntry.TECHNIQUE_PREFIXED_PROTOBUF_NATIVE_HEX
    PREFIXED_PROTOBUF_NATIVE_ENCODED = TranslatorEntry.TECHNIQUE_PREFIXED_PROTOBUF_NATIVE_ENCODED

    @property
    def proto_name(self) -> str:
        """The enum value's name in the proto (``TECHNIQUE_FORMAT``), as Goby prints it."""
        return "TECHNIQUE_" + self.name


_BINARY = {Technique.PROTOBUF_NATIVE_ENCODED, Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED}
_BASE = {
    Technique.PREFIXED_PROTOBUF_TEXT_FORMAT: Technique.PROTOBUF_TEXT_FORMAT,
    Technique.PREFIXED_PROTOBUF_NATIVE_HEX: Technique.PROTOBUF_NATIVE_HEX,
    Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED: Technique.PROTOBUF_NATIVE_ENCODED,
}


def is_binary(technique: int) -> bool:
    """True for the techniques whose output is posted to MOOS as a binary string."""
    return Technique(technique) in _BINARY


def serialize(
    msg: Message,
    technique: int = Technique.PREFIXED_PROTOBUF_TEXT_FORMAT,
    *,
    format: str | None = None,
    repeated_delimiter: str = ",",
    use_short_enum: bool = False,
) -> str | bytes:
    """``msg`` as a MOOS value: ``bytes`` for the binary techniques, ``str`` otherwise.

    ``format`` is required for ``Technique.FORMAT``; ``repeated_delimiter`` and ``use_short_enum`` apply to
    the key=value and format techniques, as in Goby.
    """
    technique = Technique(technique)
    if technique in _BASE:
        body = serialize(msg, _BASE[technique])
        if isinstance(body, bytes):
            return prefix_for(msg).encode("ascii") + body
        return prefix_for(msg) + body
    if technique is Technique.PROTOBUF_TEXT_FORMAT:
        return to_text_format(msg)
    if technique is Technique.PROTOBUF_NATIVE_ENCODED:
        return to_native(msg)
    if technique is Technique.PROTOBUF_NATIVE_HEX:
        return to_native_hex(msg)
    if technique is Technique.COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS:
        return to_key_values(msg, use_short_enum)
    if format is None:
        raise TechniqueError("TECHNIQUE_FORMAT needs a format string")
    return format_message(msg, format, repeated_delimiter, use_short_enum)


def parse(
    value: str | bytes,
    msg: Message,
    technique: int = Technique.PREFIXED_PROTOBUF_TEXT_FORMAT,
    *,
    format: str | None = None,
    repeated_delimiter: str = ",",
    use_short_enum: bool = False,
) -> Message:
    """Parse a MOOS value into ``msg`` and return it.

    The protobuf techniques clear ``msg`` first; key=value and format merge into it (Goby's behaviour).
    Binary values are ``bytes`` (or a ``str`` as our MOOS client decodes it).  Raises TechniqueError on malformed
    input.
    """
    technique = Technique(technique)
    text = _as_text(value, technique)
    if technique in _BASE:
        base = _BASE[technique]

        def base_parse(body: str, target: Message) -> Message:
            return parse(body.encode("latin-1") if base in _BINARY else body, target, base)

        return parse_prefixed(text, msg, base_parse, technique.proto_name)
    if technique is Technique.PROTOBUF_NATIVE_ENCODED:
        return from_native(text.encode("latin-1"), msg)
    if technique is Technique.PROTOBUF_TEXT_FORMAT:
        return from_text_format(text, msg)
    if technique is Technique.PROTOBUF_NATIVE_HEX:
        return from_native_hex(text, msg)
    if technique is Technique.COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS:
        return from_key_values(text, msg, use_short_enum)
    if format is None:
        raise TechniqueError("TECHNIQUE_FORMAT needs a format string")
    return parse_format(text, msg, format, repeated_delimiter, use_short_enum)


def _as_text(value: str | bytes, technique: Technique) -> str:
    """Binary techniques work on Latin-1 text (one character per byte, so the bytes survive exactly); a ``str``
    given for them is first turned back into the bytes our MOOS client decoded it from (UTF-8, surrogate escapes).
    Text techniques decode ``bytes`` the same way the client does."""
    if technique in _BINARY:
        raw = value.encode("utf-8", "surrogateescape") if isinstance(value, str) else bytes(value)
        return raw.decode("latin-1")
    return value.decode("utf-8", "surrogateescape") if isinstance(value, bytes) else value


def dynamic_parse(
    value: str | bytes,
    technique: int = Technique.PREFIXED_PROTOBUF_TEXT_FORMAT,
    pool: _descriptor_pool.DescriptorPool | None = None,
) -> Message | None:
    """A message of whatever type the ``@PB[...]`` prefix names, or None if ``value`` is not prefixed.

    Only the prefixed techniques can do this.  Raises TechniqueError for an unknown type (import its
    ``_pb2`` first) or a body that does not parse -- Goby returns null for both; we say why.
    """
    technique = Technique(technique)
    if technique not in _BASE:
        raise TechniqueError(
            f"Non-PREFIX techniques are not supported when using dynamic_parse: {technique.proto_name}"
        )
    text = _as_text(value, technique)
    split = split_prefix(text, technique.proto_name)
    if split is None:
        return None
    msg = new_message(split[0], pool)
    return parse(value, msg, technique)
