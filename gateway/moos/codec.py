"""MOOS v10 wire codec: CMOOSMsg and CMOOSCommPkt as pure functions of bytes.

Layout (all little-endian): a packet is ``int32 total_bytes, int32 count, uint8 compressed`` followed by
``count`` messages; a message is ``int32 length, int32 id, char type, char data_type, str src, str aux,
str community, str key, f64 time, f64 val, f64 val2, str sval`` where ``str`` is ``int32 n`` + ``n`` raw bytes.
Parsing is strict: a length that disagrees with the fields, or a field that overruns, is a ProtocolError, so a
corrupted stream is detected rather than silently skipped (C++ would quietly stop reading the packet).
"""

from __future__ import annotations

from struct import Struct

from .errors import ProtocolError
from .message import MoosMessage

PROTOCOL_STRING = b"ELKS CAN'T DANCE 2/8/10"
PROTOCOL_STRING_SIZE = 32
PROTOCOL_BYTES = PROTOCOL_STRING.ljust(PROTOCOL_STRING_SIZE, b"\0")

PACKET_HEADER_SIZE = 9
MESSAGE_FIXED_SIZE = 54
DEFAULT_MAX_PACKET_BYTES = 64 * 1024 * 1024

_I32 = Struct("<i")
_MSG_HEAD = Struct("<iicci")  # length, id, type, data type, len(src)
_DOUBLES_AND_LEN = Struct("<dddi")  # time, val, val2, len(sval)
_PKT_HEAD = Struct("<iiB")

_pack_i32 = _I32.pack
_pack_head = _MSG_HEAD.pack
_pack_doubles = _DOUBLES_AND_LEN.pack
_pack_pkt_head = _PKT_HEAD.pack
_unpack_i32 = _I32.unpack_from
_unpack_head = _MSG_HEAD.unpack_from
_unpack_doubles = _DOUBLES_AND_LEN.unpack_from
_unpack_pkt_head = _PKT_HEAD.unpack_from


def message_size(msg: MoosMessage) -> int:
    """Bytes the message takes on the wire (``GetSizeInBytesWhenSerialised``)."""
    return (
        MESSAGE_FIXED_SIZE
        + len(msg.raw_src)
        + len(msg.raw_aux)
        + len(msg.raw_community)
        + len(msg.raw_key)
        + len(msg.raw_sval)
    )


def encode_message(msg: MoosMessage) -> bytes:
    """Serialise one message exactly as ``CMOOSMsg::Serialize`` does."""
    src, aux, com, key, sval = msg.raw_src, msg.raw_aux, msg.raw_community, msg.raw_key, msg.raw_sval
    n_src, n_aux, n_com, n_key, n_sval = len(src), len(aux), len(com), len(key), len(sval)
    return b"".join(
        (
            _pack_head(54 + n_src + n_aux + n_com + n_key + n_sval, msg.msg_id, msg.msg_type, msg.data_type, n_src),
            src,
            _pack_i32(n_aux),
            aux,
            _pack_i32(n_com),
            com,
            _pack_i32(n_key),
            key,
            _pack_doubles(msg.msg_time, msg.dval, msg.dval2, n_sval),
            sval,
        )
    )


def frame_packet(encoded_messages: list[bytes]) -> bytes:
    """Wrap already-encoded messages into one packet (lets a server encode a message once for many peers)."""
    body = b"".join(encoded_messages)
    return _pack_pkt_head(PACKET_HEADER_SIZE + len(body), len(encoded_messages), 0) + body


def encode_packet(messages: list[MoosMessage]) -> bytes:
    """Serialise messages into one CMOOSCommPkt (compressed flag always 0)."""
    return frame_packet([encode_message(m) for m in messages])


def _read_str(buf: bytes | bytearray | memoryview, pos: int, end: int) -> tuple[bytes, int]:
    if pos + 4 > end:
        raise ProtocolError(f"string length at offset {pos} overruns the message")
    (n,) = _unpack_i32(buf, pos)
    pos += 4
    if n < 0 or pos + n > end:
        raise ProtocolError(f"string of {n} bytes at offset {pos} overruns the message")
    return bytes(buf[pos : pos + n]), pos + n


