"""Count what crosses the simulated links: a passive listener on each link's UDP multicast group.

Goby's UDP multicast driver sends one datagram per transmission, the binary ``goby.acomms.protobuf.ModemTransmission``
(``gateway.goby.acomms.udp_multicast``); every socket joined to the group gets a copy. So the demo joins both
groups itself, without being a modem, and counts DATA transmissions (frames and their bytes, per sender) and ACKs.
That is what the links carried, independent of how the brokers account for it. Saturation is bytes sent over the
bytes the slots could carry in the same time (each sender's slots times their ``max_frame_bytes``).
"""

from __future__ import annotations

import logging
import socket
import time
from collections import Counter
from dataclasses import dataclass, field

from google.protobuf.message import DecodeError

from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.acomms.udp_multicast import join_multicast, multicast_interface
from launch.trail.settings import (
    MULTICAST_ADDRESS,
    TrailSettings,
    acomms_mac_slots,
    satellite_mac_slots,
)

log = logging.getLogger(__name__)
MAX_DATAGRAM = 65535


@dataclass
class LinkStats:
    """One link's traffic since the listener started."""

    name: str
    slots: list[tuple[int, int, int]]  # (src, slot_seconds, max_frame_bytes)
    data_transmissions: int = 0
    frames: int = 0
    frame_bytes: int = 0
    acks: int = 0
    empty: int = 0
    by_src: Counter[int] = field(default_factory=Counter)
    bytes_by_src: Counter[int] = field(default_factory=Counter)
    undecodable: int = 0

    def capacity_bytes(self, sim_seconds: float) -> float:
        """What the slot plan could carry in ``sim_seconds``: every slot's max_frame_bytes, once per cycle."""
        cycle = sum(seconds for _, seconds, _ in self.slots)
        if cycle <= 0:
            return 0.0
        return sim_seconds / cycle * sum(size for _, _, size in self.slots)

    def saturation(self, sim_seconds: float) -> float | None:
        capacity = self.capacity_bytes(sim_seconds)
        return None if capacity <= 0 else self.frame_bytes / capacity


class LinkMonitor:
    """Listens on the satellite and acomms groups; ``poll()`` (from the mission loop) reads what arrived."""

    def __init__(self, settings: TrailSettings, n_auvs: int) -> None:
        self.stats = {
            "satellite": LinkStats("satellite", satellite_mac_slots()),
            "acomms": LinkStats("acomms", acomms_mac_slots(n_auvs)),
        }
        self._sockets: dict[str, socket.socket] = {}
        self.error: str | None = None
        self.started = time.monotonic()
        for name, port in (("satellite", settings.satellite_port), ("acomms", settings.acomms_port)):
            try:
                self._sockets[name] = _listen(MULTICAST_ADDRESS, port, settings.link_address)
            except OSError as exc:
                self.error = f"cannot listen on {MULTICAST_ADDRESS}:{port} ({name}): {exc}"
                log.warning("%s; link statistics will be missing", self.error)

    def poll(self) -> None:
        for name, sock in self._sockets.items():
            stats = self.stats[name]
            while True:
                try:
                    datagram = sock.recv(MAX_DATAGRAM)
                except (BlockingIOError, InterruptedError):
                    break
                except OSError as exc:
                    self.error = f"{name}: receive failed: {exc}"
                    break
                _count(stats, datagram)

    def close(self) -> None:
        for sock in self._sockets.values():
            sock.close()
        self._sockets.clear()


def _count(stats: LinkStats, datagram: bytes) -> None:
    msg = ModemTransmission()
    try:
        msg.ParseFromString(datagram)
    except DecodeError:
        stats.undecodable += 1
        return
    if msg.type == ModemTransmission.ACK:
        stats.acks += 1
        return
    frames = [f for f in msg.frame if f]
    if not frames:
        stats.empty += 1
        return
    size = sum(len(f) for f in frames)
    stats.data_transmissions += 1
    stats.frames += len(frames)
    stats.frame_bytes += size
    stats.by_src[msg.src] += 1
    stats.bytes_by_src[msg.src] += size


def _listen(group: str, port: int, link_address: str) -> socket.socket:
    """A non-blocking UDP socket joined to ``group:port`` where the modem drivers send (loopback or the default
    interface, as ``listen_address`` makes the driver choose), without sending."""
    sock = join_multicast(group, port, interface=multicast_interface(link_address))
    sock.setblocking(False)
    return sock
