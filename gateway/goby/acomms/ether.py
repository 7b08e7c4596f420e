"""The in-process "ether": one object per simulated link, every attached driver hears every datagram.

For tests and single-process simulations that need no multicast (Goby's UDP multicast driver has no loss or delay
model either, so the observable behaviour is the same). Thread-safe: the drivers of several brokers or links
may run on different threads.
"""

from __future__ import annotations

import threading
from collections import deque

from gateway.goby.acomms.driver import DatagramDriver
from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig


class Ether:
    """The shared medium: ``send`` copies a datagram into every attached driver's inbox."""

    def __init__(self, name: str = "ether") -> None:
        self.name = name
        self._lock = threading.Lock()
        self._inboxes: dict[int, deque[bytes]] = {}
        self.datagrams = 0

    def attach(self, key: int) -> deque[bytes]:
        with self._lock:
            inbox: deque[bytes] = deque()
            self._inboxes[key] = inbox
            return inbox

    def detach(self, key: int) -> None:
        with self._lock:
            self._inboxes.pop(key, None)

    def send(self, datagram: bytes) -> None:
        with self._lock:
            self.datagrams += 1
            for inbox in self._inboxes.values():
                inbox.append(datagram)


class EtherDriver(DatagramDriver):
    """A modem on an :class:`Ether` (``DriverConfig.driver_name: "ether"``)."""

    def __init__(self, ether: Ether, max_frame_size: int = 1400) -> None:
        super().__init__()
        self.ether = ether
        self._max = max_frame_size
        self._inbox: deque[bytes] | None = None

    def startup(self, cfg: DriverConfig) -> None:
        super().startup(cfg)
        self._inbox = self.ether.attach(id(self))

    def shutdown(self) -> None:
        self.refusals.flush(final=True)
        self.ether.detach(id(self))
        self._inbox = None

    def _send(self, datagram: bytes) -> None:
        self.ether.send(datagram)

    def _receive_all(self) -> list[bytes]:
        inbox = self._inbox
        out: list[bytes] = []
        while inbox:
            out.append(inbox.popleft())
        return out

    def _max_frame_size(self, msg: object) -> int:
        return self._max
