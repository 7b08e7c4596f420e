"""TECHNIQUE_PROTOBUF_NATIVE_ENCODED and TECHNIQUE_PROTOBUF_NATIVE_HEX: the binary wire format, raw or as hex."""

from __future__ import annotations

from google.protobuf.message import DecodeError, Message

from translators.techniques.errors import TechniqueError
from translators.techniques.numbers import hex_decode, hex_encode


def to_native(msg: Message) -> bytes:
    """The binary encoding (posted to MOOS as a binary string)."""
    return msg.SerializeToString()


def from_native(data: bytes | str, msg: Message) -> Message:
    """Clear ``msg`` and parse the binary encoding into it; returns ``msg``.

    A ``str`` is turned back into the bytes our MOOS client decoded it from (UTF-8 with surrogate escapes).
    """
    raw = data.encode("utf-8", "surrogateescape") if isinstance(data, str) else bytes(data)
    try:
        msg.ParseFromString(raw)
    except DecodeError as exc:
        raise TechniqueError(f"not a valid binary {msg.DESCRIPTOR.full_name}: {exc}") from exc
    return msg


def to_native_hex(msg: Message) -> str:
    """The binary encoding as lowercase hex."""
    return hex_encode(msg.SerializeToString())


def from_native_hex(text: str, msg: Message) -> Message:
    """Parse hex (either case; odd length reads as a leading ``0``) of the binary encoding into ``msg``."""
    try:
        raw = hex_decode(text)
    except ValueError as exc:
        raise TechniqueError(f"not hex for {msg.DESCRIPTOR.full_name}: {text[:40]!r}") from exc
    return from_native(raw, msg)
