"""One connection accepted by ``MoosDB`` (``server.py``): its state and buffers, and when it must be dropped.

Plain state and decisions, no socket calls: the server's one I/O thread creates these, reads and writes through
them, asks :func:`deadline` when the next one could time out and, then, :func:`timeout_reason` whether it did.
"""

from __future__ import annotations

import socket
import time as _time
from collections import deque

from .codec import PacketReader
from .db_limits import preview

PROTOCOL, HELLO, READY, CLOSED = range(4)  # waiting for the protocol string, for the name, serving, closed


class ServerClient:
    """One accepted connection and its state."""

    __slots__ = ("sock", "peer", "state", "proto_buf", "reader", "name", "asynchronous", "last_rx", "accepted",
                 "out", "out_bytes", "last_progress", "events", "held")

    def __init__(self, sock: socket.socket, peer: str, max_packet_bytes: int) -> None:
        self.sock = sock
        self.peer = peer
        self.state = PROTOCOL
        self.proto_buf = b""
        self.reader = PacketReader(max_packet_bytes)
        self.name = b""
        self.asynchronous = False
        self.accepted = self.last_rx = self.last_progress = _time.monotonic()
        self.out: deque[bytes] = deque()
        self.out_bytes = 0
        self.events = 0
        self.held = 0  # input + output bytes buffered for this client, as last counted in the DB's total

    def label(self) -> str:
        return f"{preview(self.name, 64)} ({self.peer})" if self.name else self.peer


def timeout_reason(client: ServerClient, now: float, handshake_timeout: float, stall_timeout: float,
                   client_timeout: float) -> str | None:
    """Why ``client`` must be dropped at ``now`` (monotonic): no handshake, not reading, or silent; else None."""
    if client.state in (PROTOCOL, HELLO):
        if now - client.accepted > handshake_timeout:
            return f"no handshake within {handshake_timeout:g} s"
    elif client.out_bytes and now - client.last_progress > stall_timeout:
        return f"not reading: {client.out_bytes} bytes unsent for {stall_timeout:g} s"
    elif now - client.last_rx > client_timeout:
        return f"disconnecting after {client_timeout:g} seconds of silence"
    return None


def deadline(client: ServerClient, handshake_timeout: float, stall_timeout: float, client_timeout: float) -> float:
    """When (monotonic) ``client`` times out if nothing changes meanwhile: :func:`timeout_reason`'s earliest."""
    if client.state in (PROTOCOL, HELLO):
        return client.accepted + handshake_timeout
    when = client.last_rx + client_timeout
    if client.out_bytes:
        when = min(when, client.last_progress + stall_timeout)
    return when
