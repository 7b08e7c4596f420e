"""Reading ZeroMQ socket-monitor events without ``zmq.utils.monitor``.

Why our own: ``zmq.utils.monitor`` imports ``zmq.asyncio`` and with it asyncio and ssl, 3 MiB of private memory in
every process that watches its broker connection; the event frame is six bytes (ZeroMQ's ``zmq_socket_monitor``).
"""

from __future__ import annotations

import struct
from typing import NamedTuple

import zmq

_EVENT = struct.Struct("=HI")  # event id (uint16), value (uint32), native byte order as libzmq writes them


class MonitorEvent(NamedTuple):
    event: int
    value: int
    endpoint: bytes


def parse_monitor_frames(frames: list[bytes]) -> MonitorEvent | None:
    """The event in a monitor message's two frames, or None for a malformed one (never raises)."""
    if len(frames) != 2 or len(frames[0]) != _EVENT.size:
        return None
    event, value = _EVENT.unpack(frames[0])
    return MonitorEvent(event, value, frames[1])


def recv_monitor_event(socket: zmq.Socket, flags: int = 0) -> MonitorEvent | None:
    """Receive one monitor message (raises ``zmq.Again`` with NOBLOCK when none is ready)."""
    return parse_monitor_frames(socket.recv_multipart(flags))
