"""BSON, the bytes of Goby3's JSON scheme (``nlohmann::json::to_bson``/``from_bson`` in marshalling/json.h).

The subset nlohmann writes: documents, arrays, strings, doubles, 32/64-bit integers, unsigned 64-bit (0x11),
booleans, null and binary.  Every length is checked against the bytes present; a malformed document raises
``BsonError`` naming the offset.
"""

from __future__ import annotations

import struct
from typing import Any

from gateway.goby.log.errors import LogFormatError

_I32 = struct.Struct("<i")
_I64 = struct.Struct("<q")
_U64 = struct.Struct("<Q")
_F64 = struct.Struct("<d")
MAX_DEPTH = 100


class BsonError(LogFormatError):
    """Bytes that are not a BSON document."""


def decode(data: bytes) -> dict[str, Any]:
    """The JSON object a BSON document holds."""
    value, end = _document(bytes(data), 0, len(data), False, 0)
    if end != len(data):
        raise BsonError(f"BSON: {len(data) - end} byte(s) after the document")
    assert isinstance(value, dict)
    return value


def _need(limit: int, pos: int, count: int) -> None:
    if count < 0 or pos + count > limit:
        raise BsonError(f"BSON: truncated at offset {pos} (needs {count} byte(s), {limit - pos} left)")


def _cstring(buf: bytes, pos: int, limit: int) -> tuple[str, int]:
    end = buf.find(b"\0", pos, limit)
    if end < 0:
        raise BsonError(f"BSON: unterminated name at offset {pos}")
    return buf[pos:end].decode("utf-8", "replace"), end + 1


def _document(buf: bytes, pos: int, limit: int, array: bool, depth: int) -> tuple[dict[str, Any] | list[Any], int]:
    if depth > MAX_DEPTH:
        raise BsonError(f"BSON: nested deeper than {MAX_DEPTH} at offset {pos}")
    _need(limit, pos, 4)
    (length,) = _I32.unpack_from(buf, pos)
    if length < 5:
        raise BsonError(f"BSON: document length {length} at offset {pos}")
    _need(limit, pos, length)
    end = pos + length
    if buf[end - 1] != 0:
        raise BsonError(f"BSON: document at offset {pos} does not end with NUL")
    items: dict[str, Any] = {}
    p = pos + 4
    while p < end - 1:
        kind = buf[p]
        name, p = _cstring(buf, p + 1, end - 1)
        value, p = _value(buf, p, end - 1, kind, depth)
        items[name] = value
    if p != end - 1:
        raise BsonError(f"BSON: element overruns its document at offset {p}")
    if array:
        return list(items.values()), end
    return items, end


def _value(buf: bytes, p: int, limit: int, kind: int, depth: int) -> tuple[Any, int]:
    if kind == 0x01:
        _need(limit, p, 8)
        return _F64.unpack_from(buf, p)[0], p + 8
    if kind == 0x02:
        _need(limit, p, 4)
        (length,) = _I32.unpack_from(buf, p)
        _need(limit, p + 4, length)
        if length < 1:
            raise BsonError(f"BSON: string length {length} at offset {p}")
        return buf[p + 4:p + 3 + length].decode("utf-8", "replace"), p + 4 + length
    if kind in (0x03, 0x04):
        return _document(buf, p, limit, kind == 0x04, depth + 1)
    if kind == 0x05:
        _need(limit, p, 5)
        (length,) = _I32.unpack_from(buf, p)
        _need(limit, p + 5, length)
        return {"bytes": list(buf[p + 5:p + 5 + length]), "subtype": buf[p + 4]}, p + 5 + length
    if kind == 0x08:
        _need(limit, p, 1)
        return buf[p] != 0, p + 1
    if kind == 0x0A:
        return None, p
    if kind == 0x10:
        _need(limit, p, 4)
        return _I32.unpack_from(buf, p)[0], p + 4
    if kind in (0x12, 0x09):
        _need(limit, p, 8)
        return _I64.unpack_from(buf, p)[0], p + 8
    if kind == 0x11:
        _need(limit, p, 8)
        return _U64.unpack_from(buf, p)[0], p + 8
    raise BsonError(f"BSON: unsupported element type 0x{kind:02x} at offset {p}")


def encode(obj: dict[str, Any]) -> bytes:
    """A JSON object as BSON, as ``nlohmann::json::to_bson`` writes it (integers as int32 when they fit)."""
    if not isinstance(obj, dict):
        raise BsonError("BSON: the top level must be an object")
    return _encode_doc(obj.items())


def _encode_doc(items: Any) -> bytes:
    body = b"".join(_encode_element(str(k), v) for k, v in items)
    return _I32.pack(len(body) + 5) + body + b"\0"


def _encode_element(name: str, value: Any) -> bytes:
    key = name.encode() + b"\0"
    if value is None:
        return b"\x0a" + key
    if isinstance(value, bool):
        return b"\x08" + key + (b"\x01" if value else b"\x00")
    if isinstance(value, int):
        if -(1 << 31) <= value < (1 << 31):
            return b"\x10" + key + _I32.pack(value)
        if -(1 << 63) <= value < (1 << 63):
            return b"\x12" + key + _I64.pack(value)
        return b"\x11" + key + _U64.pack(value)
    if isinstance(value, float):
        return b"\x01" + key + _F64.pack(value)
    if isinstance(value, str):
        raw = value.encode()
        return b"\x02" + key + _I32.pack(len(raw) + 1) + raw + b"\0"
    if isinstance(value, dict):
        return b"\x03" + key + _encode_doc(value.items())
    if isinstance(value, list | tuple):
        return b"\x04" + key + _encode_doc((str(i), v) for i, v in enumerate(value))
    raise BsonError(f"BSON: cannot encode {type(value).__name__} ({name})")
