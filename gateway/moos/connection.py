"""Client side of one MOOS TCP connection: connect, handshake, and read whole packets.

This layer owns the socket and the blocking reads; it knows nothing about registrations or callbacks.
"""

from __future__ import annotations

import logging
import socket
import threading
from dataclasses import dataclass

from .clock import MoosClock
from .codec import PROTOCOL_BYTES, PacketReader, encode_packet
from .errors import ConnectionClosedError, HandshakeError, PoisonedError, ProtocolError
from .message import ASYNC_KEY, DATA, POISON, STRING, WELCOME, MoosMessage, to_bytes, to_str

log = logging.getLogger(__name__)

HANDSHAKE_TIMEOUT_S = 10.0
RECV_BYTES = 256 * 1024


@dataclass
class Welcome:
    """What the DB told us in its WELCOME message."""

    community: str
    skew: float
    db_time: float
    db_is_async: bool
    db_hostname: str


def open_socket(host: str, port: int, timeout: float = 5.0) -> socket.socket:
    """Connect over IPv4 (MOOS is IPv4-only) with Nagle off; raises OSError when nobody listens."""
    infos = socket.getaddrinfo(host, port, socket.AF_INET, socket.SOCK_STREAM)
    if not infos:
        raise OSError(f"cannot resolve {host!r} to an IPv4 address")
    family, kind, proto, _, address = infos[0]
    sock = socket.socket(family, kind, proto)
    try:
        sock.settimeout(timeout)
        sock.connect(address)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.settimeout(None)
    except BaseException:
        sock.close()
        raise
    return sock


def _parse_aux_value(aux: str, name: str) -> str:
    """``MOOSValFromString`` for a ``name=value,...`` string (token case-sensitive)."""
    for part in aux.split(","):
        token, sep, value = part.partition("=")
        if sep and token.strip() == name:
            return value.strip()
    return ""


class PacketSocket:
    """A connected socket plus a PacketReader: ``read_packet()`` blocks until one whole packet arrives."""

    def __init__(self, sock: socket.socket, max_packet_bytes: int | None = None) -> None:
        self.sock = sock
        self._reader = PacketReader(max_packet_bytes) if max_packet_bytes else PacketReader()
        self._ready: list[list[MoosMessage]] = []
        self._recv_buf = bytearray(RECV_BYTES)
        self._send_lock = threading.Lock()
        self.bytes_read = 0
        self.bytes_sent = 0
        self._closed = False

    def read_packets(self) -> list[list[MoosMessage]]:
        """Block until at least one packet is complete; return every complete packet (in order)."""
        if self._ready:
            ready, self._ready = self._ready, []
            return ready
        view = memoryview(self._recv_buf)
        while True:
            try:
                n = self.sock.recv_into(view)
            except OSError as exc:
                raise ConnectionClosedError(f"connection lost: {exc}") from exc
            if n == 0:
                raise ConnectionClosedError("the peer closed the connection")
            self.bytes_read += n
            packets = self._reader.feed(view[:n])
            if packets:
                return packets

    def read_packet(self) -> list[MoosMessage]:
        """Block until exactly one more packet is available and return it."""
        packets = self.read_packets()
        first, rest = packets[0], packets[1:]
        self._ready = rest + self._ready
        return first

    def send(self, data: bytes) -> None:
        """Send all bytes (blocking: TCP flow control is our back-pressure); thread-safe."""
        try:
            with self._send_lock:
                self.sock.sendall(data)
        except OSError as exc:
            raise ConnectionClosedError(f"send failed: {exc}") from exc
        self.bytes_sent += len(data)

    def shutdown(self) -> None:
        """Wake any thread blocked on this socket; idempotent."""
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self.shutdown()
            self.sock.close()


def client_handshake(
    conn: PacketSocket, name: str, asynchronous: bool, clock: MoosClock, timeout: float = HANDSHAKE_TIMEOUT_S
) -> Welcome:
    """Send the protocol string and our name; return the DB's WELCOME or raise (POISON is PoisonedError)."""
    # Stamped without skew, as libMOOS resets its skew before the handshake: the DB's reply measures it anew.
    hello = MoosMessage(
        DATA, STRING, key=ASYNC_KEY if asynchronous else b"", msg_time=clock.local_time(), sval=to_bytes(name)
    )
    conn.sock.settimeout(timeout)
    try:
        conn.send(PROTOCOL_BYTES + encode_packet([hello]))
        try:
            reply = conn.read_packet()
        except ConnectionClosedError as exc:
            raise HandshakeError(f"the DB closed the connection during the handshake ({exc})") from exc
        except ProtocolError as exc:
            raise HandshakeError(f"the DB's handshake reply is malformed: {exc}") from exc
    finally:
        conn.sock.settimeout(None)
    if len(reply) != 1:
        raise HandshakeError(f"expected one message in the handshake reply, got {len(reply)}")
    msg = reply[0]
    if msg.msg_type == POISON:
        raise PoisonedError(f"the DB refused client {name!r}: {msg.string()}")
    if msg.msg_type != WELCOME:
        raise HandshakeError(f"expected WELCOME from the DB, got message type {msg.type()!r}")
    return Welcome(
        community=to_str(msg.raw_community),
        skew=msg.dval,
        db_time=msg.msg_time,
        db_is_async=msg.raw_sval.lower() == ASYNC_KEY,
        db_hostname=_parse_aux_value(msg.source_aux(), "hostname"),
    )
