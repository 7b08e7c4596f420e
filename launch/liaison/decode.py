"""Payload bytes -> the text a person reads in the scope (pure functions; no sockets, no threads).

PROTOBUF payloads of a type imported in this process are shown in protobuf text format, DCCL payloads too
(decoded by the project's DCCL codec, ``gateway.goby.dccl``: the intervehicle layer republishes what it sends and
receives under both schemes); CSTR as the string; anything else (an unknown type, a scheme without a decoder, a
payload that does not parse, one larger than ``max_message_size_bytes``) as its size and the first bytes in hex,
so nothing is hidden.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from google.protobuf import message as pb_message
from google.protobuf import text_format

from gateway.goby.dccl import Codec as DcclCodec
from gateway.goby.dccl import DcclError
from gateway.goby.portal.marshalling import Scheme, is_dccl, message_class

HEX_PREVIEW_BYTES = 48


@dataclass(frozen=True)
class Decoded:
    """``short``: one line for the table; ``full``: multi-line text for the expanded row; ``ok``: decoded."""

    short: str
    full: str
    ok: bool


def hex_preview(payload: bytes, limit: int = HEX_PREVIEW_BYTES) -> str:
    """``"12 bytes: 0a 0b ..."`` with at most ``limit`` bytes shown."""
    shown = payload[:limit].hex(" ")
    more = " ..." if len(payload) > limit else ""
    return f"{len(payload)} bytes: {shown}{more}"


@lru_cache(maxsize=1024)
def _cls(type_name: str) -> type[pb_message.Message] | None:
    return message_class(type_name)


def _parse_dccl(payload: bytes, cls: type[pb_message.Message], dccl: DcclCodec) -> pb_message.Message:
    if not is_dccl(cls):
        raise DcclError(f"{cls.DESCRIPTOR.full_name} has no DCCL options")
    dccl.load(cls)
    return dccl.decode(payload, cls)


def decode_payload(payload: bytes, scheme: int, type_name: str, max_size: int = 2048,
                   dccl: DcclCodec | None = None) -> Decoded:
    """Decode one publication for display; never raises for bad input (the reason is in the text).

    DCCL payloads need ``dccl``, a codec owned by the calling thread (it caches the compiled types)."""
    if max_size > 0 and len(payload) > max_size:
        text = f"{hex_preview(payload)} (larger than max_message_size_bytes {max_size}: not decoded)"
        return Decoded(text, text, False)
    if scheme == Scheme.CSTR:
        raw = payload[:-1] if payload.endswith(b"\0") else payload
        text = raw.decode(errors="replace")
        return Decoded(text, text, True)
    if scheme == Scheme.PROTOBUF or (scheme == Scheme.DCCL and dccl is not None):
        cls = _cls(type_name)
        if cls is None:
            text = f"{hex_preview(payload)} (type not loaded)"
            return Decoded(text, text, False)
        try:
            if scheme == Scheme.DCCL:
                msg = _parse_dccl(payload, cls, dccl)  # type: ignore[arg-type]
            else:
                msg = cls()
                msg.ParseFromString(payload)
        except (pb_message.DecodeError, DcclError) as exc:
            text = f"{hex_preview(payload)} (does not parse as {type_name}: {exc})"
            return Decoded(text, text, False)
        return Decoded(text_format.MessageToString(msg, as_one_line=True),
                       text_format.MessageToString(msg), True)
    text = f"{hex_preview(payload)} (no decoder for this scheme)"
    return Decoded(text, text, False)
