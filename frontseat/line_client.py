"""A TCP client for ``\\r\\n``-delimited line protocols that keeps reconnecting (the driver's link).

Its own thread connects, reads and splits lines; the owner drains them with :meth:`LineClient.read_lines`
from its thread and writes with :meth:`LineClient.write_line`. :attr:`LineClient.connection_id` counts
successful connections, so the owner can notice a reconnect that happened between two of its ticks.
"""

from __future__ import annotations

import logging
import socket
import threading
from collections import deque

from frontseat.simulator.protocol import LineSplitter, encode_lines

log = logging.getLogger(__name__)



class LineClient:
    """Keeps a TCP connection to ``host:port`` up, retrying every ``reconnect_interval`` real seconds."""

    def __init__(
        self,
        host: str,
        port: int,
        *,
        reconnect_interval: float = 1.0,
        max_line: int = 64 * 1024,
        io_timeout: float = 5.0,
        name: str = "line-client",
    ) -> None:
        self.host, self.port = host, port
        self.reconnect_interval = max(0.01, reconnect_interval)
        self.max_line = max_line
        self.io_timeout = io_timeout  # bounds how long write_line can block the owner's thread
        self._name = name
        self._lines: deque[str] = deque()
        self._lock = threading.Lock()  # guards _sock and writes
        self._sock: socket.socket | None = None
        self._connection_id = 0
        self._closing = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def address(self) -> str:
        return f"{self.host}:{self.port}"

    @property
    def connected(self) -> bool:
        return self._sock is not None

    @property
    def connection_id(self) -> int:
        """How many connections have been established so far (0 before the first)."""
        return self._connection_id

    def start(self) -> LineClient:
        """Start the connect/read thread (idempotent)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name=self._name, daemon=True)
            self._thread.start()
        return self

    def close(self) -> None:
        """Disconnect and stop the thread. Idempotent."""
        self._closing.set()
        with self._lock:
            sock = self._sock
        if sock is not None:
            _shutdown(sock)
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=10)

    def __enter__(self) -> LineClient:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def read_lines(self) -> list[str]:
        """Every complete line received since the last call (without the delimiter), oldest first."""
        lines = []
        while self._lines:
            lines.append(self._lines.popleft())
        return lines

    def write_line(self, line: str) -> bool:
        """Send ``line`` plus ``\\r\\n``; False (and nothing sent) when not connected or the send failed."""
        with self._lock:
            sock = self._sock
            if sock is None:
                return False
            try:
                sock.sendall(encode_lines([line]))
                return True
            except TimeoutError:
                # the peer stopped reading: a partial line may be on the wire, so start over on a new connection
                log.error("write to %s timed out after %.0f s; reconnecting", self.address, self.io_timeout)
                _shutdown(sock)
                return False
            except OSError as exc:
                log.warning("write to %s failed: %s", self.address, exc)
                return False

    # ----- the connection thread --------------------------------------------------------------------------
    def _run(self) -> None:
        failures = 0
        while not self._closing.is_set():
            try:
                sock = socket.create_connection((self.host, self.port), timeout=5)
            except OSError as exc:
                failures += 1
                # one warning, then quiet retries, so an absent peer does not flood the log
                (log.warning if failures == 1 else log.debug)("cannot connect to %s: %s", self.address, exc)
                self._closing.wait(self.reconnect_interval)
                continue
            failures = 0
            sock.settimeout(self.io_timeout)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                if self._closing.is_set():
                    sock.close()
                    break
                self._sock = sock
                self._connection_id += 1
            log.info("connected to %s", self.address)
            self._read_until_closed(sock)
            with self._lock:
                self._sock = None
            sock.close()
            if not self._closing.is_set():
                log.warning("connection to %s lost; retrying every %.1f s", self.address, self.reconnect_interval)
                self._closing.wait(self.reconnect_interval)

    def _read_until_closed(self, sock: socket.socket) -> None:
        splitter = LineSplitter(self.max_line)
        while True:
            try:
                data = sock.recv(65536)
            except TimeoutError:
                continue  # quiet peer; the timeout exists for writes
            except OSError:
                return
            if not data:
                return
            self._lines.extend(splitter.feed(data))
            if splitter.overflowed:
                log.error("%s sent a line longer than %d bytes; discarding it", self.address, self.max_line)


def _shutdown(sock: socket.socket) -> None:
    """Wake the reader thread out of ``recv`` (it then closes and reconnects)."""
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass
