"""DCCL's identifier codec (``dccl.default.id``): the first one or two bytes of every message.

Ids 0..127 take one byte, ``id << 1`` (bit 0 clear); ids 128..32767 take two bytes, little-endian,
``(id << 1) | 1``. The same codec can encode an ordinary uint32 field (Goby's ``Subscription.dccl_id``).
"""

from __future__ import annotations

from gateway.goby.dccl.errors import TruncatedError

ONE_BYTE_MAX_ID = 0x7F
TWO_BYTE_MAX_ID = 0x7FFF
ID_MIN_BITS = 8
ID_MAX_BITS = 16


def id_bits(dccl_id: int) -> int:
    """Bits the id takes on the wire; ``ValueError`` outside 0..32767."""
    if not 0 <= dccl_id <= TWO_BYTE_MAX_ID:
        raise ValueError(f"DCCL id {dccl_id} is outside 0..{TWO_BYTE_MAX_ID}")
    return ID_MIN_BITS if dccl_id <= ONE_BYTE_MAX_ID else ID_MAX_BITS


def id_value(dccl_id: int) -> int:
    """The id as the integer its bits hold (short form ``id << 1``, long form ``(id << 1) | 1``)."""
    return dccl_id << 1 if dccl_id <= ONE_BYTE_MAX_ID else (dccl_id << 1) | 1


def encode_id(dccl_id: int) -> bytes:
    """The id's bytes."""
    return id_value(dccl_id).to_bytes(id_bits(dccl_id) // 8, "little")


def decode_id(data: bytes, offset: int = 0) -> tuple[int, int]:
    """(id, bytes it took) from ``data[offset:]``; a named error when the bytes end too soon."""
    if len(data) <= offset:
        raise TruncatedError("no bytes to read a DCCL id from")
    first = data[offset]
    if not first & 1:
        return first >> 1, 1
    if len(data) < offset + 2:
        raise TruncatedError(f"DCCL id byte {first:#04x} announces a two-byte id, but the data ends after it")
    return ((data[offset + 1] << 8) | first) >> 1, 2

