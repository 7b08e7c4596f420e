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


_head_structs: dict[tuple[int, int, int, int], Struct] = {}


def _head_struct(n_src: int, n_aux: int, n_com: int, n_key: int) -> Struct:
    """A compiled layout for everything up to the string payload, per combination of field lengths."""
    fmt = f"<iicci{n_src}si{n_aux}si{n_com}si{n_key}sdddi"
    compiled = Struct(fmt)
    if len(_head_structs) < 4096:
        _head_structs[(n_src, n_aux, n_com, n_key)] = compiled
    return compiled


def encode_fields(
    msg_type: bytes, data_type: bytes, msg_id: int, src: bytes, aux: bytes, com: bytes, key: bytes,
    msg_time: float, dval: float, dval2: float, sval: bytes,
) -> bytes:
    """Serialise one message from its fields (no MoosMessage needed): one struct pack plus the payload."""
    n_src, n_aux, n_com, n_key = len(src), len(aux), len(com), len(key)
    lengths = (n_src, n_aux, n_com, n_key)
    head = _head_structs.get(lengths) or _head_struct(*lengths)
    return head.pack(
        head.size + len(sval), msg_id, msg_type, data_type,
        n_src, src, n_aux, aux, n_com, com, n_key, key, msg_time, dval, dval2, len(sval),
    ) + sval


def encode_message(msg: MoosMessage) -> bytes:
    """Serialise one message exactly as ``CMOOSMsg::Serialize`` does."""
    return encode_fields(
        msg.msg_type, msg.data_type, msg.msg_id, msg.raw_src, msg.raw_aux, msg.raw_community, msg.raw_key,
        msg.msg_time, msg.dval, msg.dval2, msg.raw_sval,
    )


def frame_packet(encoded_messages: list[bytes], count: int | None = None) -> bytes:
    """Wrap already-encoded messages into one packet (lets a server encode a message once for many peers).

    ``count`` is the number of messages when an element holds several (a run forwarded as received)."""
    body = b"".join(encoded_messages)
    n = len(encoded_messages) if count is None else count
    return _pack_pkt_head(PACKET_HEADER_SIZE + len(body), n, 0) + body


def encode_packet(messages: list[MoosMessage]) -> bytes:
    """Serialise messages into one CMOOSCommPkt (compressed flag always 0)."""
    return frame_packet([encode_message(m) for m in messages])


def decode_message(buf: bytes, pos: int = 0, end: int | None = None) -> tuple[MoosMessage, int]:
    """Parse one message starting at ``pos`` of ``buf`` (``bytes``); return it and the offset after it."""
    if end is None:
        end = len(buf)
    if pos + 14 > end:
        raise ProtocolError(f"message at offset {pos} is truncated ({end - pos} bytes left, need at least 54)")
    length, msg_id, msg_type, data_type, n = _unpack_head(buf, pos)
    stop = pos + length
    if length < MESSAGE_FIXED_SIZE or stop > end:
        raise ProtocolError(f"message at offset {pos} claims {length} bytes but {end - pos} remain")
    # Each check keeps the next length field inside the message, so no read can stray past ``stop``.
    p = pos + 14
    q = p + n
    if n < 0 or q + 40 > stop:
        raise ProtocolError(f"source string of {n} bytes at offset {p} overruns the message")
    src = buf[p:q]
    (n,) = _unpack_i32(buf, q)
    p = q + 4
    q = p + n
    if n < 0 or q + 36 > stop:
        raise ProtocolError(f"aux string of {n} bytes at offset {p} overruns the message")
    aux = buf[p:q]
    (n,) = _unpack_i32(buf, q)
    p = q + 4
    q = p + n
    if n < 0 or q + 32 > stop:
        raise ProtocolError(f"community string of {n} bytes at offset {p} overruns the message")
    com = buf[p:q]
    (n,) = _unpack_i32(buf, q)
    p = q + 4
    q = p + n
    if n < 0 or q + 28 > stop:
        raise ProtocolError(f"key string of {n} bytes at offset {p} overruns the message")
    key = buf[p:q]
    t, val, val2, n = _unpack_doubles(buf, q)
    p = q + 28
    if n < 0 or p + n != stop:
        raise ProtocolError(
            f"message at offset {pos}: length field says {length} bytes but its fields take {p + max(n, 0) - pos}"
        )
    return MoosMessage(msg_type, data_type, msg_id, src, aux, com, key, t, val, val2, buf[p:stop]), stop