def decode_message(buf: bytes | bytearray | memoryview, pos: int = 0, end: int | None = None) -> tuple[MoosMessage, int]:
    """Parse one message starting at ``pos``; return it and the offset just after it."""
    if end is None:
        end = len(buf)
    if pos + 14 > end:
        raise ProtocolError(f"message at offset {pos} is truncated ({end - pos} bytes left, need at least 54)")
    length, msg_id, msg_type, data_type, n = _unpack_head(buf, pos)
    if length < MESSAGE_FIXED_SIZE or pos + length > end:
        raise ProtocolError(f"message at offset {pos} claims {length} bytes but {end - pos} remain")
    stop = pos + length
    p = pos + 14
    if n < 0 or p + n > stop:
        raise ProtocolError(f"source string of {n} bytes at offset {p} overruns the message")
    src = bytes(buf[p : p + n])
    p += n
    aux, p = _read_str(buf, p, stop)
    com, p = _read_str(buf, p, stop)
    key, p = _read_str(buf, p, stop)
    if p + 28 > stop:
        raise ProtocolError(f"message at offset {pos} is truncated before its numeric fields")
    t, val, val2, n = _unpack_doubles(buf, p)
    p += 28
    if n < 0 or p + n != stop:
        raise ProtocolError(
            f"message at offset {pos}: length field says {length} bytes but its fields take {p + max(n, 0) - pos}"
        )
    sval = bytes(buf[p:stop])
    return MoosMessage(msg_type, data_type, msg_id, src, aux, com, key, t, val, val2, sval), stop


def decode_packet_body(buf: bytes | bytearray | memoryview, pos: int, total: int) -> list[MoosMessage]:
    """Parse the messages of a packet whose header starts at ``pos`` and which is ``total`` bytes long."""
    end = pos + total
    if total < PACKET_HEADER_SIZE or end > len(buf):
        raise ProtocolError(f"packet of {total} bytes does not fit the {len(buf) - pos} bytes given")
    _, count, _compressed = _unpack_pkt_head(buf, pos)
    if count < 0 or count * MESSAGE_FIXED_SIZE > total - PACKET_HEADER_SIZE:
        raise ProtocolError(f"packet of {total} bytes cannot hold {count} messages")
    p = pos + PACKET_HEADER_SIZE
    messages = []
    append = messages.append
    for _ in range(count):
        msg, p = decode_message(buf, p, end)
        append(msg)
    if p != end:
        raise ProtocolError(f"packet of {total} bytes has {end - p} stray bytes after its {count} messages")
    return messages


def decode_packet(data: bytes | bytearray | memoryview) -> list[MoosMessage]:
    """Parse exactly one complete packet."""
    if len(data) < PACKET_HEADER_SIZE:
        raise ProtocolError(f"packet truncated: {len(data)} bytes, header needs {PACKET_HEADER_SIZE}")
    (total,) = _unpack_i32(data, 0)
    if total != len(data):
        raise ProtocolError(f"packet header says {total} bytes but {len(data)} were given")
    return decode_packet_body(data, 0, total)


class PacketReader:
    """Splits a byte stream into packets: feed it what ``recv`` returned, get whole decoded packets back.

    Pure: it never touches a socket. A header with an impossible size raises ProtocolError at once, before
    the (possibly huge) body would be awaited; the error's ``packets`` attribute holds the good packets that
    preceded the bad one in the same feed.
    """

    def __init__(self, max_packet_bytes: int = DEFAULT_MAX_PACKET_BYTES) -> None:
        self._buf = bytearray()
        self._max = max_packet_bytes

    @property
    def pending_bytes(self) -> int:
        """Bytes received but not yet part of a whole packet."""
        return len(self._buf)

    def feed(self, data: bytes | bytearray | memoryview) -> list[list[MoosMessage]]:
        """Add bytes; return the list of complete packets now available, each a list of messages."""
        buf = self._buf
        buf += data
        packets = []
        pos = 0
        size = len(buf)
        try:
            while size - pos >= 4:
                (total,) = _unpack_i32(buf, pos)
                if total < PACKET_HEADER_SIZE or total > self._max:
                    raise ProtocolError(
                        f"packet header claims {total} bytes (allowed {PACKET_HEADER_SIZE}..{self._max})"
                    )
                if size - pos < total:
                    break
                packets.append(decode_packet_body(buf, pos, total))
                pos += total
        except ProtocolError as exc:
            exc.packets = packets  # the whole packets that came before the bad one, still valid
            raise
        finally:
            if pos:
                del buf[:pos]
        return packets
