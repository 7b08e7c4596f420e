"""Client side of one MOOS TCP connection, without blocking: resolve, connect, the handshake's bytes, the WELCOME.

Pure helpers for ``engine.py``, which drives them from its reactor: a connect that returns at once (the reactor
waits for the socket to become writable), the bytes of the protocol string and the name, and the checks on the
DB's reply. Nothing here waits, reads or knows about registrations or callbacks.
"""

from __future__ import annotations

import errno
import logging
import socket
from dataclasses import dataclass

from .clock import MoosClock
from .codec import PROTOCOL_BYTES, encode_packet
from .errors import HandshakeError, PoisonedError
from .message import ASYNC_KEY, DATA, POISON, STRING, WELCOME, MoosMessage, to_bytes, to_str

log = logging.getLogger(__name__)

RECV_BYTES = 256 * 1024


@dataclass
class Welcome:
    """What the DB told us in its WELCOME message."""

    community: str
    skew: float
    db_time: float
    db_is_async: bool
    db_hostname: str


def resolve(host: str, port: int) -> tuple[str, int]:
    """The IPv4 address of ``host`` (MOOS is IPv4-only); raises OSError when it has none."""
    infos = socket.getaddrinfo(host, port, socket.AF_INET, socket.SOCK_STREAM)
    if not infos:
        raise OSError(f"cannot resolve {host!r} to an IPv4 address")
    address = infos[0][4]
    return str(address[0]), int(address[1])


def start_connect(address: tuple[str, int]) -> tuple[socket.socket, bool]:
    """A non-blocking socket (Nagle off) connecting to ``address``: (socket, True when already connected).

    When not yet connected, the socket becomes writable once the connection is made or failed
    (:func:`connect_error` says which). Raises OSError when the connection failed at once (nobody listens).
    """
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        err = sock.connect_ex(address)
        if err not in (0, errno.EINPROGRESS, errno.EAGAIN):
            raise OSError(err, errno.errorcode.get(err, str(err)))
    except BaseException:
        sock.close()
        raise
    return sock, err == 0


def connect_error(sock: socket.socket) -> int:
    """0 when a non-blocking connect succeeded, else its errno."""
    return sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)


def hello_bytes(name: str, asynchronous: bool, clock: MoosClock) -> bytes:
    """The protocol string and the packet naming us, as the first bytes on a new connection."""
    # Stamped without skew, as libMOOS resets its skew before the handshake: the DB's reply measures it anew.
    hello = MoosMessage(
        DATA, STRING, key=ASYNC_KEY if asynchronous else b"", msg_time=clock.local_time(), sval=to_bytes(name)
    )
    return PROTOCOL_BYTES + encode_packet([hello])


def parse_welcome(reply: list[MoosMessage], name: str) -> Welcome:
    """The DB's first packet: its WELCOME, or HandshakeError (PoisonedError for a POISON)."""
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


def _parse_aux_value(aux: str, name: str) -> str:
    """``MOOSValFromString`` for a ``name=value,...`` string (token case-sensitive)."""
    for part in aux.split(","):
        token, sep, value = part.partition("=")
        if sep and token.strip() == name:
            return value.strip()
    return ""


def close_socket(sock: socket.socket) -> None:
    """Shut down and close, ignoring a peer that is already gone."""
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass
    try:
        sock.close()
    except OSError:
        pass
