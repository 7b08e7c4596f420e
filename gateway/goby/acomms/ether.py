"""The in-process "ether": one object per simulated link, every attached driver hears every datagram.

For tests and single-process simulations that need no multicast. The ether itself loses nothing, as Goby's UDP
multicast driver; a driver block with our ``channel_model`` extension impairs what each attached driver receives
(``gateway.goby.acomms.channel``, applied by :class:`DatagramDriver`), each driver drawing on its own. Thread-safe: the drivers of several brokers or links
may run on different threads. Each driver's inbox comes with an eventfd that a datagram makes readable, so the
link's thread waits on it as on a socket.
"""

from __future__ import annotations

import os
import threading
from collections import deque
from collections.abc import Callable

from gateway.goby.acomms.driver import DatagramDriver
from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig


class Ether:
    """The shared medium: ``send`` copies a datagram into every attached driver's inbox."""

    def __init__(self, name: str = "ether") -> None:
        self.name = name
        self._lock = threading.Lock()
        self._inboxes: dict[int, tuple[deque[bytes], Callable[[], None] | None]] = {}
        self.datagrams = 0

    def attach(self, key: int, wake: Callable[[], None] | None = None) -> deque[bytes]:
        """A new inbox under ``key``; ``wake()`` is called (under the ether's lock) after each datagram lands."""
        with self._lock:
            inbox: deque[bytes] = deque()
            self._inboxes[key] = (inbox, wake)
            return inbox

    def detach(self, key: int) -> None:
        """Remove the inbox; once this returns its ``wake`` is never called again."""
        with self._lock:
            self._inboxes.pop(key, None)

    def send(self, datagram: bytes) -> None:
        with self._lock:
            self.datagrams += 1
            for inbox, wake in self._inboxes.values():
                inbox.append(datagram)
                if wake is not None:
                    wake()


class EtherDriver(DatagramDriver):
    """A modem on an :class:`Ether` (``DriverConfig.driver_name: "ether"``)."""

    def __init__(self, ether: Ether, max_frame_size: int = 1400) -> None:
        super().__init__()
        self.ether = ether
        self._max = max_frame_size
        self._inbox: deque[bytes] | None = None
        self._fd: int | None = None  # eventfd: readable while the inbox may hold datagrams

    def startup(self, cfg: DriverConfig) -> None:
        super().startup(cfg)
        fd = self._fd = os.eventfd(0, os.EFD_NONBLOCK | os.EFD_CLOEXEC)
        self._inbox = self.ether.attach(id(self), lambda: os.eventfd_write(fd, 1))

    def shutdown(self) -> None:
        self.refusals.flush(final=True)
        self.ether.detach(id(self))
        self._inbox = None
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def fileno(self) -> int:
        if self._fd is None:
            raise ValueError(f"{self.name or 'ether driver'}: not started")
        return self._fd

    def _send(self, datagram: bytes) -> None:
        self.ether.send(datagram)

    def _receive_all(self) -> list[bytes]:
        inbox = self._inbox
        out: list[bytes] = []
        if self._fd is not None:
            try:  # reset before draining: a datagram landing after this wakes the thread again
                os.eventfd_read(self._fd)
            except BlockingIOError:
                pass
        while inbox:
            out.append(inbox.popleft())
        return out

    def _max_frame_size(self, msg: object) -> int:
        return self._max