def decode_packet_body(buf: bytes, pos: int, total: int) -> list[MoosMessage]:
    """Parse the messages of a packet whose header starts at ``pos`` of ``buf`` and is ``total`` bytes long."""
    end = pos + total
    if total < PACKET_HEADER_SIZE or end > len(buf):
        raise ProtocolError(f"packet of {total} bytes does not fit the {len(buf) - pos} bytes given")
    _, count, _compressed = _unpack_pkt_head(buf, pos)
    if count < 0 or count * MESSAGE_FIXED_SIZE > total - PACKET_HEADER_SIZE:
        raise ProtocolError(f"packet of {total} bytes cannot hold {count} messages")
    p = pos + PACKET_HEADER_SIZE
    messages: list[MoosMessage] = []
    append = messages.append
    # Fast path: messages in a packet usually share their src/aux/community/key lengths, so the previous
    # message's layout is tried first as one compiled struct. It is only accepted when every length field it
    # read equals the length it assumed, which makes it exactly as strict as decode_message.
    layout: Struct | None = None
    lengths = (-1, -1, -1, -1)
    for _ in range(count):
        if layout is not None and p + layout.size <= end:
            f = layout.unpack_from(buf, p)
            n_sval = f[15]
            stop = p + f[0]
            if (
                (f[4], f[6], f[8], f[10]) == lengths
                and n_sval >= 0
                and f[0] == layout.size + n_sval
                and stop <= end
            ):
                append(MoosMessage(f[2], f[3], f[1], f[5], f[7], f[9], f[11], f[12], f[13], f[14], buf[stop - n_sval : stop]))
                p = stop
                continue
        msg, p = decode_message(buf, p, end)
        append(msg)
        lengths = (len(msg.raw_src), len(msg.raw_aux), len(msg.raw_community), len(msg.raw_key))
        layout = _head_structs.get(lengths) or _head_struct(*lengths)
    if p != end:
        raise ProtocolError(f"packet of {total} bytes has {end - p} stray bytes after its {count} messages")
    return messages


def decode_packet(data: bytes | bytearray | memoryview) -> list[MoosMessage]:
    """Parse exactly one complete packet."""
    data = bytes(data)
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
        error: ProtocolError | None = None
        try:
            raw = self.feed_raw(data)
        except ProtocolError as exc:
            raw, error = exc.packets, exc
        good: list[list[MoosMessage]] = []
        try:
            for region, pos, total in raw:
                good.append(decode_packet_body(region, pos, total))
        except ProtocolError as exc:
            exc.packets = good
            raise
        if error is not None:
            error.packets = good
            raise error
        return good

    def feed_raw(self, data: bytes | bytearray | memoryview) -> list[tuple[bytes, int, int]]:
        """Add bytes; return the complete packets now available undecoded: ``(region, start, total)`` each, the
        packet being ``region[start:start + total]`` (all share one region: one copy). ``packet_count`` reads a
        packet's message count; ``decode_packet_body`` decodes it."""
        buf = self._buf
        buf += data
        size = len(buf)
        # Find where the last complete packet ends, then decode from one immutable copy of that region.
        end = 0
        try:
            while size - end >= 4:
                (total,) = _unpack_i32(buf, end)
                if total < PACKET_HEADER_SIZE or total > self._max:
                    raise ProtocolError(
                        f"packet header claims {total} bytes (allowed {PACKET_HEADER_SIZE}..{self._max})"
                    )
                if size - end < total:
                    break
                end += total
        except ProtocolError as exc:
            exc.packets = self._take_region(end) if end else []
            raise
        return self._take_region(end) if end else []

    def _take_region(self, end: int) -> list[tuple[bytes, int, int]]:
        """The whole packets in ``_buf[:end]``, dropped from the buffer."""
        with memoryview(self._buf) as view:
            region = bytes(view[:end])  # one copy (slicing the bytearray first would make two)
        del self._buf[:end]
        packets = []
        pos = 0
        while pos < end:
            (total,) = _unpack_i32(region, pos)
            packets.append((region, pos, total))
            pos += total
        return packets


def packet_count(region: bytes, pos: int, total: int) -> int:
    """The message count in the header of the packet at ``region[pos:pos + total]``; ProtocolError if impossible."""
    _, count, _compressed = _unpack_pkt_head(region, pos)
    if count < 0 or count * MESSAGE_FIXED_SIZE > total - PACKET_HEADER_SIZE:
        raise ProtocolError(f"packet of {total} bytes cannot hold {count} messages")
    return int(count)
